// Appearance stage: noise texture correlation (appearance_detail.hpp, fitTextureLength), and the
// helpers of the catalogue fit (makeFinding, physicsHasGhosts). The noise texture (a slow
// log-normal modulation of the speckle, K-like clutter) is correlated over noise_texture_bins;
// its figure is the range correlation of the counts at 10-100 m beyond the speckle's own (lag
// twice the range spread), matched by bisection over whole bins on re-simulations.
#include <algorithm>
#include <array>
#include <cmath>

#include "appearance_detail.hpp"

namespace spinradar::diagnose::detail {

using sim::SensorConfig;

bool physicsHasGhosts(const sim::PhysicsConfig& p) {
  auto it = p.extra.find("multipath");
  return it != p.extra.end() && !it->is_null() && !(it->is_boolean() && !it->get<bool>());
}

AppearanceFinding makeFinding(const std::string& effect, const std::string& param,
                              const std::string& unit, double base, double value, double sd,
                              double size, const std::string& size_unit, bool practical,
                              double z_min) {
  AppearanceFinding f;
  f.effect = effect, f.parameter = param, f.unit = unit;
  f.base = base, f.value = value, f.stddev = sd;
  f.z = sd > 0 ? std::abs(value - base) / sd : 0;
  f.size = size, f.size_unit = size_unit;
  const bool sig = f.z >= z_min;
  f.named = sig && practical;
  f.verdict = f.named ? "mismatch" : sig ? "negligible" : "not significant";
  return f;
}

namespace {

double standardError(const std::vector<double>& m) {
  if (m.size() < 2) return 0;
  double mu = 0, v = 0;
  for (double c : m) mu += c;
  mu /= double(m.size());
  for (double c : m) v += (c - mu) * (c - mu);
  return std::sqrt(v / double(m.size() - 1) / double(m.size()));
}

}  // namespace

TextureFigure rangeCorrelation(const std::vector<PolarScan>& scans, int lag) {
  // Replicates: the quarters of every scan (scene variation included in the error).
  constexpr int kQ = 4;
  std::vector<double> sxy, sxx;
  std::vector<double> x;
  for (const PolarScan& s : scans) {
    if (s.empty()) continue;
    const int b0 = std::clamp(int(std::ceil(s.binOfRange(10.0))), 0, s.bins - 1);
    const int b1 = std::clamp(int(std::floor(s.binOfRange(100.0))), b0, s.bins - 1);
    if (b1 - b0 <= lag + 1) continue;
    const size_t first = sxy.size();
    sxy.resize(first + kQ, 0.0);
    sxx.resize(first + kQ, 0.0);
    for (int a = 0; a < s.azimuths; ++a) {
      if (!s.valid.empty() && !s.valid[a]) continue;
      const size_t q = first + size_t(std::min(a * kQ / s.azimuths, kQ - 1));
      const uint8_t* r = s.row(a);
      double mu = 0;
      for (int b = b0; b <= b1; ++b) mu += r[b];
      mu /= double(b1 - b0 + 1);
      x.assign(r + b0, r + b1 + 1);
      for (double& v : x) v -= mu;
      for (size_t i = 0; i < x.size(); ++i) {
        sxx[q] += x[i] * x[i];
        if (i + lag < x.size()) sxy[q] += x[i] * x[i + lag];
      }
    }
  }
  TextureFigure out;
  double txy = 0, txx = 0;
  for (size_t q = 0; q < sxy.size(); ++q) {
    txy += sxy[q], txx += sxx[q];
    if (sxx[q] > 0) out.replicates.push_back(sxy[q] / sxx[q]);  // masked quarters drop out
  }
  out.value = txx > 0 ? txy / txx : NAN;
  out.se = standardError(out.replicates);
  return out;
}

// Standard error of a - b: paired by replicate when both hold the same number (same route).
static double differenceSe(const TextureFigure& a, const TextureFigure& b) {
  if (a.replicates.size() != b.replicates.size() || a.replicates.size() < 2)
    return std::hypot(a.se, b.se);
  std::vector<double> d(a.replicates.size());
  for (size_t i = 0; i < d.size(); ++i) d[i] = a.replicates[i] - b.replicates[i];
  return standardError(d);
}

AppearanceFinding fitTextureLength(const std::vector<PolarScan>& real, SensorConfig& cur,
                                   const sim::PhysicsConfig& phys, const AppearanceOptions& opt,
                                   std::vector<std::string>& notes) {
  const double base = cur.noise_texture_bins;
  // Beyond the speckle's own correlation (the range spread): where the texture shows.
  const int lag = std::max(1, int(std::lround(2 * cur.range_psf_sigma_bins)));
  const TextureFigure r = rangeCorrelation(real, lag);
  auto simAt = [&](double bins) {
    SensorConfig s = cur;
    s.noise_texture_bins = bins;
    return rangeCorrelation(renderReference(s, phys, opt, opt.seed), lag);
  };
  const TextureFigure m = simAt(base);
  const double gap = r.value - m.value, se = differenceSe(r, m);
  const bool identifiable = cur.noise_texture_db > 0;
  // Named when z >= z_min and practically large: the length by 40 % or more and the
  // correlation by 0.02 or more (a rescaled recording moved it by 0.009: 8 -> 6 bins).
  const bool sig = identifiable && std::isfinite(gap) && se > 0 && std::abs(gap) / se >= opt.z_min;
  double value = base, sd = 0;
  if (sig) {
    // The texture is a box of whole bins (render_model.cpp): bisection over integers 1..64,
    // the correlation grows with the length.
    int lo = 1, hi = 64;
    while (hi - lo > 1) {
      const int mid = (lo + hi) / 2;
      (simAt(mid).value < r.value ? lo : hi) = mid;
    }
    const double c_lo = simAt(lo).value, c_hi = simAt(hi).value;
    value = std::abs(c_lo - r.value) <= std::abs(c_hi - r.value) ? lo : hi;
    // Uncertainty: the figure's standard error through the local slope per bin, over -30 % to
    // +40 % and at least 2 bins (a box of L <= k bins has no correlation at lag k: flat there).
    const int s_lo = std::max(1, int(std::floor(value * 0.7)));
    const int s_hi = std::max(s_lo + 2, int(std::ceil(value * 1.4)));
    const double slope = (simAt(s_hi).value - simAt(s_lo).value) / double(s_hi - s_lo);
    sd = std::max(se / std::max(std::abs(slope), 1e-4), 0.29);  // 0.29: whole bins
    notes.push_back("Noise texture correlation: range correlation of the counts at lag " +
                    std::to_string(lag) + " bins " + std::to_string(r.value) + " (recording) vs " +
                    std::to_string(m.value) + " (model at " + std::to_string(base) +
                    " bins); fitted " + std::to_string(value) + " bins (" +
                    std::to_string(value * cur.range_resolution) + " m).");
  }
  AppearanceFinding f = makeFinding("noise texture correlation", "noise_texture_bins", "bins",
                                    base, value, sd, base > 0 ? std::abs(value / base - 1) : 0,
                                    "relative",
                                    std::abs(value / base - 1) >= 0.4 && std::abs(gap) >= 0.02,
                                    opt.z_min);
  if (!identifiable) f.verdict = "not identifiable", f.named = false;
  else if (!sig) f.verdict = "not significant", f.named = false;
  f.gap_before = gap;
  if (f.named) {
    cur.noise_texture_bins = value;
    f.gap_after = r.value - simAt(value).value;
  } else {
    f.gap_after = gap;
  }
  return f;
}

namespace {

// Std of the counts at or below the median at 10-100 m (the noise side of the distribution);
// quarter >= 0: only the rows of that quarter of each scan.
double lowerSpread(const std::vector<PolarScan>& scans, int quarter = -1) {
  std::array<double, 256> h{};
  for (const PolarScan& s : scans) {
    const int b0 = std::clamp(int(std::ceil(s.binOfRange(10.0))), 0, s.bins - 1);
    const int b1 = std::clamp(int(std::floor(s.binOfRange(100.0))), b0, s.bins - 1);
    for (int a = 0; a < s.azimuths; ++a)
      if ((s.valid.empty() || s.valid[a]) && (quarter < 0 || a * 4 / s.azimuths == quarter))
        for (int b = b0; b <= b1; ++b) h[s.row(a)[b]] += 1;
  }
  double n = 0;
  for (double c : h) n += c;
  double taken = 0, s1 = 0, s2 = 0;
  for (int c = 0; c < 256 && taken < n / 2; ++c) {
    const double k = std::min(h[c], n / 2 - taken);
    taken += k, s1 += k * c, s2 += k * double(c) * c;
  }
  if (taken < 2) return NAN;
  const double mu = s1 / taken;
  return std::sqrt(std::max(s2 / taken - mu * mu, 0.0));
}

// Relative standard error of lowerSpread from its replicates (the quarters of every scan).
double lowerSpreadRelSe(const std::vector<PolarScan>& scans) {
  std::vector<double> v;
  for (const PolarScan& s : scans)
    for (int q = 0; q < 4; ++q) {
      const double x = lowerSpread({s}, q);
      if (std::isfinite(x)) v.push_back(x);
    }
  double mu = 0;
  for (double x : v) mu += x;
  return v.size() >= 2 && mu > 0 ? standardError(v) / (mu / double(v.size())) : 0;
}

}  // namespace

AppearanceFinding fitCodeSet(const std::vector<PolarScan>& real, const AppearanceFigures& fr,
                             const AppearanceFigures& model, SensorConfig& cur,
                             const sim::PhysicsConfig& phys, const AppearanceOptions& opt,
                             std::vector<std::string>& notes) {
  // Native Navtech counts are 20 log10 of an integer amplitude: 19 distinct codes among 1-30 in
  // the base model (6, 9, 12, 14, ...; the row jitter fills a few more), the Oxford sample 19.
  // A product rescaled from dB (RADIATE's images) has all 30.
  AppearanceFinding f;
  f.effect = "log quantisation (code set)", f.parameter = "native_codes", f.unit = "";
  f.base = cur.native_codes;
  f.gap_before = fr.distinct_low_codes - model.distinct_low_codes;
  f.size = f.gap_before, f.size_unit = "codes among 1-30";
  const bool rescaled = cur.native_codes != 0 && fr.distinct_low_codes >= 27 &&
                        fr.distinct_low_codes - model.distinct_low_codes >= 6;
  f.value = rescaled ? 0 : cur.native_codes;
  f.z = rescaled ? INFINITY : 0;
  f.named = rescaled;
  f.verdict = rescaled ? "mismatch" : "not significant";
  f.gap_after = rescaled ? 0 : f.gap_before;
  if (!rescaled) return f;
  cur.native_codes = 0;
  // Counts per dB, a start for the range-curve fit (which refines it): the spread of the noise
  // side of the counts, recording over the model at 1 count per dB (levels do not move it while
  // the floor is clear of zero). Before the catalogue fit, so that peak widths measured in counts
  // compare like with like.
  const std::vector<PolarScan> model_scans = renderReference(cur, phys, opt, opt.seed);
  const double sr = lowerSpread(real), sm = lowerSpread(model_scans);
  if (std::isfinite(sr) && std::isfinite(sm) && sm > 0) {
    cur.power_scale = std::clamp(cur.power_scale * sr / sm, 0.5, 3.0);
    // Uncertainty: the spreads' scatter over the scan quarters (recording and model).
    const double sd = cur.power_scale * std::hypot(lowerSpreadRelSe(real), lowerSpreadRelSe(model_scans));
    notes.push_back("Rescaled counts (every code among 1-30): native_codes 0; counts per dB from "
                    "the spread of the noise side, " + std::to_string(sr) + " against " +
                    std::to_string(sm) + " at 1 count/dB: power_scale " +
                    std::to_string(cur.power_scale) + " +- " + std::to_string(sd) +
                    " (start of the range curves, which refine it).");
  }
  return f;
}

}  // namespace spinradar::diagnose::detail
