// Appearance stage: name and fit (appearance.hpp). Saturation and multipath ghosts are tested
// directly (thresholds and switches, not smooth knobs); the smooth parameters are fitted jointly
// by indirect inference: figures(real) = figures(sim(theta)), Gauss-Newton, figure Jacobian from
// re-simulations with each parameter nudged (common random numbers).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <sstream>

#include <Eigen/Dense>

#include "appearance_detail.hpp"
#include "spinradar/diagnose/glint_fit.hpp"
#include "spinradar/sim/scenes.hpp"
#include "spinradar/sim/simulator.hpp"

namespace spinradar::diagnose {

using sim::SensorConfig;

namespace {
using detail::alignLevels;
using detail::appearanceParams;
using detail::Kind;
using detail::makeFinding;
using detail::physicsHasGhosts;
}  // namespace

AppearanceReport diagnoseAppearance(const std::vector<PolarScan>& recording,
                                    const SensorConfig& sensor, const sim::PhysicsConfig& physics,
                                    const AppearanceOptions& opt_in) {
  if (opt_in.scene == "combined") return combinedAppearance(recording, sensor, physics, opt_in);
  const AppearanceOptions opt = withReferenceScene(opt_in, recording);  // its own: fit part
  const auto t0 = std::chrono::steady_clock::now();
  if (recording.empty()) throw std::runtime_error("appearance: no scans");
  AppearanceReport rep;
  // Everything is fitted on `real`, the fit part; the held-out part only checks the result.
  std::vector<PolarScan> real, holdout;
  HoldoutSplit sp = parseHoldoutSplit(opt.holdout_split);
  if (opt.holdout && sp.kind == HoldoutSplit::kAuto) sp = chooseHoldoutSplit(recording);
  if (opt.holdout) splitHoldout(recording, real, holdout, sp);
  else real = recording;
  const int glint_stride = opt.holdout && sp.kind == HoldoutSplit::kScans ? 2 : 1;  // fit scans' gap
  rep.fit_scans = int(real.size());
  rep.holdout_scans = int(holdout.size());
  rep.base = sensor;
  rep.base_physics = physics;
  rep.real = measureAppearance(real);
  auto figuresOf = [&](const SensorConfig& s, const sim::PhysicsConfig& p) {
    return measureAppearance(renderReference(s, p, opt, opt.seed));
  };
  rep.before = figuresOf(sensor, physics);
  SensorConfig cur = sensor;
  sim::PhysicsConfig phys = physics;

  // --- Saturation: a pile-up at the top code is a clipped receiver.
  {
    const bool piled = rep.real.pileup >= 3.0 && rep.real.top_count < 255;
    double value = piled ? rep.real.top_count : std::max(sensor.saturation, rep.real.top_count);
    bool identifiable = piled || rep.real.top_count > sensor.saturation;
    AppearanceFinding f = makeFinding(
        "receiver saturation", "saturation", "count", sensor.saturation, value, 0.5,
        std::abs(value - sensor.saturation) / std::max(sensor.power_scale, 1e-6), "dB",
        std::abs(value - sensor.saturation) / sensor.power_scale >= opt.level_db_min, opt.z_min);
    f.gap_before = rep.real.top_count - rep.before.top_count;
    if (!identifiable) f.verdict = "not identifiable", f.named = false;
    if (f.named) cur.saturation = value;
    rep.findings.push_back(f);
    if (!piled)
      rep.notes.push_back("No pile-up at the top count (" + std::to_string(int(rep.real.top_count)) +
                          "): the receiver does not clip within the returns seen; saturation is "
                          "only bounded from below.");
  }
  rep.findings.push_back(detail::fitCodeSet(real, rep.real, rep.before, cur, phys, opt, rep.notes));
  // --- Smooth parameters: block-wise Gauss-Newton. Each block is fitted to the figures it moves
  // most (block-diagonal Jacobian from re-simulations, each parameter nudged, common random
  // numbers); blocks iterate jointly to take up cross-talk (range spread moves CA-CFAR too).
  const auto& params = appearanceParams();
  std::vector<int> active;
  for (int i = 0; i < int(params.size()); ++i) {
    if ((!opt.fit_clutter && params[i].block == 4) || isHeldParameter(opt, params[i].key) ||
        (!opt.fit_near_stc && params[i].kind == Kind::Range) ||
        (opt.hold_gain_chain && notIdentifiableWithOwnScene(params[i].key)))  // combined
      continue;
    active.push_back(i);
  }
  if (opt.hold_clutter) rep.notes.push_back("Clutter field held at the start sensor's values.");
  if (opt.fit_clutter && !opt.hold_clutter && cur.clutter_density <= 0) cur.clutter_density = 0.05;
  if (opt.fit_near_stc && cur.stc_range <= 0) cur.stc_range = 10.0;
  if (opt.fit_clutter && cur.noise_texture_db <= 0) cur.noise_texture_db = 1.0;
  alignLevels(rep.real, cur, [&](const SensorConfig& s) { return figuresOf(s, phys); }, rep.notes,
              opt.hold_gain_chain);
  // Re-simulated even when nothing moved: the same seed gives rep.before again.
  AppearanceFigures fig_cur = figuresOf(cur, phys);
  Eigen::VectorXd e_cur = detail::figureVector(fig_cur);
  const Eigen::VectorXd e_real = detail::figureVector(rep.real);
  Eigen::VectorXd se = detail::differenceSe(rep.real, fig_cur);
  // Scene-dependent figures weigh (almost) nothing: the near band's mean, bright level and
  // CA-CFAR cells show the street's walls (sceneDependentFigures). Its floor, the lower half of
  // the counts, is the receiver's noise and stays.
  for (int k = 0; k < kBands; ++k)
    if (isSceneDependent(k, "mean")) se[4 + k] = se[8 + k] = se[12 + k] = 1e6;
  const int P = int(active.size());
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(detail::kFigures, P);
  // Blocks: parameters sharing a block number are solved together on their figures.
  std::vector<int> blocks;
  for (int j = 0; j < P; ++j)
    if (std::find(blocks.begin(), blocks.end(), params[active[j]].block) == blocks.end())
      blocks.push_back(params[active[j]].block);
  Eigen::VectorXd theta(P), sd = Eigen::VectorXd::Zero(P);
  for (int j = 0; j < P; ++j) theta[j] = cur.*(params[active[j]].field);
  auto linearise = [&]() {
    for (int j = 0; j < P; ++j) {
      const auto& p = params[active[j]];
      SensorConfig s = cur;
      s.*(p.field) += p.step;
      if (s.*(p.field) > p.hi) s.*(p.field) = cur.*(p.field) - p.step;
      const double h = s.*(p.field) - cur.*(p.field);
      const Eigen::VectorXd d = (detail::figureVector(figuresOf(s, phys)) - e_cur) / h;
      for (int fi : p.figures) J(fi, j) = d[fi];
    }
  };  linearise();
  auto solveBlocks = [&](const Eigen::VectorXd& resid, bool fill_sd) {
    Eigen::VectorXd step = Eigen::VectorXd::Zero(P);
    for (int bk : blocks) {
      std::vector<int> cols, rows;
      for (int j = 0; j < P; ++j)
        if (params[active[j]].block == bk) {
          cols.push_back(j);
          for (int fi : params[active[j]].figures)
            if (std::find(rows.begin(), rows.end(), fi) == rows.end()) rows.push_back(fi);
        }
      Eigen::MatrixXd A(rows.size(), cols.size());
      Eigen::VectorXd y(rows.size());
      for (size_t r = 0; r < rows.size(); ++r) {
        y[r] = resid[rows[r]] / se[rows[r]];
        for (size_t c = 0; c < cols.size(); ++c) A(r, c) = J(rows[r], cols[c]) / se[rows[r]];
      }
      const Eigen::MatrixXd N = A.transpose() * A +
                                1e-9 * Eigen::MatrixXd::Identity(cols.size(), cols.size());
      const Eigen::MatrixXd cov = N.inverse();
      const Eigen::VectorXd x = cov * A.transpose() * y;
      for (size_t c = 0; c < cols.size(); ++c) step[cols[c]] = x[c];
      if (fill_sd) {
        const int dof = int(rows.size()) - int(cols.size());
        const double chi2 = (y - A * x).squaredNorm();
        const double inflate = dof > 0 ? std::sqrt(std::max(1.0, chi2 / dof)) : 1.0;
        for (size_t c = 0; c < cols.size(); ++c) sd[cols[c]] = std::sqrt(cov(c, c)) * inflate;
      }
    }
    return step;
  };

  // Trust region: no parameter moves more than 3 of its steps per iteration; a step that
  // raises the weighted misfit is halved (twice at most) before it is taken.
  auto misfit = [&](const Eigen::VectorXd& e) {
    return ((e_real - e).array() / se.array()).square().sum();
  };
  // A step cut by the trust region earns one more iteration (up to twice opt.iterations).
  auto newton = [&]() {
  int iterations = opt.iterations;
  for (int it = 0; it < iterations; ++it) {
    if (it > 0 && opt.relinearise) linearise();
    Eigen::VectorXd step = solveBlocks(e_real - e_cur, false);
    bool clamped = false;
    for (int j = 0; j < P; ++j) {
      const double lim = 3 * params[active[j]].step;
      clamped = clamped || std::abs(step[j]) > lim;
      step[j] = std::clamp(step[j], -lim, lim);
    }
    if (clamped && opt.relinearise) iterations = std::min(iterations + 1, 2 * opt.iterations);
    const double m0 = misfit(e_cur);
    SensorConfig trial = cur;
    AppearanceFigures fig_trial;
    for (int half = 0; half < 3; ++half) {
      trial = cur;
      for (int j = 0; j < P; ++j) {
        const auto& p = params[active[j]];
        trial.*(p.field) = std::clamp(theta[j] + step[j], p.lo, p.hi);
      }
      fig_trial = figuresOf(trial, phys);
      if (misfit(detail::figureVector(fig_trial)) < m0 || !opt.relinearise) break;
      step *= 0.5;
    }
    if (opt.relinearise && misfit(detail::figureVector(fig_trial)) >= m0) break;
    cur = trial;
    for (int j = 0; j < P; ++j) theta[j] = cur.*(params[active[j]].field);
    fig_cur = fig_trial;
    e_cur = detail::figureVector(fig_cur);
    if (step.cwiseAbs().maxCoeff() < 1e-3) break;
  }
  };
  newton();
  rep.after = fig_cur;

  // --- Multipath ghosts: bright returns behind the first strong hit of a row.
  {
    // Against the model fitted so far (clutter also fills the space behind walls).
    const double d = rep.real.behind - rep.after.behind;
    const double se_g = std::hypot(rep.real.behind_se, rep.after.behind_se);
    const double z = se_g > 0 ? d / se_g : 0;
    const double ratio = rep.real.behind / std::max(rep.after.behind, 1e-6);
    AppearanceFinding f;
    f.effect = "multipath ghosts", f.parameter = "multipath", f.unit = "dB";
    f.base = physicsHasGhosts(physics) ? phys.extra["multipath"].is_number()
                                             ? phys.extra["multipath"].get<double>()
                                             : -15.0
                                       : -INFINITY;
    f.gap_before = d;
    f.z = z;
    f.size = ratio, f.size_unit = "x behind-hit share";
    f.named = !physicsHasGhosts(physics) && z >= opt.z_min && ratio >= opt.ghost_ratio_min;
    f.verdict = f.named ? "mismatch" : (z >= opt.z_min ? "negligible" : "not significant");
    if (f.named) {
      // Ghost level by interpolating the behind share of re-simulations with ghosts at levels
      // 5 dB apart (the share grows faster than linearly with the level: a coarser grid biases
      // the interpolated level low).
      constexpr int kLevels = 5;
      const double levels[kLevels] = {-25.0, -20.0, -15.0, -10.0, -5.0};
      double share[kLevels];
      auto grid = [&]() {
        for (int i = 0; i < kLevels; ++i) {
          sim::PhysicsConfig p = phys;
          p.extra["multipath"] = levels[i];
          share[i] = figuresOf(cur, p).behind;
          if (i > 0) share[i] = std::max(share[i], share[i - 1]);  // monotone in the level
        }
      };
      grid();
      auto level = [&](double s) {
        int i = 0;
        while (i + 2 < kLevels && s > share[i + 1]) ++i;
        return levels[i] + (s - share[i]) / std::max(share[i + 1] - share[i], 1e-9) * 5;
      };
      if (rep.real.behind > share[kLevels - 1] + 2 * rep.real.behind_se) {
        // More than the strongest ghosts give: not multipath-like (returns through or past the
        // first reflector, elevation-beam returns); left to the notes, not switched on.
        f.named = false;
        f.verdict = "not ghost-like";
        f.value = NAN;
        rep.notes.push_back(
            "Behind the first strong hit the recording has " + std::to_string(100 * rep.real.behind) +
            " % bright cells, more than multipath ghosts even at -5 dB give (" +
            std::to_string(100 * share[kLevels - 1]) + " %): penetration or elevation-beam returns the "
            "simulator's occlusion removes (occlusion_tolerance), not ghosts.");
      } else {
        f.value = std::clamp(level(rep.real.behind), -80.0, 0.0);
        f.stddev = std::abs(level(rep.real.behind + rep.real.behind_se) - f.value);
        phys.extra["multipath"] = f.value;
        // The ghosts also brightened the bright figures the receiver gain was fitted to: refit
        // the smooth parameters with the ghosts on, then the level against that model (one
        // alternation of the joint fit).
        fig_cur = figuresOf(cur, phys);
        e_cur = detail::figureVector(fig_cur);
        newton();
        grid();
        f.value = std::clamp(level(rep.real.behind), -80.0, 0.0);
        f.stddev = std::abs(level(rep.real.behind + rep.real.behind_se) - f.value);
        phys.extra["multipath"] = f.value;
        fig_cur = figuresOf(cur, phys);
        e_cur = detail::figureVector(fig_cur);
      }
    }
    rep.findings.push_back(f);
  }

  // --- Near-range leakage (appearance_leakage.cpp).
  rep.findings.push_back(detail::fitLeakage(rep.real, sensor, cur, phys, opt, fig_cur, rep.notes));
  e_cur = detail::figureVector(fig_cur);

  // Uncertainty of the fit: the block covariances, with the residual misfit of each block.
  solveBlocks(e_real - e_cur, true);
  rep.after = fig_cur;
  const Eigen::VectorXd e_before = detail::figureVector(rep.before);
  for (int j = 0; j < P; ++j) {
    const auto& p = params[active[j]];
    const double base = sensor.*(p.field), value = theta[j];
    double size = std::abs(value - base);
    std::string su = p.unit;
    bool practical = false;
    switch (p.kind) {
      case Kind::Level: practical = size >= opt.level_db_min; su = "dB"; break;
      case Kind::Slope:
        practical = size >= opt.slope_min;
        su = "dB/dec";
        break;
      case Kind::Width:
        size = base > 0 ? std::abs(value / base - 1) : 0;
        practical = size >= opt.width_rel_min;
        su = "relative";
        break;
      case Kind::Range:
        size = std::abs(value - base) / sensor.range_resolution;
        practical = std::abs(value - base) >= 1.0;  // a metre of near-range gain ramp
        su = "bins";
        break;
      case Kind::Density:
        size = value - base;
        practical = value > 0.01 && (base <= 0 || std::abs(value / base - 1) >= 0.25);
        su = "1/m^2";
        break;
    }
    AppearanceFinding f = makeFinding(p.effect, p.key, p.unit, base, value, sd[j], size, su,
                                      practical, opt.z_min);
    // The figure this parameter moves most (in standard errors): its gap before and after.
    Eigen::Index fi = 0;
    (J.col(j).array() / se.array()).abs().maxCoeff(&fi);
    f.gap_before = e_real[fi] - e_before[fi];
    f.gap_after = e_real[fi] - e_cur[fi];
    rep.findings.push_back(f);
  }

  // --- Noise texture correlation (appearance_texture.cpp), before the range curves.
  rep.findings.push_back(detail::fitTextureLength(real, cur, phys, opt, rep.notes));
  if (rep.findings.back().named) rep.after = figuresOf(cur, phys);
  // Alternating chirps (appearance_chirp.cpp): odd rows' and even rows' range spread.
  if (detail::fitAlternatingChirps(real, cur, phys, opt, rep.findings, rep.notes)) rep.after = figuresOf(cur, phys);

  // --- Per-band calibration: range curves on the per-band realism figures.
  if (opt.realism && opt.curve_iterations > 0) {
    const sim::RealismStats target = sim::computeRealism(real, "recording (fit part)");
    std::vector<std::string> steps;
    const SensorConfig curved = fitRangeCurves(target, cur, phys, opt, &steps);
    rep.notes.push_back("Per-band calibration (range gain curve, return gain curve, clutter "
                        "density curve over range): " + std::to_string(steps.size()) +
                        " steps taken" + (steps.empty() ? "." : "; last " + steps.back() + "."));
    if (!steps.empty()) {
      cur = curved;
      rep.after = figuresOf(cur, phys);
    }
  }
  // Glint terms (appearance_glint.cpp) on the fit part's pairs only: under the "scans" split its
  // scans are 2 rotations apart, and so are the reference's (one-scan samples have no pair: not
  // identifiable). Its check is `spinradar spread` on the real samples.
  if (opt.fit_glint) detail::appendGlint(real, cur, phys, opt, rep, glint_stride);
  if (opt.scene == "recording" && !opt.hold_gain_chain) detail::markOwnSceneFindings(rep.findings, rep.notes);
  std::stable_sort(rep.findings.begin(), rep.findings.end(),
                   [](const AppearanceFinding& a, const AppearanceFinding& b) {
                     if (a.named != b.named) return a.named;
                     return a.z > b.z;
                   });
  // The calibrated model is the whole fit (changes that are not named are small by definition).
  rep.fitted = cur;
  rep.fitted_physics = phys;
  detail::locateAppearance(rep);
  if (opt.realism) detail::realismBeforeAfter(real, holdout, opt, rep);
  rep.runtime_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return rep;
}

}  // namespace spinradar::diagnose
