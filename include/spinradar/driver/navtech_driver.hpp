#pragma once
// The ROS-free Navtech driver: one RadarInput -> stamps -> ScanAssembler -> scans. The nodelet
// and the CLI are shells around this class: call poll() in a loop and publish what it returns.
#include <chrono>
#include <memory>
#include <string>

#include "spinradar/driver/driver_config.hpp"
#include "spinradar/driver/navtech_time.hpp"
#include "spinradar/driver/radar_input.hpp"
#include "spinradar/driver/scan_assembler.hpp"

namespace spinradar::navtech {

/// Everything a diagnostics page needs, cumulative since construction.
struct DriverStats {
  uint64_t azimuths = 0;           ///< FFT messages received
  uint64_t scans = 0;              ///< rotations returned by poll()
  uint64_t dropped_scans = 0;      ///< too sparse, or cut by a disconnect or a time anomaly
  uint64_t partial_scans = 0;      ///< joined mid-way (at every connect): dropped, expected
  uint64_t missing_azimuths = 0;   ///< only inside rotations streamed from their start
  uint64_t duplicated_azimuths = 0;
  uint64_t implausible_times = 0;  ///< azimuths whose sensor time was unusable
  uint64_t configurations = 0;
  uint64_t clock_jumps = 0;        ///< smoothed mapping restarts
  uint64_t time_anomalies = 0;     ///< sensor time off the rotation rate (step back, jump ahead)
  std::string last_time_anomaly;   ///< what happened and when (UTC), empty when none
  int64_t last_time_anomaly_ns = 0;  ///< receive time (wall clock) of that azimuth
  InputStats input;
  TimeByteOrder byte_order = TimeByteOrder::Little;
};

class NavtechDriver {
 public:
  /// Builds the socket or capture input from `config` (validated here).
  explicit NavtechDriver(const DriverConfig& config);
  /// Uses a given input (simulator, tests); `config` supplies the time and assembly options.
  NavtechDriver(const DriverConfig& config, std::unique_ptr<RadarInput> input);

  /// Reads until a rotation completes (Ok, scan in `out`), or the timeout passes, or the
  /// input reports Disconnected / End / Error. `out`'s buffers are reused.
  InputStatus poll(AssembledScan& out, std::chrono::milliseconds timeout);

  DriverStats stats() const;
  RadarInput& input() { return *input_; }
  void setLog(LogFn log);
  bool hasConfiguration() const { return assembler_.hasConfiguration(); }
  const Configuration& configuration() const { return assembler_.configuration(); }

 private:
  void onTimeAnomaly(int64_t off_ns, int64_t receive_ns);
  DriverConfig config_;
  std::unique_ptr<RadarInput> input_;
  TimeSource time_source_;
  SensorTimeDecoder time_decoder_;
  ClockMapper mapper_;
  StampChecker stamp_checker_;
  ScanAssembler assembler_;
  Packet packet_;
  DriverStats stats_;
  LogFn log_ = stderrLog();
};

}  // namespace spinradar::navtech
