// Steps 2-4 of the diagnosis: robust scales and outliers, stepwise selection of the catalogue
// effects, joint fit, confounding and identifiability notes.
#include <algorithm>
#include <map>

#include <Eigen/Dense>
#include <sstream>
#include <string>

#include "diagnose_steps.hpp"
#include "spinradar/diagnose/advice.hpp"

namespace spinradar::diagnose::detail {
namespace {

// The regression problem on the inliers: stacked whitened range and azimuth residuals.
struct Design {
  Eigen::VectorXd y;
  Eigen::MatrixXd N, C, A;  // nuisance (none by default), candidates, per-scan rigid alignment
  std::vector<int> rows;    // observation of each stacked row
};

// Without a world file (map != nullptr): the test views of one target share its map error,
// so the rows of each target are whitened jointly (generalised least squares) with the
// covariance diag(white^2) + J cov J^T, J = d(range, azimuth)/d(target position).
void whitenByTarget(Design& d, const std::vector<Observation>& obs, const MapModel& map,
                    double sr, double sa, double wr, double wa) {
  const int m = static_cast<int>(d.rows.size());
  std::map<int, std::vector<int>> of_target;
  for (int j = 0; j < m; ++j) of_target[obs[d.rows[j]].target].push_back(j);
  for (const auto& [t, js] : of_target) {
    const int n = static_cast<int>(js.size());
    std::vector<int> rows;
    for (int j : js) rows.push_back(j);
    for (int j : js) rows.push_back(m + j);
    Eigen::MatrixXd K(2 * n, 2);
    Eigen::VectorXd white(2 * n);
    for (int q = 0; q < n; ++q) {
      const Observation& o = obs[d.rows[js[q]]];
      K.row(q) << o.tr[0] / sr, o.tr[1] / sr;
      K.row(n + q) << o.taz[0] / sa, o.taz[1] / sa;
      white(q) = wr * wr / (sr * sr);
      white(n + q) = wa * wa / (sa * sa);
    }
    Eigen::MatrixXd cov = K * map.cov[t] * K.transpose();
    cov.diagonal() += white;
    const Eigen::LLT<Eigen::MatrixXd> llt(cov);
    if (llt.info() != Eigen::Success) continue;
    auto apply = [&](Eigen::MatrixXd& M) {
      if (M.cols() == 0) return;
      Eigen::MatrixXd B(2 * n, M.cols());
      for (int q = 0; q < 2 * n; ++q) B.row(q) = M.row(rows[q]);
      B = llt.matrixL().solve(B);
      for (int q = 0; q < 2 * n; ++q) M.row(rows[q]) = B.row(q);
    };
    Eigen::MatrixXd Y = d.y;
    apply(Y);
    d.y = Y.col(0);
    apply(d.N);
    apply(d.C);
    apply(d.A);
  }
}

// White (per-view) part of the residual noise when the map error is common per target: the
// scatter left after fitting each target's position shift to its residuals.
std::pair<double, double> withinTargetScales(const std::vector<Observation>& obs,
                                             const std::vector<double>& er,
                                             const std::vector<double>& ea, double sr, double sa,
                                             double floor_r, double floor_a) {
  std::map<int, std::vector<int>> of_target;
  for (size_t i = 0; i < obs.size(); ++i)
    if (obs[i].inlier) of_target[obs[i].target].push_back(static_cast<int>(i));
  std::vector<double> rr, ra;
  int rows = 0, params = 0;
  for (const auto& [t, is] : of_target) {
    const int n = static_cast<int>(is.size());
    if (n < 2) continue;
    Eigen::MatrixXd K(2 * n, 2);
    Eigen::VectorXd y(2 * n);
    for (int q = 0; q < n; ++q) {
      const Observation& o = obs[is[q]];
      K.row(q) << o.tr[0] / sr, o.tr[1] / sr;
      K.row(n + q) << o.taz[0] / sa, o.taz[1] / sa;
      y(q) = er[is[q]] / sr;
      y(n + q) = ea[is[q]] / sa;
    }
    const Eigen::VectorXd res = y - K * K.colPivHouseholderQr().solve(y);
    for (int q = 0; q < n; ++q) {
      rr.push_back(res(q) * sr);
      ra.push_back(res(n + q) * sa);
    }
    rows += 2 * n;
    params += 2;
  }
  if (rows <= params) return {sr, sa};
  const double dof = std::sqrt(static_cast<double>(rows) / (rows - params));
  return {noiseScale(rr, floor_r) * dof, noiseScale(ra, floor_a) * dof};
}

Design buildDesign(const std::vector<Observation>& obs, const std::vector<Effect>& cands,
                   double sr, double sa, int n_scans, bool target_nuisance) {
  Design d;
  std::vector<int> idx;
  for (size_t i = 0; i < obs.size(); ++i)
    if (obs[i].inlier) idx.push_back(static_cast<int>(i));
  const int m = static_cast<int>(idx.size());
  std::map<int, int> tcol;  // target -> first nuisance column
  if (target_nuisance)
    for (int i : idx)
      if (!tcol.count(obs[i].target)) {
        const int c = static_cast<int>(2 * tcol.size());
        tcol[obs[i].target] = c;
      }
  d.y.resize(2 * m);
  d.N = Eigen::MatrixXd::Zero(2 * m, static_cast<int>(2 * tcol.size()));
  d.C.resize(2 * m, static_cast<int>(cands.size()));
  d.A = Eigen::MatrixXd::Zero(2 * m, 3 * n_scans);
  for (int j = 0; j < m; ++j) {
    const Observation& o = obs[idx[j]];
    d.y(j) = o.e_r / sr;
    d.y(m + j) = o.e_az / sa;
    for (size_t k = 0; k < cands.size(); ++k) {
      const int e = static_cast<int>(cands[k]);
      d.C(j, k) = o.dr[e] / sr;
      d.C(m + j, k) = o.daz[e] / sa;
    }
    if (target_nuisance) {
      const int c = tcol[o.target];
      for (int q = 0; q < 2; ++q) {
        d.N(j, c + q) = o.tr[q] / sr;
        d.N(m + j, c + q) = o.taz[q] / sa;
      }
    }
    for (int q = 0; q < 3; ++q) {
      d.A(j, 3 * o.scan + q) = o.nr[q] / sr;
      d.A(m + j, 3 * o.scan + q) = o.naz[q] / sa;
    }
    d.rows.push_back(idx[j]);
  }
  return d;
}

}  // namespace

// Noise scale of one residual type: the larger of the MAD and the RMS of the central 90 %
// (the MAD collapses when most residuals are exactly equal, as with noise-free peaks), with a
// floor at the precision a parabolic peak fit can claim (1/50 of a bin or of a row).
double noiseScale(const std::vector<double>& v, double floor) {
  if (v.empty()) return floor;
  std::vector<double> a = v;
  std::sort(a.begin(), a.end());
  const size_t lo = a.size() / 20, hi = a.size() - a.size() / 20;
  double mean = 0, n = 0;
  for (size_t i = lo; i < hi; ++i, ++n) mean += a[i];
  mean /= std::max(1.0, n);
  double ss = 0;
  for (size_t i = lo; i < hi; ++i) ss += (a[i] - mean) * (a[i] - mean);
  const double trimmed = std::sqrt(ss / std::max(1.0, n));
  return std::max({robustSigma(v), trimmed, floor});
}

void nameAndFitEffects(const DiagnoseInput& in, const DiagnoseOptions& opt,
                       const std::vector<Effect>& cands, DiagnoseReport& rep,
                       const MapModel* map) {
  // 2. Two passes: robust scales and outliers from the base residuals, then from the fit.
  std::vector<double> er, eaz;
  for (const auto& o : rep.obs) {
    er.push_back(o.e_r);
    eaz.push_back(o.e_az);
  }
  const double floor_r = rangeNoiseFloor(in.sensor);
  const double floor_a = azimuthNoiseFloor(in.sensor);
  double sr = noiseScale(er, floor_r), sa = noiseScale(eaz, floor_a);
  {
    std::vector<double> a = er, b = eaz;
    std::nth_element(a.begin(), a.begin() + a.size() / 2, a.end());
    std::nth_element(b.begin(), b.begin() + b.size() / 2, b.end());
    const double mr = a[a.size() / 2], ma = b[b.size() / 2];
    for (auto& o : rep.obs)
      o.inlier = std::fabs(o.e_r - mr) < 2.0 * opt.outlier_sigma * sr &&
                 std::fabs(o.e_az - ma) < 2.0 * opt.outlier_sigma * sa;
  }
  SelectionOptions so;
  so.alpha = opt.alpha;
  SelectionResult sel;
  Design d;
  for (int pass = 0; pass < 2; ++pass) {
    d = buildDesign(rep.obs, cands, sr, sa, rep.scans, opt.target_nuisance);
    if (map) {
      std::vector<double> cr, ca;
      for (const auto& o : rep.obs) {
        cr.push_back(pass == 0 ? o.e_r : o.fit_r);
        ca.push_back(pass == 0 ? o.e_az : o.fit_az);
      }
      const auto [wr, wa] = withinTargetScales(rep.obs, cr, ca, sr, sa, floor_r, floor_a);
      whitenByTarget(d, rep.obs, *map, sr, sa, wr, wa);
    }
    sel = stepwiseSelect(d.y, d.N, d.C, so);
    // Residuals of every observation under the joint fit.
    std::vector<double> rr, ra;
    for (auto& o : rep.obs) {
      double fr = o.e_r, fa = o.e_az;
      for (size_t i = 0; i < sel.selected.size(); ++i) {
        const int e = static_cast<int>(cands[sel.selected[i]]);
        fr -= sel.joint.coef(d.N.cols() + i) * o.dr[e];
        fa -= sel.joint.coef(d.N.cols() + i) * o.daz[e];
      }
      o.fit_r = fr;
      o.fit_az = fa;
    }
    // Inliers: the joint fit's residuals (they include the nuisance part).
    if (!map) {
      const int m = static_cast<int>(d.rows.size());
      for (int j = 0; j < m; ++j) {
        rep.obs[d.rows[j]].fit_r = sel.joint.resid(j) * sr;
        rep.obs[d.rows[j]].fit_az = sel.joint.resid(m + j) * sa;
      }
    }
    for (auto& o : rep.obs) {
      const double fr = o.fit_r, fa = o.fit_az;
      if (o.inlier) {
        rr.push_back(fr);
        ra.push_back(fa);
      }
    }
    if (pass == 1) break;
    sr = noiseScale(rr, floor_r);
    sa = noiseScale(ra, floor_a);
    // Without a world file a mapped "target" can be a scatterer that is not a point (wall
    // speckle, a moving object): its GLS-whitened residuals after the fit are jointly far
    // beyond their chi-square; all of its views are dropped.
    std::map<int, std::pair<double, int>> chi;
    if (map) {
      const int m = static_cast<int>(d.rows.size());
      const double s2 = std::max(sel.joint.sigma2, 1e-300);
      for (int j = 0; j < m; ++j) {
        auto& c = chi[rep.obs[d.rows[j]].target];
        c.first += (sel.joint.resid(j) * sel.joint.resid(j) +
                    sel.joint.resid(m + j) * sel.joint.resid(m + j)) / s2;
        c.second += 2;
      }
    }
    for (auto& o : rep.obs) {
      o.inlier = std::fabs(o.fit_r) < opt.outlier_sigma * sr &&
                 std::fabs(o.fit_az) < opt.outlier_sigma * sa;
      const auto it = chi.find(o.target);
      if (it != chi.end() && chi2Sf(it->second.first, it->second.second) < 1e-6) o.inlier = false;
    }
  }
  rep.sigma_r = sr;
  rep.sigma_az = sa;
  for (const auto& o : rep.obs) rep.outliers += o.inlier ? 0 : 1;
  rep.candidate_corr = sel.corr;

  // 3. Candidate table (step 1) and per-scan-alignment absorbed fractions.
  const Eigen::VectorXd cand_vif = vif(d.N, d.C);
  for (size_t k = 0; k < cands.size(); ++k) {
    CandidateRow c;
    c.effect = cands[k];
    for (const auto& t : sel.steps.front().tests)
      if (t.index == static_cast<int>(k)) {
        c.estimate = effectValue(in.base, cands[k]) + t.coef;
        c.stddev = t.stddev;
        c.z = t.z;
        c.lr = t.lr;
        c.lm = t.lm;
        c.p = t.p;
        c.delta_bic = t.delta_bic;
        c.absorbed = t.absorbed_nuisance;
      }
    c.absorbed_by_alignment = absorbedFraction(d.A, d.C.col(k));
    c.vif = cand_vif.size() ? cand_vif(k) : 1.0;
    rep.candidates.push_back(c);
  }

  // 4. Selected effects, joint estimates, confounding notes.
  sim::PhysicsConfig fitted = in.base;
  for (size_t i = 0; i < sel.selected.size(); ++i) {
    const int k = sel.selected[i];
    const SelectionStep& st = sel.steps[i];
    EffectResult r;
    r.effect = cands[k];
    r.name = effectName(r.effect);
    r.parameter = effectParameter(r.effect);
    r.unit = effectUnit(r.effect);
    const int col = static_cast<int>(d.N.cols() + i);
    r.change = sel.joint.coef(col);
    r.stddev = std::sqrt(std::max(0.0, sel.joint.cov(col, col)));
    r.value = effectValue(in.base, r.effect) + r.change;
    r.significance = r.stddev > 0 ? std::fabs(r.change) / r.stddev : 0;
    r.lr = st.chosen.lr;
    r.lm = st.chosen.lm;
    r.p = st.chosen.p;
    r.delta_bic = st.chosen.delta_bic;
    r.holm_threshold = st.holm_threshold;
    r.absorbed = st.chosen.absorbed;
    r.absorbed_by_alignment = absorbedFraction(d.A, d.C.col(k));
    r.vif = sel.joint_vif.size() ? sel.joint_vif(i) : 1.0;
    for (size_t j = 0; j < st.confounded.size(); ++j) {
      const Effect other = cands[st.confounded[j]];
      r.confounded_with.push_back(effectName(other));
      std::ostringstream s;
      s << "The data cannot separate " << r.name << " from " << effectName(other)
        << " (correlation of their orthogonalised signatures " << st.confounded_corr[j]
        << "): " << separatingDrive(r.effect, other);
      rep.notes.push_back(s.str());
    }
    if (r.effect == Effect::MotionDistortion) {
      fitted.motion_distortion = r.change > 0.5;
    } else {
      fitted = withEffect(fitted, r.effect, r.change);
    }
    rep.effects.push_back(r);
  }
  // Range residuals alone (what a range-only or scan-to-scan comparison sees): pairs that only
  // the azimuth residuals tell apart are worth a note, since real azimuths are less precise.
  {
    const int m = static_cast<int>(d.y.size() / 2);
    const Eigen::MatrixXd Cr = d.C.topRows(m);
    for (size_t i = 0; i < rep.effects.size(); ++i) {
      const int k = sel.selected[i];
      const Eigen::VectorXd xk = Cr.col(k);
      for (size_t j = 0; j < cands.size(); ++j) {
        if (static_cast<int>(j) == k) continue;
        const auto& cw = rep.effects[i].confounded_with;
        if (std::find(cw.begin(), cw.end(), effectName(cands[j])) != cw.end()) continue;
        const Eigen::VectorXd xj = Cr.col(j);
        const double na = xk.norm(), nb = xj.norm();
        if (na <= 0 || nb <= 0) continue;
        const double c = xk.dot(xj) / (na * nb);
        if (std::fabs(c) <= so.corr_max) continue;
        std::ostringstream s;
        s << "In the range residuals alone " << rep.effects[i].name << " and "
          << effectName(cands[j]) << " cannot be told apart (correlation " << c
          << "); here the azimuth (tangential) residuals separate them (joint correlation "
          << sel.corr(k, j) << "). With less precise azimuths: "
          << separatingDrive(rep.effects[i].effect, cands[j]);
        rep.notes.push_back(s.str());
      }
    }
  }
  // Pairs that are confounded although neither was selected still limit what a null means.
  for (size_t a = 0; a < cands.size(); ++a)
    for (size_t b = a + 1; b < cands.size(); ++b)
      if (std::fabs(sel.corr(a, b)) > so.corr_max) {
        bool said = false;
        for (const auto& r : rep.effects)
          if (r.effect == cands[a] || r.effect == cands[b]) said = true;
        if (said) continue;
        std::ostringstream s;
        s << effectName(cands[a]) << " and " << effectName(cands[b])
          << " have nearly identical signatures in this data (correlation " << sel.corr(a, b)
          << "); " << separatingDrive(cands[a], cands[b]);
        rep.notes.push_back(s.str());
      }
  for (const auto& c : rep.candidates)
    if (c.absorbed_by_alignment > 0.9)
      rep.notes.push_back(effectName(c.effect) + ": " +
                          std::to_string(int(std::lround(100 * c.absorbed_by_alignment))) +
                          "% of its signature is absorbed by a per-scan rigid alignment, so a "
                          "scan-matching comparison would not see it; it is visible here only "
                          "because the trajectory is taken as truth.");
  rep.mismatch_found = !rep.effects.empty();
  rep.fitted = fitted;
}

}  // namespace spinradar::diagnose::detail
