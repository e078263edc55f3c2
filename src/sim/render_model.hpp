#pragma once
// Precomputed sensor response tables: range point spread (Hann FFT window), two-way azimuth
// beam pattern, per-bin noise/clutter level, speckle samples and the log-power quantiser.
// Built once per Simulator; read-only afterwards (so rendering is thread-safe).
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "spinradar/sim/sensor_config.hpp"

namespace spinradar::sim::detail {

/// Fast deterministic RNG (splitmix64 seeding + xorshift64*).
struct Rng {
  uint64_t s;
  explicit Rng(uint64_t seed) : s(splitmix(seed) | 1) {}
  static uint64_t splitmix(uint64_t x) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
  }
  uint64_t next() {
    s ^= s >> 12;
    s ^= s << 25;
    s ^= s >> 27;
    return s * 0x2545F4914F6CDD1Dull;
  }
  double uniform() { return (next() >> 11) * (1.0 / 9007199254740992.0); }
  double normal();
};

/// Hash of a few integers to a uniform double in [0, 1) (scene texture independent of seed).
double hashUniform(uint64_t a, uint64_t b, uint64_t c = 0);

class RenderModel {
 public:
  explicit RenderModel(const SensorConfig& s);

  // ---- range point spread: power at offsets -H..H around fractional bin position ----
  static constexpr int kPhases = 16;
  int psfHalf() const { return psf_half_; }
  /// Half width needed for a return `ratio` times above the render threshold.
  int psfHalfFor(float ratio) const {
    if (ratio >= sidelobe_ratio_) return psf_half_;
    if (ratio <= 1.f) return 1;
    int h = int(psf_sigma_ * std::sqrt(2.0f * std::log(ratio))) + 1;
    return h < psf_half_ ? h : psf_half_;
  }
  /// Taps for sub-bin phase p (0..kPhases-1), offsets -H..H (2H+1 values).
  const float* psf(int phase) const { return &psf_[size_t(phase) * (2 * psf_half_ + 1)]; }

  // ---- azimuth pattern (two-way power, peak 1) ----
  float beamGain(double delta_rad) const {
    double x = std::abs(delta_rad) * inv_beam_step_;
    size_t i = size_t(x);
    if (i + 1 >= beam_.size()) return 0.f;
    float f = float(x - double(i));
    return beam_[i] + f * (beam_[i + 1] - beam_[i]);
  }
  /// Half width (rad) beyond which the gain stays below `ratio` (0 < ratio <= 1).
  double beamHalfWidthFor(double ratio) const;
  double beamExtent() const { return extent_; }

  // ---- levels ----
  /// Mean noise + clutter power (linear) in bin b.
  float noiseLin(int b) const { return noise_lin_[b]; }
  /// Noise level of bin b in 1/8 dB units.
  int noiseQ(int b) const { return noise_q_[b]; }
  const int16_t* noiseQData() const { return noise_q_.data(); }
  /// Contributions below this (linear) in bin b are skipped.
  float thresholdLin(int b) const { return thr_lin_[b]; }
  /// Linear received power of `rcs_db` at range r (m) before beam and incidence factors.
  double pointPower(double rcs_db, double r) const;
  /// Linear received power of a 1 m^2 point at range r (tabulated per 1/4 bin).
  float rangeFactor(double r) const {
    size_t i = size_t(std::max(r, 0.0) * inv_rf_step_);
    return range_factor_[std::min(i, range_factor_.size() - 1)];
  }

  // ---- speckle and quantiser ----
  /// Speckle: a long sequence of exponential power samples that is correlated along range the
  /// way receiver noise is after the range FFT window. A row reads it from a random start.
  static constexpr int kSpeckleBits = 18;
  static constexpr uint32_t kSpeckleMask = (1u << kSpeckleBits) - 1;
  float speckleLin(uint32_t i) const { return speckle_lin_[i & kSpeckleMask]; }
  int16_t speckleQ(uint32_t i) const { return speckle_q_[i & kSpeckleMask]; }
  const int16_t* speckleQData() const { return speckle_q_.data(); }
  /// Largest per-azimuth level offset (1/8 dB) the count table is sized for.
  static constexpr int kMaxRowOffsetQ = 160;
  /// Count table indexed directly by a level in 1/8 dB: noise level + speckle + row offset
  /// (with |offset| <= kMaxRowOffsetQ) is always inside it.
  const uint8_t* countTable() const { return lut_.data() - q_min_; }
  /// Output count of a power level in 1/8 dB units.
  uint8_t countOfQ(int q) const {
    q -= q_min_;
    if (q < 0) return 0;
    if (q >= int(lut_.size())) return lut_.back();
    return lut_[q];
  }
  /// Output count of a linear power (fast log2 from the float's exponent and mantissa).
  uint8_t countOfLin(float p) const {
    if (!(p > 1e-30f)) return 0;
    uint32_t bits;
    std::memcpy(&bits, &p, sizeof bits);
    int e = int((bits >> 23) & 255u) - 127;
    float l2 = float(e) + log2_mant_[(bits >> 13) & 1023u];
    // q = 80 log10(p) = 80 log10(2) log2(p), rounded (offset keeps the cast a floor).
    int q = int(l2 * 24.0823996531f + 4096.5f) - 4096;
    return countOfQ(q);
  }
  /// Half width (rad) of the azimuth pattern above 1 / ratio, from a log-spaced table.
  double beamHalfWidthForRatio(double ratio) const {
    if (ratio <= 1.0) return 0.0;
    double l = std::log2(ratio) * 4.0;
    size_t i = size_t(l) + 1;  // conservative: next table entry up
    return beam_hw_[std::min(i, beam_hw_.size() - 1)];
  }

 private:
  const SensorConfig s_;
  int psf_half_ = 0;
  float psf_sigma_ = 1.f, sidelobe_ratio_ = 1e6f;
  std::vector<float> psf_;
  double extent_ = 0, beam_step_ = 0, inv_beam_step_ = 0;
  std::vector<float> beam_;       // gain on a fine grid of |delta|
  std::vector<float> beam_tail_;  // max gain at or beyond each grid point
  std::vector<float> noise_lin_, thr_lin_;
  std::vector<float> range_factor_;
  double inv_rf_step_ = 1;
  std::vector<int16_t> noise_q_;
  std::vector<float> speckle_lin_;
  std::vector<int16_t> speckle_q_;
  int q_min_ = 0;
  std::vector<uint8_t> lut_;
  float log2_mant_[1024];
  std::vector<double> beam_hw_;  // half width for ratio = 2^(i/4)
};

}  // namespace spinradar::sim::detail
