#pragma once
// Time of a Navtech azimuth: which byte order the sensor uses for its seconds / nanoseconds,
// and how sensor time maps to the receiver's clock (sensor clocks drift and jump).
#include <cstdint>
#include <deque>
#include <string>

#include "spinradar/driver/navtech_protocol.hpp"

namespace spinradar::navtech {

/// Decodes the FFT message time. With Auto it scores both byte orders on every message (a
/// nanosecond field >= 1e9, or seconds stepping by more than 2 s between messages, is a fault
/// of that order) and uses the order with fewer faults; ties go to the order whose seconds
/// read as a date in 2000..2100, then to little-endian (what the SDK's readers assume).
class SensorTimeDecoder {
 public:
  explicit SensorTimeDecoder(TimeByteOrder order = TimeByteOrder::Auto) : order_(order) {}
  /// Returns false when the time is not plausible in the chosen order (nanoseconds >= 1e9);
  /// stamp_ns is then left unchanged.
  bool decode(const FftData& m, int64_t& stamp_ns);
  /// The order in use (Little or Big; for Auto, the current best guess).
  TimeByteOrder current() const;
  void reset();

 private:
  TimeByteOrder order_;
  uint64_t faults_le_ = 0, faults_be_ = 0;
  uint32_t last_sec_le_ = 0, last_sec_be_ = 0;
  bool have_last_ = false;
  bool year_prefers_be_ = false;
};

/// Maps sensor time onto the receive clock: t = sensor + offset, with offset the minimum of
/// (receive - sensor) over a sliding window. The minimum rejects network and scheduling delay
/// (always positive), follows slow drift within one window, follows a forward jump of the
/// sensor clock at once, and a backward jump after `jump_samples` consecutive samples that sit
/// more than `jump_threshold_ns` above the minimum.
class ClockMapper {
 public:
  explicit ClockMapper(int64_t window_ns = 5'000'000'000, int64_t jump_threshold_ns = 500'000'000,
                       int jump_samples = 32)
      : window_ns_(window_ns), jump_threshold_ns_(jump_threshold_ns), jump_samples_(jump_samples) {}
  int64_t map(int64_t sensor_ns, int64_t receive_ns);
  void reset();
  uint64_t jumps() const { return jumps_; }

 private:
  struct Sample {
    int64_t receive_ns;
    int64_t offset_ns;
  };
  int64_t window_ns_, jump_threshold_ns_;
  int jump_samples_;
  std::deque<Sample> window_;  ///< increasing offsets (monotonic queue for the minimum)
  int above_ = 0;
  uint64_t jumps_ = 0;
};

/// Checks each azimuth's sensor time against the rotation rate: from one azimuth to the next the
/// time must advance by (encoder counts turned) / (encoder_size * rotation Hz). An azimuth off
/// by more than the tolerance marks a step of the sensor clock (back or forward) or a gap in
/// the data longer than the turn suggests; either way the rotation it falls in is not one turn.
class StampChecker {
 public:
  explicit StampChecker(int64_t tolerance_ns = 100'000'000) : tolerance_ns_(tolerance_ns) {}
  /// Returns how far the stamp is off the expected one (negative: back in time), 0 when
  /// within the tolerance or when there is nothing to compare with.
  int64_t check(int64_t stamp_ns, uint16_t encoder, const Configuration& config);
  void reset() { have_last_ = false; }  ///< after a disconnect or a new configuration

 private:
  int64_t tolerance_ns_;
  bool have_last_ = false;
  int64_t last_stamp_ns_ = 0;
  uint16_t last_encoder_ = 0;
};

/// Which time an azimuth gets: `sensor` (decoded sensor time; receive time for an azimuth
/// whose sensor time is implausible), `receive`, or `smoothed` (sensor time mapped onto the
/// receive clock by ClockMapper).
enum class TimeSource { Sensor, Receive, Smoothed };
TimeSource parseTimeSource(const std::string& s);

}  // namespace spinradar::navtech
