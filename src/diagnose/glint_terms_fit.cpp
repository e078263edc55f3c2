// Fit of the anisotropic glint terms (glint_terms.hpp).
#include "spinradar/diagnose/glint_terms.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include <Eigen/Dense>

namespace spinradar::diagnose {

namespace {

constexpr double kDeg = M_PI / 180.0;
const char* const kKeys[3] = {"glint_across", "glint_along", "azimuth_jitter"};

bool usable(const SpreadBand& b, int min_matches) {
  return b.matches >= min_matches && std::isfinite(b.tangential) && std::isfinite(b.radial);
}

// Value and 1-sigma of sqrt(x) from x and its 1-sigma (one-sided near 0).
void rootOf(double x, double sx, double& value, double& sd) {
  value = std::sqrt(std::max(x, 0.0));
  const double hi = std::sqrt(std::max(x + sx, 0.0)), lo = std::sqrt(std::max(x - sx, 0.0));
  sd = std::max(0.5 * (hi - lo), 1e-6);
}

}  // namespace

std::map<std::string, double> GlintTermsFit::named() const {
  std::map<std::string, double> m;
  for (const GlintTerm* t : {&across, &along, &jitter})
    if (t->named) m[t->key] = t->value;
  return m;
}

GlintTermsFit fitGlintTerms(const std::vector<PolarScan>& recording, const sim::SensorConfig& sensor,
                            const sim::PhysicsConfig& physics, const GlintTermsOptions& opt) {
  GlintTermsFit f;
  f.across.key = kKeys[0], f.along.key = kKeys[1], f.jitter.key = kKeys[2];
  f.across.unit = f.along.unit = "m", f.jitter.unit = "deg";
  f.across.size_unit = f.along.size_unit = "bins", f.jitter.size_unit = "rows";
  for (GlintTerm* t : {&f.across, &f.along, &f.jitter}) t->verdict = "not identifiable";
  f.real = measureMatchedSpread(recording, nullptr, opt.ref.spread);
  f.measured = f.real.pairs > 0 && std::isfinite(f.real.all.tangential);
  if (!f.measured) return f;

  // Reference renders: the sensor without its own appearance physics, the three terms set here.
  sim::SensorConfig s0 = sensor;
  s0.physics.clear();
  sim::PhysicsConfig p0 = physics;
  for (const char* k : kKeys) p0.extra.erase(k);
  auto at = [&](double gc, double ga, double jd) {
    sim::PhysicsConfig p = p0;
    if (gc > 0) p.extra["glint_across"] = gc;
    if (ga > 0) p.extra["glint_along"] = ga;
    if (jd > 0) p.extra["azimuth_jitter"] = jd;
    return referenceSpread(s0, p, opt.ref);
  };
  f.base = at(0, 0, 0);
  f.probe_glint = at(opt.probe_glint, opt.probe_glint, 0);
  f.probe_jitter = at(0, 0, opt.probe_jitter);
  const double g2 = opt.probe_glint * opt.probe_glint, j2 = std::pow(opt.probe_jitter * kDeg, 2);
  f.gain_across = (std::pow(f.probe_glint.all.tangential, 2) - std::pow(f.base.all.tangential, 2)) / g2;
  f.gain_along = (std::pow(f.probe_glint.all.radial, 2) - std::pow(f.base.all.radial, 2)) / g2;
  double jn = 0, jd = 0;
  for (int b = 0; b < 4; ++b) {
    const SpreadBand &pj = f.probe_jitter.band[b], &b0 = f.base.band[b];
    if (!usable(pj, opt.min_matches) || !usable(b0, opt.min_matches)) continue;
    const double r2 = pj.range * pj.range, gain = (std::pow(pj.tangential, 2) - std::pow(b0.tangential, 2)) / j2;
    jn += pj.matches * gain * r2, jd += pj.matches * r2 * r2;
  }
  f.gain_jitter = jd > 0 ? jn / jd : 0;
  if (!(f.gain_across > 0) || !(f.gain_along > 0)) return f;  // the probe shows no glint: no model

  // Bands of the recording with enough matches in it and in the reference.
  std::vector<int> bands;
  for (int b = 0; b < 4; ++b)
    if (usable(f.real.band[b], opt.min_matches) && usable(f.base.band[b], opt.min_matches)) bands.push_back(b);
  if (bands.empty()) return f;
  const double sd_scene = opt.ref.scene_sd;
  auto var = [&](double v, double se, double v0, double se0) {
    return std::pow(2 * v * se, 2) + std::pow(2 * v0 * se0, 2) + std::pow(2 * v0 * sd_scene, 2);
  };
  // Across: y_b = across_b^2 - anchor_b^2 = G (x1 - xa1) + J r_b^2 (x2 - xa2) (x2 in rad^2),
  // linear around an anchor render, the terms 0. (A second step from a render at the first fit
  // was tried: it adds that render's own noise and did not come closer on the known-truth tests.)
  const int n = int(bands.size());
  Eigen::MatrixXd A(n, 2);
  Eigen::VectorXd y(n), w(n);
  for (int i = 0; i < n; ++i)
    A(i, 0) = f.gain_across, A(i, 1) = f.gain_jitter * std::pow(f.real.band[bands[i]].range, 2);
  const bool jitter_ok = n >= 2 && f.gain_jitter > 0;
  const MatchedSpread* anc = &f.base;
  Eigen::Vector2d xa = Eigen::Vector2d::Zero(), x = xa;
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  double xa3 = 0, x3 = 0, s3 = 0;
  auto chi2 = [&](const Eigen::Vector2d& v) { return ((A * v - y).array().square() * w.array()).sum(); };
  auto single = [&](int c) {  // one term alone, non-negative
    Eigen::Vector2d v = Eigen::Vector2d::Zero();
    const double nn = (A.col(c).array().square() * w.array()).sum();
    v(c) = nn > 0 ? std::max(0.0, (A.col(c).array() * y.array() * w.array()).sum() / nn) : 0;
    return v;
  };
  auto solve = [&] {
    for (int i = 0; i < n; ++i) {
      const SpreadBand &r = f.real.band[bands[i]], &b0 = anc->band[bands[i]];
      y(i) = r.tangential * r.tangential - b0.tangential * b0.tangential + A.row(i).dot(xa);
      w(i) = 1.0 / std::max(var(r.tangential, r.tangential_se, b0.tangential, b0.tangential_se), 1e-12);
    }
    x = single(0);
    cov.setZero();
    cov(0, 0) = 1.0 / (A.col(0).array().square() * w.array()).sum();
    if (jitter_ok) {
      const Eigen::Matrix2d N = A.transpose() * w.asDiagonal() * A;
      if (N.determinant() > 1e-12 * N(0, 0) * N(1, 1)) {
        cov = N.inverse();
        const Eigen::Vector2d full = cov * (A.transpose() * w.asDiagonal() * y);
        if (full.minCoeff() >= 0) {
          x = full;
        } else {
          const Eigen::Vector2d a = single(0), b = single(1);
          x = chi2(a) <= chi2(b) ? a : b;
        }
      }
    }
    // Along: y_b = along_b^2 - anchor_b^2 = A (x3 - xa3).
    double an = 0, ad = 0;
    for (int b : bands) {
      const SpreadBand &r = f.real.band[b], &b0 = anc->band[b];
      const double wb = 1.0 / std::max(var(r.radial, r.radial_se, b0.radial, b0.radial_se), 1e-12);
      an += wb * f.gain_along * (r.radial * r.radial - b0.radial * b0.radial + f.gain_along * xa3);
      ad += wb * f.gain_along * f.gain_along;
    }
    x3 = std::max(0.0, an / ad), s3 = std::sqrt(1.0 / ad);
  };
  solve();

  // Model per band and the residual each term buys (rms over bands of recording - model).
  auto across = [&](int b, double x1, double x2) {
    const double rr = f.real.band[b].range;
    return std::sqrt(std::max(std::pow(anc->band[b].tangential, 2) + f.gain_across * (x1 - xa(0)) +
                                  f.gain_jitter * rr * rr * (x2 - xa(1)), 0.0));
  };
  auto along = [&](int b, double xv) {
    return std::sqrt(std::max(std::pow(anc->band[b].radial, 2) + f.gain_along * (xv - xa3), 0.0));
  };
  auto resAcross = [&](double x1, double x2) {
    double s = 0;
    for (int b : bands) s += std::pow(f.real.band[b].tangential - across(b, x1, x2), 2);
    return std::sqrt(s / bands.size());
  };
  auto resAlong = [&](double xa) {
    double s = 0;
    for (int b : bands) s += std::pow(f.real.band[b].radial - along(b, xa), 2);
    return std::sqrt(s / bands.size());
  };
  auto dropOf = [](double with, double without) { return without > 0 ? 1.0 - with / without : 0.0; };
  const double res = resAcross(x(0), x(1));
  const double bin = sensor.range_resolution, row = 360.0 / sensor.azimuths;
  auto judge = [&](GlintTerm& t, double xx, double sx, double scale, double unit, double drop) {
    rootOf(xx, sx, t.value, t.stddev);
    t.value *= scale, t.stddev *= scale;
    t.z = t.value / t.stddev;
    t.size = t.value / unit;
    t.drop = drop;
    const bool sig = t.z >= opt.z_min, practical = t.size >= opt.half_unit || t.drop >= opt.drop_min;
    t.named = sig && practical;
    t.verdict = t.named ? "mismatch" : sig ? "negligible" : "not significant";
  };
  judge(f.across, x(0), std::sqrt(cov(0, 0)), 1.0, bin, dropOf(res, resAcross(0, x(1))));
  judge(f.along, x3, s3, 1.0, bin, dropOf(resAlong(x3), resAlong(0)));
  if (jitter_ok) {
    judge(f.jitter, x(1), std::sqrt(std::max(cov(1, 1), 0.0)), 1.0 / kDeg, row,
          dropOf(res, resAcross(x(0), 0)));
    // One across term left out: the other alone carries the across spread (refitted, judged again).
    if (f.across.named != f.jitter.named) {
      const int c = f.across.named ? 0 : 1;
      x = single(c);
      const double nc = (A.col(c).array().square() * w.array()).sum();
      if (c == 0)
        judge(f.across, x(0), std::sqrt(1.0 / nc), 1.0, bin, dropOf(resAcross(x(0), 0), resAcross(0, 0)));
      else
        judge(f.jitter, x(1), std::sqrt(1.0 / nc), 1.0 / kDeg, row, dropOf(resAcross(0, x(1)), resAcross(0, 0)));
    }
  }
  for (int b = 0; b < 4; ++b)
    if (std::isfinite(f.base.band[b].tangential)) {
      f.model_across[b] = across(b, x(0), x(1)), f.model0_across[b] = across(b, 0, 0);
      f.model_along[b] = along(b, x3), f.model0_along[b] = along(b, 0);
    }
  const auto nm = f.named();
  f.after = nm.empty() ? f.base
                       : at(nm.count(kKeys[0]) ? nm.at(kKeys[0]) : 0, nm.count(kKeys[1]) ? nm.at(kKeys[1]) : 0,
                            nm.count(kKeys[2]) ? nm.at(kKeys[2]) : 0);
  return f;
}

std::string glintTermsTable(const GlintTermsFit& f) {
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(3);
  os << "| term | fitted | z | size | residual drop | verdict |\n|---|---|---|---|---|---|\n";
  for (const GlintTerm* t : {&f.across, &f.along, &f.jitter})
    os << "| " << t->key << " | " << t->value << " +- " << t->stddev << " " << t->unit << " | "
       << std::setprecision(1) << t->z << " | " << std::setprecision(2) << t->size << " "
       << t->size_unit << " | " << std::setprecision(0) << 100 * t->drop << " % | " << t->verdict
       << " |\n"
       << std::setprecision(3);
  os << "\n";
  writeSpreadTableHeader(os);
  auto row = [&](const std::string& name, const MatchedSpread& m) { writeSpreadTableRow(os, name, m); };
  row("recording", f.real);
  if (f.base.pairs) row("model, terms 0", f.base);
  if (f.after.pairs && !f.named().empty()) row("model, named terms", f.after);
  os << "\ngains: across " << f.gain_across << ", along " << f.gain_along << ", jitter " << f.gain_jitter
     << " (spread^2 per term^2, from the probe renders)\n";
  return os.str();
}

}  // namespace spinradar::diagnose
