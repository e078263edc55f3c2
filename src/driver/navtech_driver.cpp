#include "spinradar/driver/navtech_driver.hpp"

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
    int64_t stamp = rx;
    if (ok && time_source_ == TimeSource::Sensor) stamp = sensor;
    if (ok && time_source_ == TimeSource::Smoothed) stamp = mapper_.map(sensor, rx);
    if (assembler_.add(packet_.fft, stamp, rx, out)) return InputStatus::Ok;
    if (std::chrono::steady_clock::now() >= deadline) return InputStatus::Timeout;
  }
}

}  // namespace navtech
}  // namespace spinradar
