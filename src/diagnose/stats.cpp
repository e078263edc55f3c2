#include "spinradar/diagnose/stats.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include <Eigen/Dense>

namespace spinradar::diagnose {
namespace {

// Regularised upper incomplete gamma Q(a, x): series for x < a + 1, Lentz continued fraction
// otherwise (Numerical Recipes, 3rd ed., 6.2).
double gammaQ(double a, double x) {
  if (x <= 0) return 1.0;
  const double gln = std::lgamma(a);
  if (x < a + 1.0) {
    double ap = a, sum = 1.0 / a, del = sum;
    for (int i = 0; i < 1000; ++i) {
      ap += 1.0;
      del *= x / ap;
      sum += del;
      if (std::fabs(del) < std::fabs(sum) * 1e-15) break;
    }
    return std::max(0.0, 1.0 - sum * std::exp(-x + a * std::log(x) - gln));
  }
  const double tiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
  for (int i = 1; i < 1000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::fabs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::fabs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::fabs(del - 1.0) < 1e-15) break;
  }
  return std::exp(-x + a * std::log(x) - gln) * h;
}

Eigen::MatrixXd hcat(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) {
  Eigen::MatrixXd M(std::max(A.rows(), B.rows()), A.cols() + B.cols());
  if (A.cols()) M.leftCols(A.cols()) = A;
  if (B.cols()) M.rightCols(B.cols()) = B;
  return M;
}

double dot(const Eigen::VectorXd& a, const Eigen::VectorXd& b) { return a.dot(b); }

}  // namespace

double chi2Sf(double x, int k) {
  if (k <= 0) throw std::invalid_argument("chi2Sf: degrees of freedom must be positive");
  if (!(x > 0)) return 1.0;
  if (k == 1) return std::erfc(std::sqrt(0.5 * x));
  return gammaQ(0.5 * k, 0.5 * x);
}

double normalTwoSidedP(double z) { return std::erfc(std::fabs(z) / std::sqrt(2.0)); }

Eigen::VectorXd orthogonalise(const Eigen::MatrixXd& X, const Eigen::VectorXd& y) {
  if (X.cols() == 0) return y;
  // Column-pivoting QR tolerates rank-deficient nuisance sets.
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(X);
  return y - X * qr.solve(y);
}

double absorbedFraction(const Eigen::MatrixXd& X, const Eigen::VectorXd& x) {
  const double n2 = x.squaredNorm();
  if (n2 <= 0) return 1.0;
  return std::clamp(1.0 - orthogonalise(X, x).squaredNorm() / n2, 0.0, 1.0);
}

Eigen::VectorXd vif(const Eigen::MatrixXd& N, const Eigen::MatrixXd& X) {
  const int k = static_cast<int>(X.cols());
  if (k == 0) return Eigen::VectorXd();
  Eigen::MatrixXd Xp(X.rows(), k);
  for (int j = 0; j < k; ++j) {
    Xp.col(j) = orthogonalise(N, X.col(j));
    const double nn = Xp.col(j).norm();
    if (nn > 0) Xp.col(j) /= nn;
  }
  const Eigen::MatrixXd R = Xp.transpose() * Xp;
  Eigen::VectorXd out(k);
  Eigen::FullPivLU<Eigen::MatrixXd> lu(R);
  if (!lu.isInvertible()) {
    out.setConstant(std::numeric_limits<double>::infinity());
    return out;
  }
  const Eigen::MatrixXd Ri = lu.inverse();
  for (int j = 0; j < k; ++j) out(j) = Ri(j, j);
  return out;
}

std::vector<bool> holm(const std::vector<double>& p, double alpha) {
  const size_t m = p.size();
  std::vector<size_t> order(m);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return p[a] < p[b]; });
  std::vector<bool> rej(m, false);
  for (size_t i = 0; i < m; ++i) {
    if (p[order[i]] > alpha / static_cast<double>(m - i)) break;
    rej[order[i]] = true;
  }
  return rej;
}

OlsFit ols(const Eigen::MatrixXd& X, const Eigen::VectorXd& y) {
  OlsFit f;
  const int n = static_cast<int>(y.size()), p = static_cast<int>(X.cols());
  if (p == 0) {
    f.resid = y;
    f.rss = y.squaredNorm();
    f.sigma2 = n > 0 ? f.rss / n : 0;
    return f;
  }
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(X);
  f.coef = qr.solve(y);
  f.resid = y - X * f.coef;
  f.rss = f.resid.squaredNorm();
  f.sigma2 = f.rss / std::max(1, n - p);
  const Eigen::MatrixXd XtX = X.transpose() * X;
  f.cov = f.sigma2 * XtX.completeOrthogonalDecomposition().pseudoInverse();
  return f;
}

double robustSigma(const std::vector<double>& v) {
  if (v.empty()) return 0;
  std::vector<double> a = v;
  const size_t mid = a.size() / 2;
  std::nth_element(a.begin(), a.begin() + mid, a.end());
  const double med = a[mid];
  for (double& x : a) x = std::fabs(x - med);
  std::nth_element(a.begin(), a.begin() + mid, a.end());
  return 1.4826 * a[mid];
}

