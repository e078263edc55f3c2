// Realism figures over several noise seeds (realism_seeds.hpp).
#include "spinradar/sim/realism_seeds.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace spinradar::sim {

namespace {

// Every averaged figure of RealismStats, so that mean / lo / hi cannot miss one.
template <class F>
void forEachFigure(RealismStats& s, F&& f) {
  for (double* v : {&s.zero_fraction, &s.mean, &s.q50, &s.q90, &s.q99, &s.q999, &s.max,
                    &s.bright_fraction, &s.azimuth_corr, &s.range_corr_short, &s.range_corr_long,
                    &s.detections_cen, &s.detections_cfar, &s.cacfar, &s.beyond_mean,
                    &s.beyond_q90})
    f(*v);
  for (double* a : {s.band_mean, s.band_q90, s.band_cacfar, s.band_cen, s.band_floor, s.band_zero})
    for (int k = 0; k < 4; ++k) f(a[k]);
}

}  // namespace

std::vector<uint64_t> renderSeeds(uint64_t first, int n, uint64_t stride) {
  if (n < 1)
    throw std::invalid_argument("render seeds: " + std::to_string(n) +
                                " noise seeds asked for, at least 1 is needed");
  if (stride == 0) throw std::invalid_argument("render seeds: a seed stride of 0 repeats one seed");
  std::vector<uint64_t> s(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) s[size_t(i)] = first + uint64_t(i) * stride;
  return s;
}

SeedSpread spreadOf(const std::vector<double>& v) {
  if (v.empty()) throw std::invalid_argument("seed spread of no values");
  SeedSpread s;
  s.lo = s.hi = v.front();
  for (double x : v) {
    if (!std::isfinite(x)) throw std::invalid_argument("seed spread of a non-finite value");
    s.mean += x;
    s.lo = std::min(s.lo, x);
    s.hi = std::max(s.hi, x);
  }
  s.n = int(v.size());
  s.mean /= s.n;
  return s;
}

RealismOverSeeds realismOverSeeds(std::vector<RealismStats> per_seed) {
  if (per_seed.empty()) throw std::invalid_argument("realism over seeds: no render");
  RealismOverSeeds r;
  r.mean = r.lo = r.hi = per_seed.front();
  forEachFigure(r.mean, [](double& v) { v = 0; });
  for (RealismStats s : per_seed) {  // a copy: forEachFigure walks mutable fields
    std::vector<double> vals;
    forEachFigure(s, [&](double& v) { vals.push_back(v); });
    size_t i = 0;
    forEachFigure(r.mean, [&](double& v) { v += vals[i++]; });
    i = 0;
    forEachFigure(r.lo, [&](double& v) { v = std::min(v, vals[i++]); });
    i = 0;
    forEachFigure(r.hi, [&](double& v) { v = std::max(v, vals[i++]); });
  }
  const double n = double(per_seed.size());
  forEachFigure(r.mean, [n](double& v) { v /= n; });
  r.per_seed = std::move(per_seed);
  return r;
}

RealismOverSeeds realismOverSeeds(const SeedRender& render, const std::vector<uint64_t>& seeds,
                                  const std::string& name, const RealismOptions& options) {
  std::vector<RealismStats> per_seed;
  per_seed.reserve(seeds.size());
  for (uint64_t seed : seeds) per_seed.push_back(computeRealism(render(seed), name, options));
  return realismOverSeeds(std::move(per_seed));
}

SeedSpread worstGapOverSeeds(
    const RealismOverSeeds& sim, const RealismStats& real,
    const std::function<std::vector<double>(const RealismStats&, const RealismStats&)>& gaps) {
  std::vector<double> worst;
  for (const auto& s : sim.per_seed) {
    double w = 0;
    for (double g : gaps(s, real)) w = std::max(w, g);
    worst.push_back(w);
  }
  return spreadOf(worst);
}

}  // namespace spinradar::sim
