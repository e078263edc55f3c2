#include "spinradar/estimation/refined_estimator.hpp"

#include "cauchy_weights.hpp"

#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "spinradar/estimation/doppler.hpp"
#include "spinradar/estimation/scan_period.hpp"
#include "spinradar/core/lie.hpp"
#include "spinradar/core/normal_equations.hpp"

namespace spinradar {

RefinedEstimator::RefinedEstimator(const EstimatorConfig& config) { setConfig(config); }

void RefinedEstimator::setConfig(const EstimatorConfig& config) {
  config_ = config;
  mc_.setConfig(config);
  mc_.setTangentialFloor(kTangentialFloor);  // its start and gate too (Oxford pair 1)
}

namespace {

/// d p_c / d varpi for p_c = p + beta (u . v) u with v = -varpi_xy: -beta u u^T [1 0].
inline Eigen::Matrix<double, 2, 3> dopplerJacobian(double ux, double uy, double beta) {
  Eigen::Matrix<double, 2, 3> D;
  D << -beta * ux * ux, -beta * ux * uy, 0.0, -beta * uy * ux, -beta * uy * uy, 0.0;
  return D;
}

}  // namespace

bool RefinedEstimator::optimise(Eigen::Vector3d& varpi, Eigen::Matrix3d& cov,
                                double& chi2_per_dof, int& used) {
  const double beta = config_.beta, sr = config_.range_sigma, sa = config_.azimuth_sigma;
  const int n = static_cast<int>(x1_.size());
  w_.assign(n, 1.0);
  Eigen::Matrix3d A, P_inv = Eigen::Matrix3d::Zero();
  Eigen::Vector3d prior = Eigen::Vector3d::Zero();
  if (has_prev_) {
    // White-noise acceleration: the velocity changes by ~sigma * dt between pairs.
    const double dl = kAccelSigma * prior_dt_, da = kAngAccelSigma * prior_dt_;
    Eigen::Matrix3d P = prev_cov_;
    P.diagonal() += Eigen::Vector3d(dl * dl, dl * dl, da * da);
    P_inv = P.inverse();
    prior = -prev_xi_;  // paper convention
  }
  double wr2 = 0.0, wsum = 0.0;
  const int iterations = std::max(3, config_.gn_iterations);
  r2_.assign(n, 0.0);
  for (int it = 0; it < iterations; ++it) {
    // Cauchy weights (robust_loss) from the previous iterate's residuals.
    if (config_.robust_loss && it >= 1) {
      r2_scratch_.assign(r2_.begin(), r2_.end());
      const double inv_scale = cauchyInverseScale(r2_scratch_);
      for (int m = 0; m < n; ++m) w_[m] = cauchyWeight(r2_[m], inv_scale);
    }
    A = P_inv;
    Eigen::Vector3d b = P_inv * (prior - varpi);
    wr2 = wsum = 0.0;
    for (int m = 0; m < n; ++m) {
      const double vx = -varpi(0), vy = -varpi(1);
      const double d1 = beta * (u1x_[m] * vx + u1y_[m] * vy), d2 = beta * (u2x_[m] * vx + u2y_[m] * vy);
      const Eigen::Vector2d p1(x1_[m] + d1 * u1x_[m], y1_[m] + d1 * u1y_[m]);
      const Eigen::Vector2d p2(x2_[m] + d2 * u2x_[m], y2_[m] + d2 * u2y_[m]);
      const double dt = dt_[m];
      const Eigen::Matrix3d T = se2::exp(dt * varpi);
      const Eigen::Matrix2d C = T.topLeftCorner<2, 2>();
      const Eigen::Vector2d g = C * p1 + T.topRightCorner<2, 1>();
      const Eigen::Vector2d e = p2 - g;
      // e(varpi + d) ~ e - G d with G = dt g^odot + C D1 - D2 (Doppler terms of both ends).
      const Eigen::Matrix<double, 2, 3> G = dt * se2::odot2(g) +
                                            C * dopplerJacobian(u1x_[m], u1y_[m], beta) -
                                            dopplerJacobian(u2x_[m], u2y_[m], beta);
      const Eigen::Matrix2d S =
          cartesianCovariance(p2, sr, sa, kTangentialFloor) +
          C * cartesianCovariance(p1, sr, sa, kTangentialFloor) * C.transpose();
      const Eigen::Matrix2d Si = S.inverse();
      const double r2 = e.dot(Si * e);
      r2_[m] = r2;
      const double w = w_[m];  // 1 without robust_loss (see the header)
      const Eigen::Matrix<double, 3, 2> GtW = w * G.transpose() * Si;
      A.noalias() += GtW * G;
      b.noalias() += GtW * e;
      wr2 += w * r2;
      wsum += w;
    }
    Eigen::Vector3d d;
    if (!solveNormalEquations(A, b, d)) return false;
    varpi += d;
    if (it >= 2 && d.head<2>().norm() < 1e-6 && std::abs(d(2)) < 1e-8) break;
  }
  const double dof = std::max(1.0, 2.0 * wsum - 3.0);
  chi2_per_dof = wr2 / dof;
  cov = A.inverse() * std::max(1.0, chi2_per_dof);
  used = n;
  return varpi.allFinite() && cov.allFinite();
}

bool RefinedEstimator::estimate(const FeatureFrame& f1, const FeatureFrame& f2,
                                const std::vector<Match>& matches, std::vector<Keypoint>& c1,
                                std::vector<Keypoint>& c2, MotionEstimate& out) {
  const int64_t ref1 = f1.stamp_ns, ref2 = f2.stamp_ns;
  const double dt_ref = 1e-9 * static_cast<double>(ref2 - ref1);
  const bool continuous = has_prev_ && prev_ref2_ == ref1;
  if (!continuous) has_prev_ = false;
  // 1. MC-RANSAC on the raw keypoints: robust start and gate.
  if (!mc_.estimate(f1.keypoints, f2.keypoints, matches, ref1, ref2, out)) {
    has_prev_ = false;
    dopplerCorrect(f1.keypoints, Eigen::Vector3d::Zero(), 0.0, c1);
    dopplerCorrect(f2.keypoints, Eigen::Vector3d::Zero(), 0.0, c2);
    return false;
  }
  const Eigen::Vector3d xi0 = out.velocity;
  const double beta = config_.beta;
  const double gate2 = config_.inlier_threshold * config_.inlier_threshold;
  x1_.clear(); y1_.clear(); x2_.clear(); y2_.clear();
  u1x_.clear(); u1y_.clear(); u2x_.clear(); u2y_.clear();
  dt_.clear(); midx_.clear();
  for (size_t i = 0; i < matches.size(); ++i) {
    const Keypoint& a = f1.keypoints[matches[i].i1];
    const Keypoint& b = f2.keypoints[matches[i].i2];
    const double ax = std::cos(a.azimuth), ay = -std::sin(a.azimuth);
    const double bx = std::cos(b.azimuth), by = -std::sin(b.azimuth);
    const double da = beta * (ax * xi0(0) + ay * xi0(1)), db = beta * (bx * xi0(0) + by * xi0(1));
    const double dt = 1e-9 * static_cast<double>(b.stamp_ns - a.stamp_ns);
    const Eigen::Matrix3d T = se2::exp(-dt * xi0);
    const Eigen::Vector2d g = T.topLeftCorner<2, 2>() * Eigen::Vector2d(a.x + da * ax, a.y + da * ay) +
                              T.topRightCorner<2, 1>();
    if ((Eigen::Vector2d(b.x + db * bx, b.y + db * by) - g).squaredNorm() > gate2) continue;
    x1_.push_back(a.x); y1_.push_back(a.y); x2_.push_back(b.x); y2_.push_back(b.y);
    u1x_.push_back(ax); u1y_.push_back(ay); u2x_.push_back(bx); u2y_.push_back(by);
    dt_.push_back(dt);
    midx_.push_back(static_cast<int>(i));
  }
  prior_dt_ = dt_ref;
  // 2-4. Doppler-aware, prior-regularised Gauss-Newton on the gated matches.
  Eigen::Vector3d varpi = -xi0;
  Eigen::Matrix3d cov;
  double chi2 = 0.0;
  int used = 0;
  if (static_cast<int>(x1_.size()) < 3 || !optimise(varpi, cov, chi2, used) || used < 3) {
    has_prev_ = false;
    out.ok = false;
    dopplerCorrect(f1.keypoints, Eigen::Vector3d::Zero(), 0.0, c1);
    dopplerCorrect(f2.keypoints, Eigen::Vector3d::Zero(), 0.0, c2);
    return false;
  }
  Eigen::Vector3d xi = -varpi;
  // 6. Standing still.
  if (xi.head<2>().norm() < kStillSpeed && xi.dot(cov.ldlt().solve(xi)) < 11.34 /* chi2_3 99% */)
    xi.setZero();
  // 5. Lag-free T_12 from the previous and current pair velocities, interpolated to the
  //    step's middle: their mean while no scan is missing; after a dropped scan (or on a
  //    recording read every other scan) the current pair weighs more, as each pair's centre
  //    is half a rotation period, not half a step, after its step's middle (scan_period.hpp).
  //    The mean there lagged by a quarter step less half a period (0.125 s at 2 Hz of a 4 Hz
  //    sensor): at a turn entry the step came out 4-5 deg short, and the keyframe
  //    estimator's prior with it (issue 19).
  const double w_prev =
      ScanPeriod::earlierPairWeight(prev_step_, dt_ref, ScanPeriod::rotation(f2));
  if (has_prev_ && w_prev == 0.5) {
    setMotionFromVelocity(0.5 * (prev_xi_ + xi), 0.5 * (prev_cov_ + cov), dt_ref, out);
  } else if (has_prev_) {
    setMotionFromVelocity(w_prev * prev_xi_ + (1.0 - w_prev) * xi,
                          w_prev * prev_cov_ + (1.0 - w_prev) * cov, dt_ref, out);
  } else {
    setMotionFromVelocity(xi, cov, dt_ref, out);
  }
  out.velocity = xi;
  out.velocity_cov = cov;
  out.inliers.clear();
  for (size_t k = 0; k < midx_.size(); ++k)
    if (w_[k] > 0.5) out.inliers.push_back(midx_[k]);
  out.matches = static_cast<int>(matches.size());
  out.ok = true;
  dopplerCorrect(f1.keypoints, xi, beta, c1);
  dopplerCorrect(f2.keypoints, xi, beta, c2);
  prev_xi_ = xi;
  prev_cov_ = cov;
  prev_ref2_ = ref2;
  prev_step_ = dt_ref;
  has_prev_ = true;
  return true;
}

}  // namespace spinradar
