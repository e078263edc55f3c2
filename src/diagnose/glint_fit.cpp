// Fit of the glint (glint_fit.hpp).
#include "spinradar/diagnose/glint_fit.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "spinradar/sim/scenes.hpp"
#include "spinradar/sim/simulator.hpp"

namespace spinradar::diagnose {

namespace {

double glintOf(const sim::PhysicsConfig& p) {
  auto it = p.extra.find("glint");
  return it != p.extra.end() && it->is_number() ? it->get<double>() : 0.0;
}

// Piecewise-linear inverse of the (made monotone) reference curve: glint giving spread s.
double inverse(const std::vector<double>& g, const std::vector<double>& s, double x) {
  if (x <= s.front()) return g.front();
  for (size_t i = 1; i < s.size(); ++i)
    if (x <= s[i]) return g[i - 1] + (x - s[i - 1]) / std::max(s[i] - s[i - 1], 1e-9) * (g[i] - g[i - 1]);
  return g.back();
}

double interp(const std::vector<double>& g, const std::vector<double>& v, double x) {
  if (x <= g.front()) return v.front();
  for (size_t i = 1; i < g.size(); ++i)
    if (x <= g[i]) return v[i - 1] + (x - g[i - 1]) / (g[i] - g[i - 1]) * (v[i] - v[i - 1]);
  return v.back();
}

}  // namespace

MatchedSpread referenceSpread(const sim::SensorConfig& sensor, const sim::PhysicsConfig& physics,
                              const GlintOptions& opt) {
  sim::Scene sc = sim::builtinScene(opt.scene);
  sim::Simulator s(std::move(sc.world), std::move(sc.trajectory), sensor, physics, opt.seed);
  const int total = s.scanCount();
  // Scans opt.spread.stride apart, as the recording's pairs (the motion between them adds spread).
  const int k_gap = std::max(1, opt.spread.stride);
  const int n = std::min(opt.scans, (total - 1) / k_gap + 1), S = std::max(1, opt.segments);
  const int width = (n - 1) * k_gap + 1;
  std::vector<MatchedSpread> seg;
  for (int k = 0; k < S; ++k) {
    const int first = std::clamp(int((k + 0.5) * total / S) - width / 2, 0, total - width);
    std::vector<PolarScan> scans;
    for (int i = first; i < first + width; i += k_gap) scans.push_back(s.renderScan(i));
    seg.push_back(measureMatchedSpread(scans, nullptr, opt.spread));
  }
  // Average of the segments: matches-weighted per band; the pooled figure's standard error from
  // the segments' scatter (or their own, if larger).
  MatchedSpread out = seg.front();
  auto merge = [&](auto get) {
    SpreadBand m;
    double w = 0, se2t = 0, se2r = 0;
    std::vector<double> t, r;
    for (auto& x : seg) {
      const SpreadBand& b = get(x);
      if (!std::isfinite(b.tangential) || b.matches < 2) continue;
      m.tangential += b.matches * b.tangential, m.radial += b.matches * b.radial;
      m.range += b.matches * b.range;
      se2t += b.tangential_se * b.tangential_se, se2r += b.radial_se * b.radial_se;
      w += b.matches, m.matches += b.matches;
      t.push_back(b.tangential), r.push_back(b.radial);
    }
    if (w <= 0) return SpreadBand{NAN, NAN, NAN, NAN, 0};
    m.tangential /= w, m.radial /= w, m.range /= w;
    auto sdOf = [](const std::vector<double>& v) {
      if (v.size() < 2) return 0.0;
      double mu = 0, sd = 0;
      for (double x : v) mu += x;
      mu /= v.size();
      for (double x : v) sd += (x - mu) * (x - mu);
      return std::sqrt(sd / (v.size() - 1));
    };
    const double n = double(t.size());
    m.tangential_se = std::max(std::sqrt(se2t) / n, sdOf(t) / std::sqrt(n));
    m.radial_se = std::max(std::sqrt(se2r) / n, sdOf(r) / std::sqrt(n));
    return m;
  };
  for (int b = 0; b < 4; ++b) out.band[b] = merge([b](MatchedSpread& x) -> SpreadBand& { return x.band[b]; });
  out.all = merge([](MatchedSpread& x) -> SpreadBand& { return x.all; });
  out.pairs = 0;
  for (auto& x : seg) out.pairs += x.pairs;
  return out;
}

GlintFit fitGlint(const std::vector<PolarScan>& recording, const sim::SensorConfig& sensor,
                  const sim::PhysicsConfig& physics, const GlintOptions& opt) {
  if (opt.grid.size() < 2 || opt.grid.front() != 0.0)
    throw std::invalid_argument("glint fit: the grid must start at 0 and hold two values or more");
  GlintFit f;
  f.base = glintOf(physics);
  f.real = measureMatchedSpread(recording, nullptr, opt.spread);
  f.measured = f.real.pairs > 0 && std::isfinite(f.real.all.tangential);
  if (!f.measured) {
    f.verdict = "not identifiable";
    f.value = f.base;
    return f;
  }
  f.grid = opt.grid;
  for (double g : opt.grid) {
    sim::PhysicsConfig p = physics;
    if (g > 0) p.extra["glint"] = g; else p.extra.erase("glint");
    const MatchedSpread m = referenceSpread(sensor, p, opt);
    // Monotone in the glint (the reference's own scatter aside).
    f.ref_spread.push_back(f.ref_spread.empty() ? m.all.tangential
                                                : std::max(m.all.tangential, f.ref_spread.back()));
    f.ref_se.push_back(m.all.tangential_se);
  }
  const double s = f.real.all.tangential;
  f.value = inverse(f.grid, f.ref_spread, s);
  // Uncertainty: the recording's and the reference's standard errors through the local slope.
  const double se = std::sqrt(std::pow(f.real.all.tangential_se, 2) + std::pow(opt.scene_sd, 2) +
                              std::pow(interp(f.grid, f.ref_se, f.value), 2));
  const double lo = inverse(f.grid, f.ref_spread, s - se), hi = inverse(f.grid, f.ref_spread, s + se);
  f.stddev = std::max(0.5 * (hi - lo), 1e-4);
  if (f.value <= 0) f.stddev = std::max(hi, 1e-4);  // one-sided: below the glint-free model
  f.z = std::abs(f.value - f.base) / f.stddev;
  const bool sig = f.z >= opt.z_min, practical = std::abs(f.value - f.base) >= opt.practical_min;
  f.named = sig && practical;
  f.verdict = f.named ? "mismatch" : sig ? "negligible" : "not significant";
  if (s > f.ref_spread.back()) f.verdict += " (beyond the grid)";
  auto at = [&](double g) {
    sim::PhysicsConfig p = physics;
    if (g > 0) p.extra["glint"] = g; else p.extra.erase("glint");
    return referenceSpread(sensor, p, opt);
  };
  f.before = at(f.base);
  f.after = f.named ? at(f.value) : f.before;
  return f;
}

std::string glintTable(const GlintFit& f) {
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(3);
  writeSpreadTableHeader(os);
  auto row = [&](const std::string& name, const MatchedSpread& m) { writeSpreadTableRow(os, name, m); };
  row("recording", f.real);
  if (f.before.pairs) row("model, glint " + std::to_string(f.base).substr(0, 5) + " m", f.before);
  if (f.named) row("model, glint " + std::to_string(f.value).substr(0, 5) + " m (fitted)", f.after);
  return os.str();
}

}  // namespace spinradar::diagnose
