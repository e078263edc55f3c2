#include "spinradar/driver/driver_health.hpp"

#include <iomanip>
#include <sstream>
#include <vector>

namespace spinradar::navtech {

DriverHealth::DriverHealth(double window_s, double no_data_s)
    : window_ns_(int64_t(window_s * 1e9)), no_data_ns_(int64_t(no_data_s * 1e9)) {}

Health DriverHealth::update(const DriverStats& s, bool has_configuration, int64_t now_ns) {
  if (!started_ || s.azimuths != last_azimuths_) {
    started_ = true;
    last_azimuths_ = s.azimuths;
    last_data_ns_ = now_ns;
  }
  history_.push_back({now_ns, s});
  // Keep one snapshot at or before the window's start as the baseline.
  while (history_.size() > 2 && history_[1].t_ns <= now_ns - window_ns_) history_.pop_front();
  const DriverStats& b = history_.front().stats;
  const double window_s = (now_ns - history_.front().t_ns) * 1e-9;

  std::vector<std::string> what;
  auto count = [&](uint64_t now, uint64_t before, const char* name) {
    if (now > before) what.push_back(std::to_string(now - before) + " " + name);
  };
  count(s.input.stream.garbage_bytes, b.input.stream.garbage_bytes, "garbage bytes");
  count(s.input.stream.oversized, b.input.stream.oversized, "oversized headers");
  count(s.input.stream.truncated, b.input.stream.truncated, "truncated messages");
  count(s.input.malformed, b.input.malformed, "malformed messages");
  count(s.input.unknown_types, b.input.unknown_types, "messages of unknown type");
  count(s.input.disconnects, b.input.disconnects, "disconnects");
  count(s.input.failed_connects, b.input.failed_connects, "failed connects");
  count(s.dropped_scans, b.dropped_scans, "dropped rotations");
  count(s.missing_azimuths, b.missing_azimuths, "missing azimuths");
  count(s.duplicated_azimuths, b.duplicated_azimuths, "duplicated azimuths");
  count(s.implausible_times, b.implausible_times, "implausible sensor times");
  count(s.time_anomalies, b.time_anomalies, "time anomalies");

  Health h;
  std::ostringstream m;
  m << std::fixed << std::setprecision(1);
  if (!has_configuration) {
    h.level = HealthLevel::Error;
    m << "no sensor configuration (not connected?)";
  } else if (now_ns - last_data_ns_ > no_data_ns_) {
    h.level = HealthLevel::Error;
    m << "no data for " << (now_ns - last_data_ns_) * 1e-9 << " s";
  } else if (!what.empty()) {
    h.level = HealthLevel::Warn;
    m << "in the last " << window_s << " s:";
    for (size_t i = 0; i < what.size(); ++i) m << (i ? ", " : " ") << what[i];
  } else {
    m << "streaming";
  }
  if (h.level != HealthLevel::Error && s.time_anomalies > b.time_anomalies)
    m << "; last: " << s.last_time_anomaly;
  h.message = m.str();
  return h;
}

}  // namespace spinradar::navtech
