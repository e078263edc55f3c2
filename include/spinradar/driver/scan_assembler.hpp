#pragma once
// Azimuth messages -> one PolarScan per rotation.
//
// Rows are placed by encoder value, never by arrival order: row = nearest multiple of the
// encoder step (encoder_size / azimuths) after removing the phase at which the sensor reports
// (learned from the first azimuth after a reset: real CIR204-H data reads 13, 27, ..., 5599),
// so a lost message leaves a hole (valid = 0) instead of shifting every later row. A row that
// arrives twice keeps its first data and is marked valid = 0 (which copy is right is unknown). A rotation closes when its last row
// arrives (lowest latency) or when the encoder wraps (value smaller than the previous one).
// Missing rows get the encoder and angle they should have had, zero power, and a stamp
// interpolated from their valid neighbours so stamps stay monotonic.
//
// 16-bit data (message type 31) is kept at full precision in `power16`; the 8-bit core
// `PolarScan::power` gets min(255, round(value / fft16_divisor)). With the default divisor 256
// this is the high byte, which is the 8-bit scale when the 16-bit value is the 8-bit power
// with 8 fractional bits (how the emulator encodes it).
#include <cstdint>
#include <vector>

#include "spinradar/driver/navtech_protocol.hpp"
#include "spinradar/core/polar_scan.hpp"

namespace spinradar::navtech {

struct AssemblerOptions {
  bool drop_partial = true;          ///< drop (else mark) a rotation joined mid-way
  double min_valid_fraction = 0.5;   ///< rotations with fewer valid rows are dropped
  double fft16_divisor = 256.0;      ///< 16-bit value -> 8-bit power
};

/// One rotation as the driver publishes it.
struct AssembledScan {
  PolarScan scan;                 ///< 8-bit power, per-row angle, stamp, encoder, valid
  std::vector<uint16_t> power16;  ///< full-precision bins when bit_depth == 16, else empty
  int bit_depth = 8;
  Configuration config;           ///< sensor configuration the rotation was taken with
  uint64_t sequence = 0;          ///< rotations emitted since construction
  int missing = 0;                ///< rows without data
  int duplicated = 0;             ///< rows that arrived more than once
  int malformed = 0;              ///< messages with a wrong bin count or encoder
  bool partial = false;           ///< joined mid-rotation (only emitted with drop_partial off)
  int64_t last_receive_ns = 0;    ///< receive time of the message that closed the rotation
};

struct AssemblerStats {
  uint64_t scans = 0;
  uint64_t dropped_scans = 0;     ///< too few valid rows, or cut by a reset (disconnect, time step)
  uint64_t partial_scans = 0;     ///< joined mid-way (after a connect or reset), dropped as asked
  /// Rows lost inside rotations streamed from their start (emitted or dropped); the rows of a
  /// rotation joined mid-way were never sent to us and are not counted.
  uint64_t missing_azimuths = 0;
  uint64_t duplicated_azimuths = 0;
  uint64_t malformed = 0;
  uint64_t resets = 0;
};

class ScanAssembler {
 public:
  explicit ScanAssembler(AssemblerOptions options = {}) : opt_(options) {}

  /// A (new) configuration: a different one discards the rotation in progress.
  void setConfiguration(const Configuration& config);
  bool hasConfiguration() const { return have_config_; }
  const Configuration& configuration() const { return config_; }

  /// Adds one azimuth with its chosen stamp. Returns true when a rotation was completed and
  /// written to `out` (buffers in `out` are reused: no allocation per rotation after warm-up).
  bool add(const FftData& msg, int64_t stamp_ns, int64_t receive_ns, AssembledScan& out);

  /// Discards the rotation in progress (disconnect, restart); the next one counts as partial.
  void reset();
  const AssemblerStats& stats() const { return stats_; }

 private:
  void begin(int bins, int bit_depth);
  bool finish(AssembledScan& out);
  int rowOf(uint16_t encoder);

  AssemblerOptions opt_;
  Configuration config_;
  bool have_config_ = false;
  AssembledScan work_;
  std::vector<uint8_t> filled_;  ///< 0 empty, 1 once, 2 duplicated
  bool in_rotation_ = false;
  bool first_after_reset_ = true;
  int first_row_ = 0;
  int last_encoder_ = -1;
  double phase_ = -1;  ///< encoder phase of row 0 within one step, learned after a reset
  int64_t last_receive_ns_ = 0;
  uint64_t sequence_ = 0;
  AssemblerStats stats_;
};

}  // namespace spinradar::navtech
