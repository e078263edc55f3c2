#include "spinradar/driver/scan_assembler.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace spinradar::navtech {

namespace {
int64_t saturate(double t) {
  if (!(t > -9.2e18)) return int64_t(-9.2e18);
  if (t > 9.2e18) return int64_t(9.2e18);
  return int64_t(t);
}
}  // namespace

void ScanAssembler::setConfiguration(const Configuration& config) {
  if (have_config_ && config == config_) return;  // re-sent on request or reconnect
  reset();
  config_ = config;
  have_config_ = config.plausible();
}

void ScanAssembler::reset() {
  if (in_rotation_) {
    ++stats_.dropped_scans;
    ++stats_.resets;
  }
  in_rotation_ = false;
  first_after_reset_ = true;
  last_encoder_ = -1;
  phase_ = -1;
}

int ScanAssembler::rowOf(uint16_t encoder) {
  const int n = config_.azimuth_samples;
  const double step = double(config_.encoder_size) / n;
  // Sensors report azimuths at a fixed phase within each encoder step (Oxford CIR204-H data:
  // 13, 27, 41, ..., 5599; the emulator: 0, 14, 28, ...). Learn it from the first azimuth so
  // row a is the a-th azimuth of the rotation whatever the phase, then take the nearest row.
  if (phase_ < 0) phase_ = std::fmod(double(encoder), step);
  const long r = std::lround(std::floor((encoder - phase_) / step + 0.5));
  return int(((r % n) + n) % n);
}

void ScanAssembler::begin(int bins, int bit_depth) {
  const int n = config_.azimuth_samples;
  work_.scan.resize(n, bins);
  std::fill(work_.scan.valid.begin(), work_.scan.valid.end(), uint8_t(0));
  work_.scan.range_resolution = config_.rangeResolution();
  work_.scan.range_offset = config_.range_offset;
  work_.scan.encoder_size = config_.encoder_size;
  work_.bit_depth = bit_depth;
  if (bit_depth == 16)
    work_.power16.assign(size_t(n) * bins, 0);
  else
    work_.power16.clear();
  work_.config = config_;
  work_.malformed = 0;
  filled_.assign(n, 0);
  in_rotation_ = true;
  first_row_ = -1;
}

bool ScanAssembler::add(const FftData& msg, int64_t stamp_ns, int64_t receive_ns,
                        AssembledScan& out) {
  if (!have_config_ || msg.encoder >= config_.encoder_size || msg.power.empty()) {
    ++stats_.malformed;
    if (in_rotation_) ++work_.malformed;
    return false;
  }
  bool closed = false;
  if (in_rotation_ && msg.encoder < last_encoder_) closed = finish(out);
  if (!in_rotation_) begin(int(msg.power.size()), msg.bit_depth);
  last_encoder_ = msg.encoder;
  last_receive_ns_ = receive_ns;
  if (int(msg.power.size()) != work_.scan.bins || msg.bit_depth != work_.bit_depth) {
    ++stats_.malformed;
    ++work_.malformed;
    return closed;
  }
  const int row = rowOf(msg.encoder);
  if (first_row_ < 0) first_row_ = row;
  if (filled_[row]) {
    filled_[row] = 2;
  } else {
    filled_[row] = 1;
    PolarScan& s = work_.scan;
    s.encoder[row] = msg.encoder;
    s.azimuth[row] = 2.0 * M_PI * msg.encoder / config_.encoder_size;
    s.stamp_ns[row] = stamp_ns;
    uint8_t* dst = s.row(row);
    const size_t nb = msg.power.size();
    if (work_.bit_depth == 16) {
      std::copy(msg.power.begin(), msg.power.end(), work_.power16.begin() + long(row * nb));
      const double k = 1.0 / opt_.fft16_divisor;
      for (size_t b = 0; b < nb; ++b)
        dst[b] = uint8_t(std::min(255.0, std::floor(msg.power[b] * k + 0.5)));
    } else {
      for (size_t b = 0; b < nb; ++b) dst[b] = uint8_t(msg.power[b]);
    }
  }
  // The last row completes the rotation now instead of one message later at the wrap.
  if (row == config_.azimuth_samples - 1 && !closed) {
    closed = finish(out);
    last_encoder_ = -1;
  }
  return closed;
}

bool ScanAssembler::finish(AssembledScan& out) {
  in_rotation_ = false;
  const bool partial = first_after_reset_ && first_row_ != 0;
  first_after_reset_ = false;
  PolarScan& s = work_.scan;
  const int n = s.azimuths;
  int missing = 0, duplicated = 0, first_valid = -1, last_valid = -1;
  for (int a = 0; a < n; ++a) {
    if (filled_[a] == 0) ++missing;
    if (filled_[a] == 2) ++duplicated;
    if (filled_[a] == 1) {
      s.valid[a] = 1;
      if (first_valid < 0) first_valid = a;
      last_valid = a;
    }
  }
  if (!partial) stats_.missing_azimuths += uint64_t(missing);
  stats_.duplicated_azimuths += uint64_t(duplicated);
  const int valid = n - missing - duplicated;
  if (partial && opt_.drop_partial) {
    ++stats_.partial_scans;
    return false;
  }
  if (valid < opt_.min_valid_fraction * n || first_valid < 0) {
    ++stats_.dropped_scans;
    return false;
  }
  // Rows without data: nominal encoder and angle, stamps interpolated between valid rows.
  double dt = 1e9 / (config_.rotationHz() > 0 ? config_.rotationHz() * n : 4.0 * n);
  if (last_valid > first_valid)
    dt = double(s.stamp_ns[last_valid] - s.stamp_ns[first_valid]) / (last_valid - first_valid);
  int prev = -1;
  for (int a = 0; a < n; ++a) {
    if (filled_[a] == 1) {
      prev = a;
      continue;
    }
    if (filled_[a] == 2) continue;  // keeps the first copy's encoder and stamp
    s.encoder[a] = uint16_t(std::lround(phase_ + double(a) * config_.encoder_size / n) %
                            config_.encoder_size);
    s.azimuth[a] = 2.0 * M_PI * s.encoder[a] / config_.encoder_size;
    int next = a + 1;
    while (next < n && filled_[next] != 1) ++next;
    // In 128-bit / clamped double arithmetic: stamps come off the wire and may be anything.
    if (prev >= 0 && next < n)
      s.stamp_ns[a] = int64_t(__int128(s.stamp_ns[prev]) +
                              (__int128(s.stamp_ns[next]) - s.stamp_ns[prev]) * (a - prev) /
                                  (next - prev));
    else if (prev >= 0)
      s.stamp_ns[a] = saturate(double(s.stamp_ns[prev]) + dt * (a - prev));
    else
      s.stamp_ns[a] = saturate(double(s.stamp_ns[first_valid]) - dt * (first_valid - a));
  }
  work_.missing = missing;
  work_.duplicated = duplicated;
  work_.partial = partial;
  work_.sequence = sequence_++;
  work_.last_receive_ns = last_receive_ns_;
  std::swap(work_, out);
  ++stats_.scans;
  return true;
}

}  // namespace spinradar::navtech
