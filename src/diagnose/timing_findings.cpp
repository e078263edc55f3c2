// Timing stage, part 2: rotation jitter from target residuals, the findings with their
// evidence and the timing model to use (advice); the report sections: timing_report.cpp.
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include <Eigen/Dense>

#include "spinradar/diagnose/diagnose.hpp"
#include "spinradar/diagnose/stats.hpp"
#include "spinradar/diagnose/timing.hpp"
#include "diagnose_steps.hpp"
#include "markdown_table.hpp"
#include "timing_detail.hpp"

namespace spinradar::diagnose {
namespace {

using detail::scansWord;
using detail::usRms;

/// Scan-to-scan figures from few scans: say how weak.
std::string spreadEvidence(int k) {
  if (k < 3) return "only " + scansWord(k) + ": no spread can be estimated";
  const double rel = 1.0 / std::sqrt(2.0 * (k - 1));
  std::string s = scansWord(k) + "; the spread itself is known to about +-" +
                  fmt(100 * rel, 2) + " % (1/sqrt(2(K-1)))";
  if (k < 10) s += ": weak evidence, record more scans";
  return s;
}

}  // namespace

namespace detail {

void addStampFindings(TimingReport& t, const TimingOptions& opt) {
  if (t.bursts) {
    TimingFinding f;
    f.name = "stamp_bursts";
    f.parameter = "spacing";
    f.unit = "s";
    f.value = t.burst_spacing;
    f.stddev = t.burst_spacing_sd;
    f.significance = t.burst_z;
    f.p = t.burst_p;
    f.scans = t.scans;
    const int packets = static_cast<int>(std::lround(
        static_cast<double>(t.rows) / std::max(1, t.burst_size)));
    f.evidence = "about " + std::to_string(packets) + " packets in " + scansWord(t.scans) +
                 "; " + fmt(100 * t.burst_size_agreement, 3) +
                 " % of the packets seen between two gaps have exactly " +
                 std::to_string(t.burst_size) + " rows";
    f.details = {{"size", t.burst_size},
                 {"spacing_s", t.burst_spacing},
                 {"spacing_sd_s", t.burst_spacing_sd},
                 {"gap_s", t.burst_gap},
                 {"size_agreement", t.burst_size_agreement},
                 {"phase", t.burst_phase},
                 {"delay", "not identifiable from stamps (a timestamp offset)"}};
    t.findings.push_back(f);
  }
  if (t.scans >= 2 && t.period_p < opt.alpha && t.period_rel_std > opt.min_period_variation) {
    TimingFinding f;
    f.name = "rotation_period_variation";
    f.parameter = "relative std of the period (stamps)";
    f.value = t.period_rel_std;
    f.stddev = t.period_rel_std_sd;
    f.significance = chi2ToZ(t.period_chi2, t.period_dof);
    f.p = t.period_p;
    f.scans = t.scans;
    f.evidence = spreadEvidence(t.scans);
    f.details = {{"period_s", t.period}, {"period_sd_s", t.period_sd}};
    t.findings.push_back(f);
  }
}

}  // namespace detail

void analyseJitter(const std::vector<Observation>& obs, int scans, double sigma_r,
                   double sigma_az, double floor_r, double floor_az, double tau_fixed,
                   bool target_nuisance, TimingReport& t, const TimingOptions& opt) {
  const int to = static_cast<int>(Effect::TimestampOffset);
  if (sigma_r <= 0 || sigma_az <= 0 || scans < 2) return;
  // Scans with enough returns and a usable regressor.
  // A scan's information on its stretch is the squared norm of its whitened regressor; a scan
  // in which the sensor stands still (stretching its firing times moves nothing) has none,
  // and a stretch it cannot place to better than 100 % (information below 1) is left out:
  // kept, its estimate 0 +- 0 of the minimum-norm solution pulled the spread down.
  std::vector<int> per_scan(scans, 0);
  std::vector<double> info(scans, 0.0);
  for (const auto& o : obs)
    if (o.scan >= 0 && o.scan < scans) {
      ++per_scan[o.scan];
      const double tau = tau_fixed < 0 ? o.tau : tau_fixed;
      info[o.scan] += std::pow(tau * o.dr[to] / sigma_r, 2) + std::pow(tau * o.daz[to] / sigma_az, 2);
    }
  std::vector<int> col(scans, -1), used;
  for (int k = 0; k < scans; ++k)
    if (per_scan[k] >= 3 && info[k] >= 1.0) {
      col[k] = static_cast<int>(used.size());
      used.push_back(k);
    }
  if (used.size() < 3) {
    t.notes.push_back("Rotation jitter not tested: fewer than 3 scans with 3 or more target "
                      "returns and a measurable stretch (sensor moving).");
    return;
  }
  std::vector<int> tcol;  // target -> first nuisance column
  int n_nuis = 0;
  if (target_nuisance) {
    int max_t = 0;
    for (const auto& o : obs) max_t = std::max(max_t, o.target + 1);
    tcol.assign(max_t, -1);
    for (const auto& o : obs)
      if (o.scan >= 0 && o.scan < scans && col[o.scan] >= 0 && tcol[o.target] < 0) {
        tcol[o.target] = n_nuis;
        n_nuis += 2;
      }
  }
  const int K = static_cast<int>(used.size());
  // Residuals after the catalogue fit; own robust scales and outliers (the catalogue's inlier
  // flags were set without the per-scan stretches, so a large jitter would be cut away there).
  std::vector<const Observation*> rows;
  for (const auto& o : obs)
    if (o.scan >= 0 && o.scan < scans && col[o.scan] >= 0) rows.push_back(&o);
  std::vector<bool> keep(rows.size(), true);
  double sr = sigma_r, sa = sigma_az;
  {
    // Robust start: per scan, the x^2-weighted median of y / x over both residual components.
    // Scale and outliers from a plain first fit fail when most scans are clean: the robust
    // scale collapses to the floor, and a few jumped peaks drag the fit, so the returns of the
    // jittered scans would all be cut as outliers.
    std::vector<std::vector<std::pair<double, double>>> ratio(K);
    auto add = [&](int k, double x, double y) {
      if (std::fabs(x) > 1e-12) ratio[k].push_back({y / x, x * x});
    };
    for (const Observation* o : rows) {
      const double tau = tau_fixed < 0 ? o->tau : tau_fixed;
      add(col[o->scan], -tau * o->dr[to] / sigma_r, o->fit_r / sigma_r);
      add(col[o->scan], -tau * o->daz[to] / sigma_az, o->fit_az / sigma_az);
    }
    std::vector<double> e0(K, 0.0);
    for (int k = 0; k < K; ++k) {
      auto& v = ratio[k];
      std::sort(v.begin(), v.end());
      double total = 0, acc = 0;
      for (const auto& p : v) total += p.second;
      for (const auto& p : v) {
        acc += p.second;
        if (acc >= 0.5 * total) {
          e0[k] = p.first;
          break;
        }
      }
    }
    std::vector<double> rr, ra;
    for (const Observation* o : rows) {
      const double tau = tau_fixed < 0 ? o->tau : tau_fixed;
      rr.push_back(o->fit_r + e0[col[o->scan]] * tau * o->dr[to]);
      ra.push_back(o->fit_az + e0[col[o->scan]] * tau * o->daz[to]);
    }
    sr = detail::noiseScale(rr, floor_r);
    sa = detail::noiseScale(ra, floor_az);
    for (size_t i = 0; i < rows.size(); ++i)
      keep[i] = std::fabs(rr[i]) < opt.outlier_sigma * sr && std::fabs(ra[i]) < opt.outlier_sigma * sa;
  }
  OlsFit fit;
  Eigen::MatrixXd X;
  std::vector<int> idx;
  for (int pass = 0; pass < 3; ++pass) {
    idx.clear();
    for (size_t i = 0; i < rows.size(); ++i)
      if (keep[i]) idx.push_back(static_cast<int>(i));
    const int m = static_cast<int>(idx.size());
    X = Eigen::MatrixXd::Zero(2 * m, n_nuis + K);
    Eigen::VectorXd y(2 * m);
    for (int j = 0; j < m; ++j) {
      const Observation& o = *rows[idx[j]];
      const double tau = tau_fixed < 0 ? o.tau : tau_fixed;
      y(j) = o.fit_r / sr;
      y(m + j) = o.fit_az / sa;
      X(j, n_nuis + col[o.scan]) = -tau * o.dr[to] / sr;
      X(m + j, n_nuis + col[o.scan]) = -tau * o.daz[to] / sa;
      if (target_nuisance)
        for (int q = 0; q < 2; ++q) {
          X(j, tcol[o.target] + q) = o.tr[q] / sr;
          X(m + j, tcol[o.target] + q) = o.taz[q] / sa;
        }
    }
    fit = ols(X, y);
    if (pass == 2) break;
    std::vector<double> rr, ra;
    for (int j = 0; j < m; ++j) {
      rr.push_back(fit.resid(j) * sr);
      ra.push_back(fit.resid(m + j) * sa);
    }
    // The catalogue's scales: the larger of the MAD and the 5 %-trimmed RMS, floored. Peak
    // positions of noise-free renders are quantised (residuals 0 or +-half a bin): the MAD
    // alone is then 0 and every non-zero residual would be cut as an outlier.
    const double nsr = detail::noiseScale(rr, floor_r);
    const double nsa = detail::noiseScale(ra, floor_az);
    for (int j = 0; j < m; ++j)
      keep[idx[j]] = std::fabs(rr[j]) < opt.outlier_sigma * nsr &&
                     std::fabs(ra[j]) < opt.outlier_sigma * nsa;
    sr = nsr;
    sa = nsa;
  }
  t.jitter_tested = true;
  double exact_zero = 0;  // returns whose residual is exactly 0 (quantised, noise-free peaks)
  for (const Observation* o : rows) exact_zero += (o->fit_r == 0.0 && o->fit_az == 0.0);
  exact_zero /= static_cast<double>(rows.size());
  t.stretch.assign(scans, 0.0);
  t.stretch_sd.assign(scans, 0.0);
  Eigen::VectorXd e(K);
  Eigen::MatrixXd cov(K, K);
  double vbar = 0, mean = 0;
  // Noise variance at least 1 in whitened units (the scales' floors are the precision a peak
  // fit can claim), so an exact fit does not make tiny differences infinitely significant.
  const Eigen::MatrixXd inv =
      (X.transpose() * X).completeOrthogonalDecomposition().pseudoInverse();
  const double s2_eff = std::max(fit.sigma2, 1.0);
  for (int a = 0; a < K; ++a) {
    e(a) = fit.coef(n_nuis + a);
    for (int b = 0; b < K; ++b) cov(a, b) = s2_eff * inv(n_nuis + a, n_nuis + b);
    t.stretch[used[a]] = e(a);
    t.stretch_sd[used[a]] = std::sqrt(std::max(cov(a, a), 0.0));
    vbar += cov(a, a) / K;
    mean += e(a) / K;
  }
  // Wald test that every scan has the same stretch: differences to the last scan.
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(K - 1, K);
  for (int a = 0; a + 1 < K; ++a) {
    C(a, a) = 1;
    C(a, K - 1) = -1;
  }
  const Eigen::VectorXd ce = C * e;
  const Eigen::MatrixXd cc = C * cov * C.transpose();
  // An exact fit (noise-free simulation) leaves no variance: nothing to test.
  const double q = cc.norm() > 0 ? ce.dot(cc.ldlt().solve(ce)) : 0.0;
  double ss = 0;
  for (int a = 0; a < K; ++a) ss += (e(a) - mean) * (e(a) - mean);
  const double wmean = mean;
  t.jitter_dof = K - 1;
  t.jitter_chi2 = q;
  t.jitter_p = chi2Sf(q, K - 1);
  // Spread of the true stretches: sample variance about the mean minus the estimation noise.
  const double var = std::max(0.0, ss / (K - 1) - vbar);
  t.jitter_std = std::sqrt(var);
  t.jitter_std_sd = var > 0 ? std::sqrt(2.0 / (K - 1)) * (var + vbar) / (2 * t.jitter_std) : 0;
  if (t.jitter_p < opt.alpha && t.jitter_std > 0) {
    TimingFinding f;
    f.name = "rotation_jitter";
    f.parameter = "relative std of the rotation period (targets)";
    f.value = t.jitter_std;
    f.stddev = t.jitter_std_sd;
    f.significance = detail::chi2ToZ(q, K - 1);
    f.p = t.jitter_p;
    f.scans = K;
    f.evidence = spreadEvidence(K) + "; per-scan stretch known to +-" +
                 fmt(std::sqrt(vbar), 2) + " (mean 1-sigma)";
    if (target_nuisance)
      f.evidence += "; scene mapped from the recording: the mapped positions absorb part of "
                    "each scan's shift, so the spread is a lower bound (2-3.5x low in simulation)";
    if (exact_zero > 0.3)
      f.evidence += "; " + fmt(100 * exact_zero, 2) + " % of the returns have exactly zero "
                    "residual (quantised peaks): shifts below a quantisation step read as 0, so "
                    "the spread is a lower bound";
    f.details = {{"stretch", t.stretch}, {"stretch_sd", t.stretch_sd}, {"mean_stretch", wmean},
                 {"exact_zero_fraction", exact_zero}};
    t.findings.push_back(f);
  }
}

void adviseTiming(TimingReport& t, double offset_s, double offset_sd) {
  t.advice.clear();
  auto has = [&](const std::string& n) {
    return std::any_of(t.findings.begin(), t.findings.end(),
                       [&](const TimingFinding& f) { return f.name == n; });
  };
  const double ms = 1e3;
  if (t.bursts) {
    t.advice.push_back(
        "Stamps are packet arrival times, not firing times: rows come in packets of " +
        std::to_string(t.burst_size) + " (stamps " + fmt(t.burst_spacing * 1e6, 4) +
        " us apart inside a packet, a " + fmt(t.burst_gap * ms, 4) +
        " ms step between packets). Use uniform firing times t_i = c_k + i * T_k / " +
        std::to_string(t.rows_per_rotation) + " per scan (fitted T = " +
        fmt(t.period_mean * ms, 6) + " ms) instead of the stamps. The delay between a "
        "packet's acquisition and its arrival is a constant timestamp offset, measurable only "
        "against a trajectory. Simulator: \"stamp_bursts\": {\"size\": " +
        std::to_string(t.burst_size) + ", \"spacing\": " + fmt(t.burst_spacing, 4) +
        (offset_sd > 0 ? ", \"delay\": " + fmt(offset_s, 4) : std::string()) + "}.");
  } else {
    const bool jitter = has("rotation_jitter");
    t.advice.push_back("Stamps are uniform (" + fmt(usRms(t.stamp_rms_uniform), 3) +
                       " us RMS about one line per scan, row interval " +
                       fmt(t.row_interval * 1e6, 5) + " us)" +
                       (jitter ? ", but nominal: see the rotation jitter below."
                               : ": use them as firing times."));
  }
  if (has("rotation_period_variation"))
    t.advice.push_back("The rotation period in the stamps varies by " +
                       fmt(100 * t.period_rel_std, 3) +
                       " % (std) from scan to scan: use each scan's own period (first-stamp "
                       "differences or the stamp slope), not the nominal one.");
  if (has("rotation_jitter"))
    t.advice.push_back(
        "The stamps are nominal but the true rotation period varies by " +
        fmt(100 * t.jitter_std, 3) + " % (std) from scan to scan (the targets' positions "
        "stretch with it): the stamps do not follow the rotation. Take firing times from a "
        "per-scan period the sensor measures (encoder/clock), or simulate with "
        "\"rotation_jitter\": " + fmt(t.jitter_std, 3) + ".");
  if (offset_sd > 0)
    t.advice.push_back("Stamps are offset from the firing times by " + fmt(offset_s * ms, 4) +
                       " +- " + fmt(offset_sd * ms, 2) + " ms (catalogue effect "
                       "timestamp_offset): correct them by " + fmt(-offset_s * ms, 4) +
                       " ms, or simulate with \"timestamp_offset\": " + fmt(offset_s, 4) + "." +
                       (t.bursts ? " Here it is measured against the firing times fitted from "
                                   "the bursty stamps: it is the packet delay (arrival minus "
                                   "acquisition of the packet's last row)."
                                 : ""));
  if (t.findings.empty() && offset_sd <= 0)
    t.advice.push_back("No timing effect found: uniform firing at the recorded stamps is the "
                       "timing model to use.");
}

}  // namespace spinradar::diagnose
