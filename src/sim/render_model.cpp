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

// Near-range sensitivity time control: the receiver gain ramps up to stc_range.
double nearStc(const SensorConfig& s, double r) {
  if (s.stc_range <= 0 || r >= s.stc_range) return 1.0;
  return std::pow(std::max(r, 0.1) / s.stc_range, s.stc_near_db_per_decade / 10.0);
}

double sinc(double x) { return std::abs(x) < 1e-9 ? 1.0 : std::sin(M_PI * x) / (M_PI * x); }

}  // namespace

RenderModel::RenderModel(const SensorConfig& s) : s_(s) {
  // Range point spread: Gaussian-like mainlobe in power (fits real Navtech peaks: -29 dB at
  // +-10 bins for sigma 2.7) plus window sidelobes decaying as offset^-3.
  psf_half_ = s.range_psf_half_width;
  psf_sigma_ = float(s.range_psf_sigma_bins);
  double sl = std::pow(10.0, s.range_sidelobe_db / 10.0);
  sidelobe_ratio_ = float(1.0 / sl);
  int taps = 2 * psf_half_ + 1;
  psf_.resize(size_t(kPhases) * taps);
  for (int p = 0; p < kPhases; ++p) {
    double frac = double(p) / kPhases;
    for (int k = -psf_half_; k <= psf_half_; ++k) {
      double x = (k - frac) / s.range_psf_sigma_bins;
      double side = std::abs(x) > 2.0 ? sl * std::pow(2.0 / std::abs(x), 3.0) : sl;
      psf_[size_t(p) * taps + (k + psf_half_)] = float(std::exp(-0.5 * x * x) + side);
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

  beam_hw_.resize(4 * 64 + 2);
  for (size_t i = 0; i < beam_hw_.size(); ++i)
    beam_hw_[i] = beamHalfWidthFor(std::pow(2.0, -double(i) / 4.0));
  for (int m = 0; m < 1024; ++m) log2_mant_[m] = float(std::log2(1.0 + (m + 0.5) / 1024.0));

  // Noise floor + diffuse clutter per bin (clutter is range dependent, referenced to 10 m).
  noise_lin_.resize(s.bins);
  thr_lin_.resize(s.bins);
  noise_q_.resize(s.bins);
  for (int b = 0; b < s.bins; ++b) {
    double r = std::max((b + 0.5) * s.range_resolution, 1.0);
    double lr = std::log10(r / 10.0);
    double n = std::pow(10.0, (s.noise_floor_db + s.noise_range_slope_db_per_decade * lr) / 10.0);
    double c = std::pow(10.0, (s.noise_floor_db + s.clutter_db + s.clutter_db_per_decade * lr) / 10.0);
    double tot = (n + (s.clutter_db > 0 ? c : 0.0)) * nearStc(s, (b + 0.5) * s.range_resolution);
    // Near-range leakage (transmitter-receiver coupling, bumper/radome returns).
    if (s.leakage_db > 0)
      tot += std::pow(10.0, (s.noise_floor_db + s.leakage_db) / 10.0 -
                                (b + 0.5) * s.range_resolution / s.leakage_range);
    // Range gain curve (STC beyond the single slope): receiver gain, so noise and returns alike.
    tot *= std::pow(10.0, s.stcCurveDb((b + 0.5) * s.range_resolution) / 10.0);
    noise_lin_[b] = float(tot);
    noise_q_[b] = int16_t(std::clamp(std::lround(80.0 * std::log10(tot)), -600l, 1600l));
    thr_lin_[b] = float(tot * std::pow(10.0, s.render_threshold_db / 10.0));
  }

  double rf_step = s.range_resolution / 4;
  inv_rf_step_ = 1.0 / rf_step;
  range_factor_.resize(size_t(4 * (s.bins + 2 * s.range_psf_half_width + 64)));
  for (size_t i = 0; i < range_factor_.size(); ++i)
    range_factor_[i] = float(pointPower(0.0, std::max((i + 0.5) * rf_step, 0.1)));

  // Speckle: complex white noise through the amplitude response of the range window (the
  // square root of the Gaussian power PSF), |z|^2 normalised to mean 1: exponential marginal,
  // range-correlated like real receiver noise.
  {
    const int ns = 1 << kSpeckleBits;
    Rng rng(0x5EC3C1Eull);
    std::vector<double> re(ns), im(ns);
    for (int i = 0; i < ns; ++i) {
      re[i] = rng.normal();
      im[i] = rng.normal();
    }
    double sig_a = std::sqrt(2.0) * s.range_psf_sigma_bins;  // amplitude response std
    int hw = int(std::ceil(3 * sig_a));
    std::vector<double> h(size_t(2 * hw + 1));
    for (int k = -hw; k <= hw; ++k) h[k + hw] = std::exp(-0.5 * k * k / (sig_a * sig_a));
    std::vector<double> pw(ns);
    double mean = 0;
    for (int i = 0; i < ns; ++i) {
      double zr = 0, zi = 0;
      for (int k = -hw; k <= hw; ++k) {
        int j = (i + k) & (ns - 1);
        zr += h[k + hw] * re[j];
        zi += h[k + hw] * im[j];
      }
      pw[i] = zr * zr + zi * zi;
      mean += pw[i];
    }
    mean /= ns;
    // Texture: a slow log-normal modulation of the speckle power (range-correlated over
    // noise_texture_bins), which gives the heavy tails real clutter and noise show; the mean
    // power is kept.
    if (s.noise_texture_db > 0) {
      const int L = std::max(1, int(std::lround(s.noise_texture_bins)));
      std::vector<double> g(ns), sm(ns);
      for (int i = 0; i < ns; ++i) g[i] = rng.normal();
      double acc = 0;
      for (int k = 0; k < L; ++k) acc += g[k];
      for (int i = 0; i < ns; ++i) {
        sm[i] = acc / std::sqrt(double(L));
        acc += g[(i + L) & (ns - 1)] - g[i];
      }
      const double sig = s.noise_texture_db * std::log(10.0) / 10.0;
      double m2 = 0;
      for (int i = 0; i < ns; ++i) {
        pw[i] *= std::exp(sig * sm[i]);
        m2 += pw[i];
      }
      mean = m2 / ns;
    }
    speckle_lin_.resize(ns);
    speckle_q_.resize(ns);
    for (int i = 0; i < ns; ++i) {
      double e = std::max(pw[i] / mean, 1e-5);
      speckle_lin_[i] = float(e);
      speckle_q_[i] = int16_t(std::lround(80.0 * std::log10(e)));
    }
  }

  // Quantiser: power (1/8 dB) -> amplitude A -> integer magnitude n = floor(A) ->
  // round(power_scale * 20 log10 n). This reproduces the native Navtech code set
  // (0, 6, 9, 12, 14, 15, 17, ...) and its many zeros.
  // Range: noise level [-600, 1600] + speckle [-400, 100] + row offset +-160, and signals.
  q_min_ = -1200;
  int q_max = 8 * 330;
  lut_.resize(size_t(q_max - q_min_ + 1));
  for (int q = q_min_; q <= q_max; ++q) {
    double a = std::pow(10.0, q / 8.0 / 20.0);
    double n = std::floor(a);
    double c = n >= 1 ? s.power_scale * 20.0 * std::log10(n) : 0.0;
    // Rescaled products (RADIATE's 8-bit images): the dB value itself, every code present.
    if (s.native_codes == 0) c = std::max(0.0, s.power_scale * q / 8.0);
    // Receiver compression: above the knee the output grows by compression_ratio per count.
    if (c > s.compression_knee) c = s.compression_knee + (c - s.compression_knee) * s.compression_ratio;
    c = std::round(c);
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
  db += s_.stcCurveDb(r) + s_.returnGainDb(r);
  return std::pow(10.0, db / 10.0) * nearStc(s_, r);
}


}  // namespace spinradar::sim::detail
