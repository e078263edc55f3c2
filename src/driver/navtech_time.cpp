#include "spinradar/driver/navtech_time.hpp"

#include <cmath>
#include <stdexcept>

namespace spinradar::navtech {

namespace {
constexpr uint32_t kYear2000 = 946684800u;
constexpr uint32_t kYear2100 = 4102444800u;
bool plausibleDate(uint32_t s) { return s >= kYear2000 && s < kYear2100; }
uint32_t absDiff(uint32_t a, uint32_t b) { return a > b ? a - b : b - a; }
}  // namespace

TimeSource parseTimeSource(const std::string& s) {
  if (s == "sensor") return TimeSource::Sensor;
  if (s == "receive") return TimeSource::Receive;
  if (s == "smoothed") return TimeSource::Smoothed;
  throw std::invalid_argument("parameter 'time_source' = '" + s +
                              "' is not one of: sensor, receive, smoothed");
}

TimeByteOrder SensorTimeDecoder::current() const {
  if (order_ != TimeByteOrder::Auto) return order_;
  if (faults_le_ != faults_be_)
    return faults_le_ < faults_be_ ? TimeByteOrder::Little : TimeByteOrder::Big;
  return year_prefers_be_ ? TimeByteOrder::Big : TimeByteOrder::Little;
}

void SensorTimeDecoder::reset() {
  faults_le_ = faults_be_ = 0;
  have_last_ = false;
  year_prefers_be_ = false;
}

bool SensorTimeDecoder::decode(const FftData& m, int64_t& stamp_ns) {
  if (order_ == TimeByteOrder::Auto) {
    const uint32_t sle = m.seconds(false), sbe = m.seconds(true);
    if (m.nanoseconds(false) >= 1000000000u) ++faults_le_;
    if (m.nanoseconds(true) >= 1000000000u) ++faults_be_;
    if (have_last_) {
      if (absDiff(sle, last_sec_le_) > 2) ++faults_le_;
      if (absDiff(sbe, last_sec_be_) > 2) ++faults_be_;
    } else {
      year_prefers_be_ = plausibleDate(sbe) && !plausibleDate(sle);
    }
    last_sec_le_ = sle;
    last_sec_be_ = sbe;
    have_last_ = true;
  }
  const bool be = current() == TimeByteOrder::Big;
  const uint32_t ns = m.nanoseconds(be);
  if (ns >= 1000000000u) return false;
  stamp_ns = int64_t(m.seconds(be)) * 1000000000 + ns;
  return true;
}

int64_t StampChecker::check(int64_t stamp_ns, uint16_t encoder, const Configuration& c) {
  const bool had = have_last_;
  const int64_t prev_ns = last_stamp_ns_;
  const int prev_encoder = last_encoder_;
  have_last_ = true;
  last_stamp_ns_ = stamp_ns;
  last_encoder_ = encoder;
  if (!had || c.encoder_size == 0 || c.rotation_mhz == 0) return 0;
  const int e = c.encoder_size;
  const int turned = ((int(encoder) - prev_encoder) % e + e) % e;
  const double expected_ns = 1e9 * turned / (double(e) * c.rotationHz());
  // In double: stamps come off the wire and may be anything.
  const double off = double(stamp_ns) - double(prev_ns) - expected_ns;
  if (std::fabs(off) <= double(tolerance_ns_)) return 0;
  if (off > 9e18) return int64_t(9e18);
  if (off < -9e18) return int64_t(-9e18);
  return int64_t(off);
}

void ClockMapper::reset() {
  window_.clear();
  above_ = 0;
}

int64_t ClockMapper::map(int64_t sensor_ns, int64_t receive_ns) {
  const int64_t offset = receive_ns - sensor_ns;
  if (!window_.empty() && offset - window_.front().offset_ns > jump_threshold_ns_) {
    if (++above_ >= jump_samples_) {  // the sensor clock stepped back: start over
      window_.clear();
      above_ = 0;
      ++jumps_;
    }
  } else {
    above_ = 0;
  }
  while (!window_.empty() && window_.back().offset_ns >= offset) window_.pop_back();
  window_.push_back({receive_ns, offset});
  while (window_.size() > 1 && window_.front().receive_ns < receive_ns - window_ns_)
    window_.pop_front();
  return sensor_ns + window_.front().offset_ns;
}

}  // namespace spinradar::navtech
