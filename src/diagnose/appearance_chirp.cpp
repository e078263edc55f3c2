// Appearance stage: alternating chirps of unequal range resolution (appearance_detail.hpp,
// fitOddRangeSpread). Boreas-RT's RAS6 alternates down and up chirps row by row; in its sample
// the up chirp's (odd rows') returns are about 1.4 times as wide along range as the down
// chirp's, and its noise is correlated over more bins, so the even rows give 2.6-3.4 times the
// plain CA-CFAR cells of the odd ones at 10-100 m. One range spread for every row cannot give
// both. The figure is the ratio of the mean -6 dB range widths of strong isolated returns,
// odd rows over even rows of the same scans (the scene cancels: neighbouring rows see the same
// objects); sensor key range_psf_odd_ratio is matched to it on re-simulations.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "appearance_detail.hpp"

namespace spinradar::diagnose::detail {

using sim::SensorConfig;

ParityWidths parityRangeWidths(const std::vector<PolarScan>& scans, double counts_per_db,
                               double sigma_bins) {
  // A return: the largest count within +-win bins, at least 20 dB over the median of its row's
  // 10-100 m counts; its width: the contiguous bins within 6 dB of it.
  const int win = std::max(4, int(std::ceil(6 * sigma_bins)));
  const double over = 20 * counts_per_db, drop = 6 * counts_per_db;
  std::vector<double> w[2];
  std::vector<int> sorted;
  for (const PolarScan& s : scans) {
    if (s.empty()) continue;
    const int b0 = std::clamp(int(std::ceil(s.binOfRange(10.0))), win, s.bins - 1);
    const int b1 = std::clamp(int(std::floor(s.binOfRange(100.0))), b0, s.bins - 1 - win);
    if (b1 - b0 < 4 * win) continue;
    for (int a = 0; a < s.azimuths; ++a) {
      if (!s.valid.empty() && !s.valid[a]) continue;
      const uint8_t* r = s.row(a);
      sorted.assign(r + b0, r + b1 + 1);
      std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
      const double floor = sorted[sorted.size() / 2];
      for (int b = b0; b <= b1; ++b) {
        const int v = r[b];
        if (v < floor + over || v < r[b + 1] || v <= r[b - 1]) continue;
        bool top = true;  // ties go to the first bin
        for (int k = b - win; k < b && top; ++k) top = r[k] < v;
        for (int k = b + 1; k <= b + win && top; ++k) top = r[k] <= v;
        if (!top) continue;
        int lo = b, hi = b;
        while (lo > b - win && r[lo - 1] >= v - drop) --lo;
        while (hi < b + win && r[hi + 1] >= v - drop) ++hi;
        if (lo == b - win || hi == b + win) continue;  // extended: no single response
        w[a & 1].push_back(hi - lo + 1);
      }
    }
  }
  ParityWidths out;
  double mean[2] = {NAN, NAN}, se[2] = {0, 0};
  for (int p = 0; p < 2; ++p) {
    const size_t n = w[p].size();
    (p ? out.n_odd : out.n_even) = int(n);
    if (n < 10) continue;
    double s1 = 0, s2 = 0;
    for (double x : w[p]) s1 += x, s2 += x * x;
    mean[p] = s1 / double(n);
    se[p] = std::sqrt(std::max(s2 / double(n) - mean[p] * mean[p], 0.0) / double(n - 1));
  }
  out.even = mean[0], out.odd = mean[1], out.se_even = se[0], out.se_odd = se[1];
  out.ratio = mean[1] / mean[0];
  out.se = std::isfinite(out.ratio) ? out.ratio * std::hypot(se[0] / mean[0], se[1] / mean[1]) : 0;
  return out;
}

bool fitAlternatingChirps(const std::vector<PolarScan>& real, SensorConfig& cur,
                          const sim::PhysicsConfig& phys, const AppearanceOptions& opt,
                          std::vector<AppearanceFinding>& findings,
                          std::vector<std::string>& notes) {
  const double base = cur.range_psf_odd_ratio, base_sigma = cur.range_psf_sigma_bins;
  const double cpd = cur.power_scale;
  const ParityWidths r = parityRangeWidths(real, cpd, base_sigma);
  auto simAt = [&](double sigma, double ratio) {
    SensorConfig s = cur;
    s.range_psf_sigma_bins = sigma, s.range_psf_odd_ratio = ratio;
    return parityRangeWidths(renderReference(s, phys, opt, opt.seed), cpd, base_sigma);
  };
  const ParityWidths m = simAt(base_sigma, base);
  const double gap = r.ratio - m.ratio, se = std::hypot(r.se, m.se);
  const bool measured = std::isfinite(gap) && se > 0;
  const bool sig = measured && std::abs(gap) / se >= opt.z_min;
  // The -6 dB width of a Gaussian power response grows by 2 sqrt(2 ln 10^0.6) = 3.32 bins per
  // bin of its std: fixed-point steps on the even rows' width (range_psf_sigma_bins) and the
  // odd rows' (its product with the ratio), at most 6 re-simulations.
  constexpr double kSlope = 3.32;
  double sigma = base_sigma, value = base, sd = 0, sd_sigma = 0;
  ParityWidths fit = m;
  if (sig) {
    for (int it = 0; it < 6; ++it) {
      const double s_even = std::clamp(sigma + (r.even - fit.even) / kSlope, 0.3, 20.0);
      const double s_odd = std::clamp(sigma * value + (r.odd - fit.odd) / kSlope, 0.3, 20.0);
      const double next = std::clamp(s_odd / s_even, 0.5, 3.0);
      const bool done = std::abs(s_even - sigma) < 0.01 && std::abs(next - value) < 0.005;
      sigma = s_even, value = next;
      if (done) break;
      fit = simAt(sigma, value);
    }
    // Uncertainty: the mean widths' standard errors through the slope.
    sd_sigma = std::hypot(r.se_even, fit.se_even) / kSlope;
    sd = value * std::hypot(sd_sigma / sigma, std::hypot(r.se_odd, fit.se_odd) / kSlope / (sigma * value));
  }
  std::ostringstream note;
  note << "Alternating chirps: mean -6 dB range width of strong isolated returns, odd / even rows "
       << r.odd << " / " << r.even << " bins (" << r.n_odd << " / " << r.n_even
       << " returns), ratio " << r.ratio << " +- " << r.se << " (recording) against " << m.ratio
       << " +- " << m.se << " (model at range_psf_odd_ratio " << base << ")";
  if (sig)
    note << "; fitted range_psf_odd_ratio " << value << " +- " << sd << ", range_psf_sigma_bins "
         << sigma << " +- " << sd_sigma << " (model widths " << fit.odd << " / " << fit.even
         << "; this replaces the catalogue's range point spread, fitted to the pooled rows, whose "
            "isolated-peak window cuts the wider rows' responses)";
  notes.push_back(note.str() + ".");
  AppearanceFinding f = makeFinding("odd-row range spread (alternating chirps)",
                                    "range_psf_odd_ratio", "", base, value, sd,
                                    std::abs(value / base - 1), "relative",
                                    std::abs(value / base - 1) >= opt.width_rel_min, opt.z_min);
  if (!measured) f.verdict = "not identifiable", f.named = false;
  else if (!sig) f.verdict = "not significant", f.named = false;
  f.gap_before = gap;
  f.gap_after = sig ? r.ratio - fit.ratio : gap;
  findings.push_back(f);
  if (!f.named) return false;
  cur.range_psf_odd_ratio = value;
  AppearanceFinding g = makeFinding("range point spread", "range_psf_sigma_bins", "bins",
                                    base_sigma, sigma, sd_sigma, std::abs(sigma / base_sigma - 1),
                                    "relative",
                                    std::abs(sigma / base_sigma - 1) >= opt.width_rel_min, opt.z_min);
  g.gap_before = r.even - m.even, g.gap_after = r.even - fit.even;
  // It replaces the catalogue's range point spread (fitted to the pooled rows before it): the
  // base and the figure stay the catalogue's base model's.
  auto old = std::find_if(findings.begin(), findings.end(), [](const AppearanceFinding& x) {
    return x.parameter == "range_psf_sigma_bins";
  });
  if (old != findings.end()) {
    g = makeFinding(g.effect, g.parameter, g.unit, old->base, sigma, sd_sigma,
                    std::abs(sigma / old->base - 1), "relative",
                    std::abs(sigma / old->base - 1) >= opt.width_rel_min, opt.z_min);
    g.gap_before = old->gap_before, g.gap_after = r.even - fit.even;
    *old = g;
  } else {
    findings.push_back(g);
  }
  cur.range_psf_sigma_bins = sigma;  // fitted, named or not
  return true;
}

}  // namespace spinradar::diagnose::detail
