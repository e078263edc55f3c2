// Appearance stage: speckle of extended targets (appearance_detail.hpp, fitReturnSpeckle), and
// the helpers of the catalogue fit (makeFinding, physicsHasGhosts). The
// simulator sums the powers of the scatterers a bin holds (walls, clutter), so an extended return
// is smooth; a real one is the coherent sum, exponential in power from cell to cell and from
// pulse to pulse. The figure: how much the counts of bright cells (15 counts over the floor) jump
// between neighbouring bins and neighbouring rows at 10-100 m. The level return_speckle (0 = off,
// 1 = fully developed) by bisection on re-simulations; the roughness grows with it.
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

Roughness returnRoughness(const std::vector<PolarScan>& scans) {
  constexpr int kQ = 4;  // replicates: scan quarters
  std::array<double, kQ> sum{}, n{};
  for (const PolarScan& s : scans) {
    if (s.empty()) continue;
    const int b0 = std::clamp(int(std::ceil(s.binOfRange(10.0))), 0, s.bins - 1);
    const int b1 = std::clamp(int(std::floor(s.binOfRange(100.0))), b0, s.bins - 1);
    auto valid = [&](int a) { return s.valid.empty() || s.valid[a]; };
    // Floor: mean of the lower half of the counts at 10-100 m (histogram).
    std::array<double, 256> h{};
    double cells = 0;
    for (int a = 0; a < s.azimuths; ++a)
      if (valid(a))
        for (int b = b0; b <= b1; ++b) h[s.row(a)[b]] += 1, cells += 1;
    if (cells < 2) continue;
    double acc = 0, taken = 0;
    for (int c = 0; c < 256 && taken < cells / 2; ++c) {
      const double k = std::min(h[c], cells / 2 - taken);
      acc += k * c, taken += k;
    }
    const int thr = int(std::lround(acc / taken + 15));
    for (int a = 0; a < s.azimuths; ++a) {
      const int an = (a + 1) % s.azimuths;
      if (!valid(a)) continue;
      const int q = std::min(a * kQ / s.azimuths, kQ - 1);
      const uint8_t *r = s.row(a), *rn = s.row(an);
      for (int b = b0; b < b1; ++b) {
        if (r[b] < thr) continue;
        if (r[b + 1] >= thr) sum[q] += std::abs(int(r[b]) - int(r[b + 1])), n[q] += 1;
        if (valid(an) && rn[b] >= thr) sum[q] += std::abs(int(r[b]) - int(rn[b])), n[q] += 1;
      }
    }
  }
  Roughness out;
  double tot = 0, cnt = 0;
  std::vector<double> m;
  for (int q = 0; q < kQ; ++q) {
    tot += sum[q], cnt += n[q];
    if (n[q] >= 20) m.push_back(sum[q] / n[q]);
  }
  out.value = cnt > 0 ? tot / cnt : NAN;
  out.pairs = cnt;
  if (m.size() >= 2) {
    double mu = 0, v = 0;
    for (double x : m) mu += x;
    mu /= double(m.size());
    for (double x : m) v += (x - mu) * (x - mu);
    out.se = std::sqrt(v / double(m.size() - 1) / double(m.size()));
  }
  return out;
}

AppearanceFinding fitReturnSpeckle(const std::vector<PolarScan>& real, SensorConfig& cur,
                                   const sim::PhysicsConfig& phys, const AppearanceOptions& opt,
                                   std::vector<std::string>& notes) {
  const double base = cur.return_speckle;
  const Roughness r = returnRoughness(real);
  auto simAt = [&](double f) {
    SensorConfig s = cur;
    s.return_speckle = f;
    return returnRoughness(renderReference(s, phys, opt, opt.seed));
  };
  const Roughness m = simAt(base);
  const double gap = r.value - m.value, se = std::hypot(r.se, m.se);
  const bool sig = std::isfinite(gap) && se > 0 && std::abs(gap) / se >= opt.z_min;
  double value = base, sd = 0;
  if (sig) {
    // Bisection on [0, 1]: the roughness grows with the level.
    double lo = 0, hi = 1;
    const double at_hi = simAt(1.0).value;
    if (r.value >= at_hi) {
      lo = hi = 1.0;
      notes.push_back("Speckle of extended targets: the recording's bright cells jump by " +
                      std::to_string(r.value) + " counts between neighbours, more than fully "
                      "developed speckle gives in the reference scene (" + std::to_string(at_hi) +
                      "): return_speckle on its bound 1.");
    }
    for (int it = 0; it < 9 && hi - lo > 1e-3; ++it) {
      const double mid = 0.5 * (lo + hi);
      (simAt(mid).value < r.value ? lo : hi) = mid;
    }
    value = 0.5 * (lo + hi);
    // Uncertainty: the recording's standard error through the local slope (+-0.15).
    const double a = std::max(value - 0.15, 0.0), b = std::min(value + 0.15, 1.0);
    const double slope = (simAt(b).value - simAt(a).value) / (b - a);
    sd = r.se / std::max(std::abs(slope), 0.05);
  }
  AppearanceFinding f = makeFinding("speckle of extended targets", "return_speckle", "",
                                    base, value, sd, std::abs(value - base), "",
                                    std::abs(value - base) >= 0.1, opt.z_min);
  if (!sig) f.verdict = "not significant", f.named = false;
  f.gap_before = gap;
  if (f.named) {
    cur.return_speckle = value;
    f.gap_after = r.value - simAt(value).value;
  } else {
    f.gap_after = gap;
  }
  return f;
}

}  // namespace spinradar::diagnose::detail
