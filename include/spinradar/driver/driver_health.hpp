#pragma once
// The driver's status for /diagnostics (and anyone else): a level that reflects the last few
// seconds, not the totals since start, with the reason in words.
#include <cstdint>
#include <deque>
#include <string>

#include "spinradar/driver/navtech_driver.hpp"

namespace spinradar::navtech {

enum class HealthLevel { Ok, Warn, Error };

struct Health {
  HealthLevel level = HealthLevel::Ok;
  std::string message;
};

/// Level from successive DriverStats snapshots: ERROR without a configuration or when no
/// azimuth arrived for `no_data_s`; WARN while, within the last `window_s`, bytes or messages
/// were thrown away (garbage, oversize, truncated, malformed, unknown type), the connection
/// dropped, rotations were dropped or lost azimuths (rotations joined mid-way at a connect
/// excepted: that is normal), or the sensor time was implausible or stepped (the message says
/// what happened and when); else OK.
class DriverHealth {
 public:
  explicit DriverHealth(double window_s = 5.0, double no_data_s = 2.0);
  /// `now_ns`: any monotonic clock, the same on every call.
  Health update(const DriverStats& stats, bool has_configuration, int64_t now_ns);

 private:
  struct Snapshot {
    int64_t t_ns;
    DriverStats stats;
  };
  int64_t window_ns_, no_data_ns_;
  std::deque<Snapshot> history_;  ///< oldest first; the oldest is the window's baseline
  uint64_t last_azimuths_ = 0;
  int64_t last_data_ns_ = 0;
  bool started_ = false;
};

}  // namespace spinradar::navtech
