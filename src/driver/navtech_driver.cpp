#include "spinradar/driver/navtech_driver.hpp"

#include <cmath>
#include <ctime>
#include <iomanip>
#include <sstream>

#include "spinradar/core/param_check.hpp"

namespace spinradar {

void DriverConfig::validate() const {
  checkParamRanges(*this, "driver");
  checkOneOf(input, {"socket", "capture", "sim"}, "input");
  checkOneOf(time_source, {"sensor", "receive", "smoothed"}, "time_source");
  checkOneOf(time_byte_order, {"auto", "little", "big"}, "time_byte_order");
  if (backoff_min > backoff_max)
    throw std::invalid_argument("parameter 'backoff_min' must not exceed 'backoff_max'");
  if (input == "capture" && capture_file.empty())
    throw std::invalid_argument("parameter 'capture_file' is required with input 'capture'");
}

namespace navtech {

namespace {
/// Wall-clock time as ISO 8601 UTC with milliseconds.
std::string utcString(int64_t ns) {
  const time_t sec = time_t(ns / 1000000000);
  tm t{};
  gmtime_r(&sec, &t);
  std::ostringstream o;
  o << std::put_time(&t, "%Y-%m-%dT%H:%M:%S") << '.' << std::setw(3) << std::setfill('0')
    << (ns / 1000000) % 1000 << 'Z';
  return o.str();
}

AssemblerOptions assemblerOptions(const DriverConfig& c) {
  AssemblerOptions o;
  o.drop_partial = c.drop_partial;
  o.min_valid_fraction = c.min_valid_fraction;
  o.fft16_divisor = c.fft16_divisor;
  return o;
}
}  // namespace

NavtechDriver::NavtechDriver(const DriverConfig& config)
    : NavtechDriver(config, (config.validate(), makeInput(config))) {}

NavtechDriver::NavtechDriver(const DriverConfig& config, std::unique_ptr<RadarInput> input)
    : config_(config),
      input_(std::move(input)),
      time_source_(parseTimeSource(config.time_source)),
      time_decoder_(parseTimeByteOrder(config.time_byte_order)),
      mapper_(int64_t(config.smoothing_window * 1e9)),
      stamp_checker_(int64_t(config.time_jump_tolerance * 1e9)),
      assembler_(assemblerOptions(config)) {
  config_.validate();
}

void NavtechDriver::setLog(LogFn log) {
  log_ = log ? log : stderrLog();
  input_->setLog(log_);
}

DriverStats NavtechDriver::stats() const {
  DriverStats s = stats_;
  const AssemblerStats& a = assembler_.stats();
  s.scans = a.scans;
  s.dropped_scans = a.dropped_scans;
  s.partial_scans = a.partial_scans;
  s.missing_azimuths = a.missing_azimuths;
  s.duplicated_azimuths = a.duplicated_azimuths;
  s.clock_jumps = mapper_.jumps();
  s.input = input_->stats();
  s.byte_order = time_decoder_.current();
  return s;
}

InputStatus NavtechDriver::poll(AssembledScan& out, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    const InputStatus st = input_->next(packet_, std::max(left, std::chrono::milliseconds(0)));
    if (st == InputStatus::Disconnected) {
      assembler_.reset();  // never publish a rotation cut by the disconnect
      time_decoder_.reset();
      mapper_.reset();
      stamp_checker_.reset();
      return st;
    }
    if (st != InputStatus::Ok) return st;
    if (packet_.kind == Packet::Kind::Configuration) {
      const Configuration& c = packet_.config;
      ++stats_.configurations;
      if (!c.plausible()) {
        log_(LogLevel::Error, input_->describe() + ": implausible configuration (azimuths " +
                                  std::to_string(c.azimuth_samples) + ", encoder " +
                                  std::to_string(c.encoder_size) + "): data ignored until a valid one");
      } else if (!assembler_.hasConfiguration() || c != assembler_.configuration()) {
        std::ostringstream m;
        m << input_->describe() << ": configuration " << c.azimuth_samples << " azimuths, "
          << c.range_in_bins << " bins of " << c.rangeResolution() << " m, encoder "
          << c.encoder_size << ", " << c.rotationHz() << " Hz"
          << (assembler_.hasConfiguration() ? " (changed: rotation in progress discarded)" : "");
        log_(LogLevel::Info, m.str());
      }
      if (!assembler_.hasConfiguration() || c != assembler_.configuration()) stamp_checker_.reset();
      assembler_.setConfiguration(c);
      continue;
    }
    ++stats_.azimuths;
    const int64_t rx = packet_.receive_ns;
    int64_t sensor = 0;
    const bool ok = time_decoder_.decode(packet_.fft, sensor);
    if (!ok && stats_.implausible_times++ % 1000 == 0 && time_source_ != TimeSource::Receive)
      log_(LogLevel::Warn, input_->describe() + ": implausible sensor time (nanoseconds >= 1e9); "
                                                "using receive time for that azimuth");
    if (ok && time_source_ != TimeSource::Receive && assembler_.hasConfiguration()) {
      const int64_t off = stamp_checker_.check(sensor, packet_.fft.encoder, assembler_.configuration());
      if (off != 0) onTimeAnomaly(off, rx);
    }
    int64_t stamp = rx;
    if (ok && time_source_ == TimeSource::Sensor) stamp = sensor;
    if (ok && time_source_ == TimeSource::Smoothed) stamp = mapper_.map(sensor, rx);
    if (assembler_.add(packet_.fft, stamp, rx, out)) return InputStatus::Ok;
    if (std::chrono::steady_clock::now() >= deadline) return InputStatus::Timeout;
  }
}

void NavtechDriver::onTimeAnomaly(int64_t off_ns, int64_t receive_ns) {
  // The rotation in progress holds azimuths from both sides of the step: it is not one turn.
  // It is dropped, and so is the rest of it (joined mid-way); the next whole rotation is
  // published. The smoothed mapping starts over on the new sensor time at once.
  ++stats_.time_anomalies;
  std::ostringstream m;
  m << std::fixed << std::setprecision(3)
    << (off_ns < 0 ? "sensor clock stepped back by " : "sensor time jumped forward by ")
    << std::fabs(off_ns * 1e-9) << " s" << (off_ns < 0 ? "" : " (clock step or gap in the data)")
    << " at " << utcString(receive_ns) << " (azimuth " << stats_.azimuths << ")";
  stats_.last_time_anomaly = m.str();
  stats_.last_time_anomaly_ns = receive_ns;
  log_(LogLevel::Warn, input_->describe() + ": " + m.str() +
                           ": rotation in progress dropped, clock mapping re-anchored");
  assembler_.reset();
  mapper_.reset();
}

}  // namespace navtech
}  // namespace spinradar