SelectionResult stepwiseSelect(const Eigen::VectorXd& y, const Eigen::MatrixXd& N,
                               const Eigen::MatrixXd& C, const SelectionOptions& opt) {
  SelectionResult res;
  const int n = static_cast<int>(y.size()), m = static_cast<int>(C.cols());
  res.n = n;
  if (N.rows() != n && N.cols() > 0) throw std::invalid_argument("stepwiseSelect: N rows");
  if (C.rows() != n) throw std::invalid_argument("stepwiseSelect: C rows");

  // Candidates orthogonalised on the nuisance alone: absorbed fractions and correlations.
  Eigen::MatrixXd Cn(n, m);
  std::vector<double> absorbed_nuis(m, 1.0);
  for (int k = 0; k < m; ++k) {
    Cn.col(k) = orthogonalise(N, C.col(k));
    const double n2 = C.col(k).squaredNorm();
    absorbed_nuis[k] = n2 > 0 ? std::clamp(1.0 - Cn.col(k).squaredNorm() / n2, 0.0, 1.0) : 1.0;
  }
  res.corr = Eigen::MatrixXd::Identity(m, m);
  for (int a = 0; a < m; ++a)
    for (int b = 0; b < m; ++b) {
      const double na = Cn.col(a).norm(), nb = Cn.col(b).norm();
      if (a != b && na > 0 && nb > 0) res.corr(a, b) = dot(Cn.col(a), Cn.col(b)) / (na * nb);
    }

  std::vector<int> remaining(m);
  std::iota(remaining.begin(), remaining.end(), 0);
  Eigen::MatrixXd base = N;
  while (!remaining.empty() && n > base.cols() + 2) {
    const Eigen::VectorXd e0 = orthogonalise(base, y);
    const double rss0 = e0.squaredNorm();
    const int dof1 = n - static_cast<int>(base.cols()) - 1;
    SelectionStep step;
    step.rss_before = rss0;
    std::vector<Eigen::VectorXd> perp(m);
    for (int k : remaining) {
      CandidateTest t;
      t.index = k;
      t.absorbed_nuisance = absorbed_nuis[k];
      perp[k] = orthogonalise(base, C.col(k));
      const double xx = perp[k].squaredNorm(), x0 = C.col(k).squaredNorm();
      t.absorbed = x0 > 0 ? std::clamp(1.0 - xx / x0, 0.0, 1.0) : 1.0;
      if (xx <= 1e-12 * std::max(1.0, x0) || rss0 <= 0) {
        step.tests.push_back(t);  // fully absorbed: not testable
        continue;
      }
      const double xe = dot(perp[k], e0);
      t.coef = xe / xx;
      const double rss1 = std::max(rss0 - xe * xe / xx, 1e-300);
      t.lm = n * (xe * xe / xx) / rss0;
      t.lr = n * std::log(rss0 / rss1);
      t.p = chi2Sf(t.lr, 1);
      t.delta_bic = n * std::log(rss1 / rss0) + std::log(static_cast<double>(n));
      t.stddev = std::sqrt(rss1 / std::max(1, dof1) / xx);
      t.z = t.stddev > 0 ? t.coef / t.stddev : 0;
      step.tests.push_back(t);
    }
    auto best = std::max_element(step.tests.begin(), step.tests.end(),
                                 [](const CandidateTest& a, const CandidateTest& b) {
                                   return a.lr < b.lr;
                                 });
    step.chosen = *best;
    step.holm_threshold = opt.alpha / static_cast<double>(remaining.size());
    step.accepted = best->lr > 0 && best->p < step.holm_threshold &&
                    (!opt.require_bic || best->delta_bic < 0) &&
                    std::fabs(best->z) >= opt.min_abs_z;
    const int kb = best->index;
    step.rss_after = rss0 - (best->lr > 0 ? rss0 * (1.0 - std::exp(-best->lr / n)) : 0.0);
    for (int j : remaining) {
      if (j == kb || !perp[kb].size() || !perp[j].size()) continue;
      const double na = perp[kb].norm(), nb = perp[j].norm();
      if (na <= 0 || nb <= 0) continue;
      const double c = dot(perp[kb], perp[j]) / (na * nb);
      if (std::fabs(c) > opt.corr_max) {
        step.confounded.push_back(j);
        step.confounded_corr.push_back(c);
      }
    }
    res.steps.push_back(step);
    if (!step.accepted) break;
    res.selected.push_back(kb);
    remaining.erase(std::find(remaining.begin(), remaining.end(), kb));
    base = hcat(base, C.col(kb));
  }

  Eigen::MatrixXd S(n, res.selected.size());
  for (size_t i = 0; i < res.selected.size(); ++i) S.col(i) = C.col(res.selected[i]);
  res.joint = ols(hcat(N, S), y);
  res.joint_vif = vif(N, S);
  return res;
}

}  // namespace spinradar::diagnose
