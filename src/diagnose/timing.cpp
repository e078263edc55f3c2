// Timing stage, part 1: what the per-azimuth stamps say (bursts, rotation period per scan).
// Method: include/spinradar/diagnose/timing.hpp and docs/diagnose_timing.md.
#include "spinradar/diagnose/timing.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

#include "spinradar/diagnose/stats.hpp"
#include "timing_detail.hpp"

namespace spinradar::diagnose {
namespace detail {

double chi2ToZ(double chi2, int dof) {
  // Wilson-Hilferty: smooth where chi2Sf underflows (the burst tests reach z in the hundreds).
  if (dof <= 0) return 0;
  const double k = dof, c = 2.0 / (9.0 * k);
  return std::max(0.0, (std::cbrt(std::max(chi2, 0.0) / k) - (1.0 - c)) / std::sqrt(c));
}

std::vector<ScanRows> scanRows(const std::vector<PolarScan>& scans) {
  std::vector<ScanRows> out;
  for (size_t k = 0; k < scans.size(); ++k) {
    const PolarScan& s = scans[k];
    ScanRows r;
    r.scan = static_cast<int>(k);
    std::vector<double> az;
    std::vector<int> rows;
    double prev = 0;
    for (int a = 0; a < s.azimuths; ++a) {
      if (!s.valid.empty() && !s.valid[a]) continue;
      double x = s.azimuth[a];
      if (!az.empty()) {  // unwrap to strictly increasing (as ScanGeometry)
        while (x <= prev) x += 2 * M_PI;
        while (x - prev > M_PI) x -= 2 * M_PI;
        if (x <= prev) continue;
      }
      az.push_back(x);
      rows.push_back(a);
      prev = x;
    }
    if (az.size() < 8)
      throw std::runtime_error("timing: scan " + std::to_string(k) + " has fewer than 8 valid rows");
    std::vector<double> steps;
    for (size_t j = 1; j < az.size(); ++j) steps.push_back(az[j] - az[j - 1]);
    std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
    const double step = steps[steps.size() / 2];
    r.per_rotation = static_cast<int>(std::lround(2 * M_PI / step));
    r.first_ns = s.stamp_ns[rows.front()];
    for (size_t j = 0; j < az.size(); ++j) {
      r.row.push_back(rows[j]);
      r.index.push_back(static_cast<int>(std::lround((az[j] - az.front()) / step)));
      r.t.push_back(static_cast<double>(s.stamp_ns[rows[j]] - r.first_ns) * 1e-9);
    }
    out.push_back(std::move(r));
  }
  return out;
}

namespace {

int floorDiv(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

}  // namespace

int packetFirst(int index, int size, int phase) {
  return phase + floorDiv(index - phase, size) * size;
}

}  // namespace detail

namespace {

using detail::ScanRows;

struct Step {
  double d;
  int next;  // azimuth index of the later row
};

std::vector<Step> stepsOf(const ScanRows& r) {
  std::vector<Step> s;
  for (size_t j = 1; j < r.t.size(); ++j)
    if (r.index[j] - r.index[j - 1] == 1) s.push_back({r.t[j] - r.t[j - 1], r.index[j]});
  return s;
}

/// Best phase of packet size b in one scan: the residue class of the later row's index whose
/// steps differ most from the others (least squares with two means).
struct PhaseFit {
  int phase = 0;
  double rss = 0;
};

PhaseFit bestPhase(const std::vector<Step>& st, int b) {
  std::vector<double> s1(b, 0.0);
  std::vector<int> n1(b, 0);
  double s = 0, ss = 0;
  for (const Step& x : st) {
    const int r = ((x.next % b) + b) % b;
    s1[r] += x.d;
    ++n1[r];
    s += x.d;
    ss += x.d * x.d;
  }
  const int n = static_cast<int>(st.size());
  PhaseFit best;
  best.rss = ss - (n > 0 ? s * s / n : 0);
  for (int r = 0; r < b; ++r) {
    if (n1[r] == 0 || n1[r] == n) continue;
    const double rest = s - s1[r];
    const double rss = ss - s1[r] * s1[r] / n1[r] - rest * rest / (n - n1[r]);
    if (rss < best.rss - 1e-30) best = {r, rss};
  }
  return best;
}

/// Least squares of the stamps: per scan c_k and dt_k, plus (bursts) one common spacing.
struct StampFit {
  OlsFit f;
  int scans = 0;
};

StampFit fitStamps(const std::vector<ScanRows>& rows, bool bursts, int b,
                   const std::vector<int>& phase) {
  int n = 0;
  for (const auto& r : rows) n += static_cast<int>(r.t.size());
  const int K = static_cast<int>(rows.size());
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(n, 2 * K + (bursts ? 1 : 0));
  Eigen::VectorXd y(n);
  int i = 0;
  for (int k = 0; k < K; ++k)
    for (size_t j = 0; j < rows[k].t.size(); ++j, ++i) {
      const int idx = rows[k].index[j];
      X(i, 2 * k) = 1.0;
      if (bursts) {
        const int first = detail::packetFirst(idx, b, phase[k]);
        X(i, 2 * k + 1) = first + b - 1;
        X(i, 2 * K) = idx - first;
      } else {
        X(i, 2 * k + 1) = idx;
      }
      y(i) = rows[k].t[j];
    }
  return {ols(X, y), K};
}

}  // namespace

TimingReport analyseStamps(const std::vector<PolarScan>& scans, double rotation_hz,
                           const TimingOptions& opt) {
  TimingReport t;
  if (scans.empty()) throw std::runtime_error("timing: the recording holds no scans");
  const std::vector<ScanRows> rows = detail::scanRows(scans);
  const int K = static_cast<int>(rows.size());
  t.scans = K;
  for (const auto& r : rows) t.rows += static_cast<int>(r.t.size());
  t.rows_per_rotation = rows.front().per_rotation;

  // 1. Burst search: packet size common to the recording, phase per scan.
  std::vector<std::vector<Step>> steps;
  int n_steps = 0;
  for (const auto& r : rows) {
    steps.push_back(stepsOf(r));
    n_steps += static_cast<int>(steps.back().size());
  }
  int min_steps = n_steps;
  for (const auto& s : steps) min_steps = std::min(min_steps, static_cast<int>(s.size()));
  const int max_b = std::min(opt.max_burst, min_steps / 3);
  int best_b = 0;
  double best_rss = 0;
  long hypotheses = 0;
  for (int b = 2; b <= max_b; ++b) {
    double rss = 0;
    for (const auto& s : steps) rss += bestPhase(s, b).rss;
    hypotheses += b;
    if (best_b == 0 || rss < best_rss) {
      best_b = b;
      best_rss = rss;
    }
  }
  if (best_b > 0) {
    // Pooled two-mean test of the gap step at the packet boundaries.
    double s1 = 0, s0 = 0;
    int n1 = 0, n0 = 0;
    std::vector<int> phase;
    for (const auto& s : steps) {
      const int ph = bestPhase(s, best_b).phase;
      phase.push_back(ph);
      for (const Step& x : s) {
        if (((x.next - ph) % best_b + best_b) % best_b == 0) {
          s1 += x.d;
          ++n1;
        } else {
          s0 += x.d;
          ++n0;
        }
      }
    }
    if (n1 > 0 && n0 > 0) {
      const double m1 = s1 / n1, m0 = s0 / n0;
      const double floor2 = opt.stamp_quantum * opt.stamp_quantum / 6.0;  // step of 2 stamps
      const double sigma2 = std::max(best_rss / std::max(1, n_steps - 2 * K), floor2);
      const double z = (m1 - m0) / std::sqrt(sigma2 * (1.0 / n1 + 1.0 / n0));
      // Bonferroni over every (size, phase) tried in every scan.
      const double p = std::min(1.0, normalTwoSidedP(z) * static_cast<double>(hypotheses * K));
      t.burst_z = z;
      t.burst_p = p;
      t.burst_gap = m1;
      // Packet sizes seen: runs between steps above the midpoint of the two means.
      const double cut = 0.5 * (m0 + m1);
      int runs = 0, exact = 0;
      for (const auto& s : steps) {
        int last = -1;
        for (const Step& x : s)
          if (x.d > cut) {
            if (last >= 0) {
              ++runs;
              exact += (x.next - last == best_b);
            }
            last = x.next;
          }
      }
      const double agreement = runs > 0 ? static_cast<double>(exact) / runs : 0;
      // The search takes the best of many (size, phase) choices per scan, so noisy uniform
      // stamps reach |z| ~ 5 by chance (2 of 20 at 30 us noise before these checks): also
      // require a gap step of at least a tenth of the mean row interval and that most packets
      // seen between two gaps have the fitted size (noise gives random run lengths).
      const double mean_step = (s1 + s0) / (n1 + n0);
      if (z > 0 && p < opt.alpha && m1 - m0 > std::max(opt.min_burst_step, 0.1 * mean_step) &&
          agreement >= 0.5) {
        t.bursts = true;
        t.burst_size = best_b;
        t.burst_phase = phase;
        t.burst_size_agreement = agreement;
      }
    }
  }

  // 2. Stamp model: uniform lines per scan, and the burst model when found.
  const StampFit uni = fitStamps(rows, false, 0, {});
  t.stamp_rms_uniform = std::sqrt(uni.f.rss / std::max(1, t.rows));
  const StampFit fit = t.bursts ? fitStamps(rows, true, t.burst_size, t.burst_phase) : uni;
  t.stamp_rms_model = std::sqrt(fit.f.rss / std::max(1, t.rows));
  if (t.bursts) {
    t.stamp_model = "bursts";
    t.burst_spacing = fit.f.coef(2 * K);
    // Floor: one stamp quantum spread over the rows (an exact fit is not infinitely precise).
    t.burst_spacing_sd = std::max(std::sqrt(std::max(fit.f.cov(2 * K, 2 * K), 0.0)),
                                  opt.stamp_quantum / std::sqrt(12.0 * t.rows));
  }
  // Standard errors are floored at the stamp quantum: a perfect fit is not infinitely precise.
  const double q2 = opt.stamp_quantum * opt.stamp_quantum / 12.0;
  const int P = t.rows_per_rotation;
  std::vector<int> row0(K, 0);  // first row of each scan in the stacked fit
  for (int k = 1; k < K; ++k) row0[k] = row0[k - 1] + static_cast<int>(rows[k - 1].t.size());
  double dt_sum = 0;
  for (int k = 0; k < K; ++k) {
    const double dt = fit.f.coef(2 * k + 1);
    double m = 0, sxx = 0;
    for (int idx : rows[k].index) m += idx;
    m /= static_cast<double>(rows[k].index.size());
    for (int idx : rows[k].index) sxx += (idx - m) * (idx - m);
    // Stamp errors are correlated inside a packet (a late packet delays all its rows), so the
    // row-level OLS variance is optimistic: also take the slope variance from the residuals
    // averaged over blocks (packets, or 16 rows for uniform stamps), and keep the larger.
    const int block = t.bursts ? t.burst_size : 16;
    const int phase = t.bursts ? t.burst_phase[k] : 0;
    std::map<int, std::pair<double, double>> sums;  // block -> (sum residual, sum index)
    std::map<int, int> counts;
    for (size_t j = 0; j < rows[k].index.size(); ++j) {
      const int idx = rows[k].index[j];
      const int b = detail::packetFirst(idx, block, phase);
      sums[b].first += fit.f.resid(row0[k] + static_cast<int>(j));
      sums[b].second += idx;
      ++counts[b];
    }
    double s2b = 0, sxb = 0;
    for (const auto& [b, sr] : sums) {
      const double c = counts[b];
      s2b += (sr.first / c) * (sr.first / c);
      sxb += (sr.second / c - m) * (sr.second / c - m);
    }
    const int nb = static_cast<int>(sums.size());
    const double v_block = nb > 2 && sxb > 0 ? s2b / (nb - 2) / sxb : 0.0;
    const double v = std::max({fit.f.cov(2 * k + 1, 2 * k + 1), v_block,
                               q2 / std::max(sxx, 1.0)});
    dt_sum += dt;
    t.period.push_back(dt * P);
    t.period_sd.push_back(std::sqrt(v) * P);
  }
  t.row_interval = dt_sum / K;
  for (int k = 0; k + 1 < K; ++k) {
    const double c0 = static_cast<double>(rows[k].first_ns) * 1e-9 + fit.f.coef(2 * k);
    const double c1 = static_cast<double>(rows[k + 1].first_ns) * 1e-9 + fit.f.coef(2 * k + 2);
    t.start_gap.push_back(c1 - c0);
  }
  // 3. Does the period vary from scan to scan? Weighted equality test and the spread.
  // Stamps that do not advance (all zero, or made up per scan) carry no period information.
  if (K >= 2 && t.row_interval > 0) {
    double sw = 0, swx = 0, mean = 0, vbar = 0;
    for (int k = 0; k < K; ++k) {
      const double w = 1.0 / std::max(t.period_sd[k] * t.period_sd[k], 1e-30);
      sw += w;
      swx += w * t.period[k];
      mean += t.period[k] / K;
      vbar += t.period_sd[k] * t.period_sd[k] / K;
    }
    const double wmean = swx / sw;
    double q = 0, ss = 0;
    for (int k = 0; k < K; ++k) {
      q += (t.period[k] - wmean) * (t.period[k] - wmean) /
           std::max(t.period_sd[k] * t.period_sd[k], 1e-30);
      ss += (t.period[k] - mean) * (t.period[k] - mean);
    }
    t.period_mean = mean;
    t.period_dof = K - 1;
    t.period_chi2 = q;
    t.period_p = chi2Sf(q, K - 1);
    const double var = std::max(0.0, ss / (K - 1) - vbar);
    t.period_rel_std = std::sqrt(var) / mean;
    t.period_rel_std_sd = t.period_rel_std / std::sqrt(2.0 * (K - 1));
  } else if (K == 1) {
    t.period_mean = t.period.front();
  }
  // Scan start times: a second view of the period, from the clock that stamps the scans.
  if (t.start_gap.size() >= 2 && t.period_mean > 0) {
    std::vector<double> g;
    for (double x : t.start_gap) {
      const double m = std::max(1.0, std::round(x / t.period_mean));  // skipped scans
      g.push_back(x / m);
    }
    double mean = 0, ss = 0;
    for (double x : g) mean += x / g.size();
    for (double x : g) ss += (x - mean) * (x - mean);
    t.start_gap_mean = mean;
    t.start_gap_rel_std = std::sqrt(ss / (g.size() - 1)) / mean;
    if (t.start_gap_rel_std > 0.005 || std::fabs(mean - t.period_mean) > 0.005 * t.period_mean)
      t.notes.push_back(
          "Scan start times are " + std::to_string(std::lround(mean * 1e6)) + " us apart on "
          "average (relative std " + std::to_string(std::lround(t.start_gap_rel_std * 1e4) / 100.0)
              .substr(0, 5) + " % over " + std::to_string(g.size()) + " gaps) while the row stamps "
          "give " + std::to_string(std::lround(t.period_mean * 1e6)) + " us per rotation. "
          "Whether the rotation or the clock that stamps the scans varies cannot be told from "
          "the stamps alone; if the row stamps are made up from one time per scan (RADIATE), "
          "they say nothing about the rotation.");
  }
  if (rotation_hz > 0)
    t.notes.push_back("Period in the sensor configuration: " +
                      std::to_string(std::lround(1e6 / rotation_hz)) + " us.");
  detail::addStampFindings(t, opt);
  return t;
}

std::vector<PolarScan> correctedStamps(const std::vector<PolarScan>& scans,
                                       const TimingReport& timing) {
  if (!timing.bursts) return scans;
  const std::vector<ScanRows> rows = detail::scanRows(scans);
  const StampFit fit = fitStamps(rows, true, timing.burst_size, timing.burst_phase);
  std::vector<PolarScan> out = scans;
  const int K = static_cast<int>(rows.size());
  for (int k = 0; k < K; ++k) {
    const double c = fit.f.coef(2 * k), dt = fit.f.coef(2 * k + 1);
    for (size_t j = 0; j < rows[k].row.size(); ++j)
      out[k].stamp_ns[rows[k].row[j]] =
          rows[k].first_ns + std::llround((c + rows[k].index[j] * dt) * 1e9);
  }
  return out;
}

}  // namespace spinradar::diagnose
