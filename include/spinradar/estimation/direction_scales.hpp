#pragma once
// Residual scales estimated apart along each match's radial and tangential direction, for the
// sandwich covariance of a weighted least-squares solve (issue 19).
//
// Why: the keyframe solve weighs each match with the covariance S its configured range and
// azimuth noise give (range_sigma radially, |p| azimuth_sigma tangentially), and its
// covariance rescaled that S by one chi2/dof. The two directions are off by different
// factors: azimuth peaks (sub-row azimuths) have a much smaller tangential error than row
// keypoints while their radial error is alike (city_wide, 400 scans, median over solves:
// k_r 0.37, k_t 0.06 with peaks; 0.88 / 1.04 with rows), and a narrow range PSF shrinks the
// radial one alone; one factor, set by both, over-states the tangential (yaw) part with
// peaks and under-states it where the radial residuals are the small ones.
//
// Model: the true residual covariance of a match is G S G with G = sqrt(k_r) u u^T +
// sqrt(k_t) t t^T (u: the radial direction, t: the tangential one), i.e. S's variance along u
// scaled by k_r and along t by k_t. k_r and k_t come from the residuals normalised by S's own
// variance in that direction, robustly (median absolute value, so that the few wrong matches
// left inside the gate do not set the scale of all; the mean square, k_t median 0.66 with
// peaks on city_wide, made the registrations' yaw sigma ~3x their measured error, the median
// 0.051 deg against 0.046), with a floor. The meat of the sandwich
// sum_m J_m^T S_m^-1 G S G S_m^-1 J_m is accumulated per match as three matrices, so the scales
// can be applied once all residuals are in. With k_r = k_t = k it is k times the information
// of the matches: the one-factor covariance.
#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Core>

namespace spinradar {

template <int N>
class DirectionScales {
 public:
  using MatN = Eigen::Matrix<double, N, N>;
  using MatN2 = Eigen::Matrix<double, N, 2>;
  /// 1.4826 median|z| is the standard deviation of a zero-mean normal z.
  static constexpr double kMadToSigma = 1.4826;

  /// Room for n matches (no allocation per solve after this).
  void reserve(size_t n) {
    zr_.reserve(n);
    zt_.reserve(n);
  }
  void clear() {
    Mr_.setZero();
    Mt_.setZero();
    Mrt_.setZero();
    zr_.clear();
    zt_.clear();
  }
  /// One match: residual e, the covariance S it was weighted with, u its radial direction
  /// (unit), JtW = J^T S^-1 (J: the residual's Jacobian over the N parameters).
  void add(const Eigen::Vector2d& e, const Eigen::Matrix2d& S, const Eigen::Vector2d& u,
           const MatN2& JtW) {
    const Eigen::Vector2d t(-u.y(), u.x());
    const Eigen::Vector2d Su = S * u;
    const double vr = u.dot(Su), vt = t.dot(S * t), vrt = t.dot(Su);
    const Eigen::Matrix<double, N, 1> a = JtW * u, b = JtW * t;
    Mr_.noalias() += vr * a * a.transpose();
    Mt_.noalias() += vt * b * b.transpose();
    Mrt_.noalias() += vrt * (a * b.transpose() + b * a.transpose());
    zr_.push_back(u.dot(e) / std::sqrt(vr));
    zt_.push_back(t.dot(e) / std::sqrt(vt));
  }
  size_t count() const { return zr_.size(); }

  /// Estimates k_r, k_t: (1.4826 median |z|)^2 per direction, times n / (n - params / 2) for
  /// the parameters fitted to the same residuals (as chi2 / dof), at least `floor`.
  /// Reorders the stored residuals.
  void estimate(int params, double floor) {
    const double n = static_cast<double>(zr_.size());
    const double dof = n > 0.5 * params + 1.0 ? n / (n - 0.5 * params) : 1.0;
    k_r_ = std::max(floor, dof * robustVariance(zr_));
    k_t_ = std::max(floor, dof * robustVariance(zt_));
  }
  double radialScale() const { return k_r_; }
  double tangentialScale() const { return k_t_; }
  /// sum_m J^T S^-1 (G S G) S^-1 J with the estimated scales.
  MatN meat() const { return k_r_ * Mr_ + k_t_ * Mt_ + std::sqrt(k_r_ * k_t_) * Mrt_; }

 private:
  static double robustVariance(std::vector<double>& z) {
    if (z.empty()) return 0.0;
    for (double& x : z) x = std::abs(x);
    const auto mid = z.begin() + static_cast<std::ptrdiff_t>(z.size() / 2);
    std::nth_element(z.begin(), mid, z.end());
    const double s = kMadToSigma * *mid;
    return s * s;
  }

  MatN Mr_ = MatN::Zero(), Mt_ = MatN::Zero(), Mrt_ = MatN::Zero();
  std::vector<double> zr_, zt_;
  double k_r_ = 1.0, k_t_ = 1.0;
};

}  // namespace spinradar
