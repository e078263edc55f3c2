#include "render_model.hpp"

#include <algorithm>
#include <cmath>

namespace spinradar::sim::detail {

double Rng::normal() {
  double u1 = uniform(), u2 = uniform();
  if (u1 < 1e-300) u1 = 1e-300;
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2 * M_PI * u2);
}

double hashUniform(uint64_t a, uint64_t b, uint64_t c) {
  uint64_t h = Rng::splitmix(a * 0x9E3779B97F4A7C15ull ^ Rng::splitmix(b ^ Rng::splitmix(c)));
  return (h >> 11) * (1.0 / 9007199254740992.0);
}

namespace {

double sinc(double x) { return std::abs(x) < 1e-9 ? 1.0 : std::sin(M_PI * x) / (M_PI * x); }

// Amplitude response of a Hann-windowed FFT, x in resolution cells (first null at |x| = 2).
double hannResponse(double x) {
  double d = 1.0 - x * x;
  if (std::abs(d) < 1e-9) return 0.5;
  return sinc(x) / d;
}

}  // namespace

RenderModel::RenderModel(const SensorConfig& s) : s_(s) {
  // Range point spread: power = |W|^2 of the Hann window response, sampled per sub-bin phase.
  psf_half_ = s.range_psf_half_width;
  psf_main_half_ = std::min(psf_half_, int(std::ceil(2.0 * s.range_cell_bins)));
  int taps = 2 * psf_half_ + 1;
  psf_.resize(size_t(kPhases) * taps);
  for (int p = 0; p < kPhases; ++p) {
    double frac = double(p) / kPhases;
    for (int k = -psf_half_; k <= psf_half_; ++k) {
      double w = hannResponse((k - frac) / s.range_cell_bins);
      psf_[size_t(p) * taps + (k + psf_half_)] = float(w * w);
    }
  }

  // Azimuth: one-way power sinc^2 with the given -3 dB width, two-way = squared, plus a sidelobe
  // plateau tapered to zero at the extent, then smeared by the rotation during one azimuth.
  extent_ = s.azimuth_extent_deg * M_PI / 180.0;
  beam_step_ = 0.0002;  // rad
  inv_beam_step_ = 1.0 / beam_step_;
  int nb = int(extent_ / beam_step_) + 2;
  double theta0 = 0.5 * s.beam_width_deg * M_PI / 180.0 / 0.44295;
  double plateau = std::pow(10.0, s.azimuth_sidelobe_db / 10.0);
  std::vector<double> raw(size_t(2 * nb + 1));
  for (int i = -nb; i <= nb; ++i) {
    double d = std::abs(i * beam_step_);
    double one = sinc(d / theta0);
    one *= one;
    double taper = d < extent_ ? 0.5 * (1 + std::cos(M_PI * d / extent_)) : 0.0;
    raw[i + nb] = one * one + plateau * taper;
  }
  double az_step = 2 * M_PI / s.azimuths;
  int box = std::max(1, int(az_step / beam_step_ / 2));
  beam_.assign(size_t(nb), 0.f);
  for (int i = 0; i < nb; ++i) {
    double acc = 0;
    int cnt = 0;
    for (int k = -box; k <= box; ++k) {
      int j = i + k + nb;
      if (j >= 0 && j < int(raw.size())) acc += raw[j];
      ++cnt;
    }
    beam_[i] = float(acc / cnt);
  }
  float peak = beam_[0];
  for (auto& g : beam_) g /= peak;
  beam_tail_.assign(beam_.size(), 0.f);
  float m = 0;
  for (int i = nb - 1; i >= 0; --i) beam_tail_[i] = m = std::max(m, beam_[i]);

  // Noise floor + diffuse clutter per bin (clutter is range dependent, referenced to 10 m).
  noise_lin_.resize(s.bins);
  thr_lin_.resize(s.bins);
  noise_q_.resize(s.bins);
  for (int b = 0; b < s.bins; ++b) {
    double r = std::max((b + 0.5) * s.range_resolution, 1.0);
    double lr = std::log10(r / 10.0);
    double n = std::pow(10.0, (s.noise_floor_db + s.noise_range_slope_db_per_decade * lr) / 10.0);
    double c = std::pow(10.0, (s.noise_floor_db + s.clutter_db + s.clutter_db_per_decade * lr) / 10.0);
    double tot = n + (s.clutter_db > 0 ? c : 0.0);
    noise_lin_[b] = float(tot);
    noise_q_[b] = int(std::lround(80.0 * std::log10(tot)));
    thr_lin_[b] = float(tot * std::pow(10.0, s.render_threshold_db / 10.0));
  }

  double rf_step = s.range_resolution / 4;
  inv_rf_step_ = 1.0 / rf_step;
  range_factor_.resize(size_t(4 * (s.bins + 2 * s.range_psf_half_width + 64)));
  for (size_t i = 0; i < range_factor_.size(); ++i)
    range_factor_[i] = float(pointPower(0.0, std::max((i + 0.5) * rf_step, 0.1)));

  // Speckle: exponential power samples (stratified; indexed at random when rendering).
  int ns = 1 << kSpeckleBits;
  speckle_lin_.resize(ns);
  speckle_q_.resize(ns);
  for (int i = 0; i < ns; ++i) {
    double u = (i + 0.5) / ns;
    double e = -std::log(u);
    speckle_lin_[i] = float(e);
    speckle_q_[i] = int16_t(std::lround(80.0 * std::log10(e)));
  }

  // Quantiser: power (1/8 dB) -> amplitude A -> integer magnitude n = floor(A) ->
  // round(power_scale * 20 log10 n). This reproduces the native Navtech code set
  // (0, 6, 9, 12, 14, 15, 17, ...) and its many zeros.
  q_min_ = -8 * 40;
  int q_max = 8 * 320;
  lut_.resize(size_t(q_max - q_min_ + 1));
  for (int q = q_min_; q <= q_max; ++q) {
    double a = std::pow(10.0, q / 8.0 / 20.0);
    double n = std::floor(a);
    double c = n >= 1 ? std::round(s.power_scale * 20.0 * std::log10(n)) : 0.0;
    lut_[q - q_min_] = uint8_t(std::clamp(c, 0.0, s.saturation));
  }
}

double RenderModel::beamHalfWidthFor(double ratio) const {
  // beam_tail_ is non-increasing: the first grid point where it falls below ratio.
  auto it = std::partition_point(beam_tail_.begin(), beam_tail_.end(),
                                 [ratio](float g) { return g >= ratio; });
  return double(it - beam_tail_.begin()) * beam_step_;
}

double RenderModel::pointPower(double rcs_db, double r) const {
  double lr = std::log10(std::max(r, 0.1));
  double db = s_.radar_constant_db + rcs_db - 40.0 * lr + s_.range_gain_db_per_decade * lr;
  return std::pow(10.0, db / 10.0);
}

uint8_t RenderModel::countOfLin(float p) const {
  if (!(p > 0)) return 0;
  return countOfQ(int(std::lround(80.0f * std::log10(p))));
}

}  // namespace spinradar::sim::detail
