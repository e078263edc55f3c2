#include "spinradar/estimation/rigid_ransac.hpp"

#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/mc_ransac.hpp"

namespace spinradar {

bool fitRigid2d(const Eigen::Vector2d* a, const Eigen::Vector2d* b, const int* idx, int n,
                Eigen::Matrix3d& T) {
  if (n < 2) return false;
  Eigen::Vector2d ca = Eigen::Vector2d::Zero(), cb = Eigen::Vector2d::Zero();
  for (int k = 0; k < n; ++k) {
    ca += a[idx[k]];
    cb += b[idx[k]];
  }
  ca /= n;
  cb /= n;
  double sdot = 0.0, scross = 0.0;
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector2d qa = a[idx[k]] - ca, qb = b[idx[k]] - cb;
    sdot += qb.dot(qa);
    scross += qb.x() * qa.y() - qb.y() * qa.x();
  }
  if (std::abs(sdot) + std::abs(scross) < 1e-12) return false;  // all points coincide
  const double th = std::atan2(scross, sdot), c = std::cos(th), s = std::sin(th);
  T.setIdentity();
  T(0, 0) = c;
  T(0, 1) = -s;
  T(1, 0) = s;
  T(1, 1) = c;
  T.topRightCorner<2, 1>() = ca - T.topLeftCorner<2, 2>() * cb;
  return true;
}

RigidRansac::RigidRansac(const EstimatorConfig& config) : config_(config) {}

int RigidRansac::countInliers(const Eigen::Matrix3d& T, std::vector<int>* inliers) const {
  // The gate of MC-RANSAC (one azimuth row of tangential slack, see McRansac::kAzimuthQuantum).
  const double thr = config_.inlier_threshold, sa = config_.azimuth_sigma;
  const Eigen::Matrix2d C = T.topLeftCorner<2, 2>();
  const Eigen::Vector2d r = T.topRightCorner<2, 1>();
  int n = 0;
  if (inliers) inliers->clear();
  for (size_t i = 0; i < p1_.size(); ++i) {
    if (withinInlierGate(p1_[i] - C * p2_[i] - r, p1_[i], thr, sa)) {
      ++n;
      if (inliers) inliers->push_back(static_cast<int>(i));
    }
  }
  return n;
}

bool RigidRansac::estimate(const std::vector<Keypoint>& k1, const std::vector<Keypoint>& k2,
                           const std::vector<Match>& matches, int64_t ref1_ns, int64_t ref2_ns,
                           MotionEstimate& out) {
  p1_.resize(matches.size());
  p2_.resize(matches.size());
  for (size_t i = 0; i < matches.size(); ++i) {
    const Keypoint& a = k1[matches[i].i1];
    const Keypoint& b = k2[matches[i].i2];
    p1_[i] = {a.x, a.y};
    p2_[i] = {b.x, b.y};
  }
  return estimate(p1_, p2_, 1e-9 * static_cast<double>(ref2_ns - ref1_ns), out);
}

bool RigidRansac::estimate(const std::vector<Eigen::Vector2d>& p1,
                           const std::vector<Eigen::Vector2d>& p2, double dt_ref,
                           MotionEstimate& out) {
  if (&p1 != &p1_) p1_ = p1;  // no-op when called from the keypoint overload
  if (&p2 != &p2_) p2_ = p2;
  const int M = static_cast<int>(p1_.size());
  out.ok = false;
  out.matches = M;
  out.inliers.clear();
  if (M < 2 || !(dt_ref > 0.0)) return false;

  // Fixed seed per call, as the paper does, so every scan pair is reproducible.
  rng_.seed(static_cast<uint32_t>(config_.ransac_seed));
  std::uniform_int_distribution<int> pick(0, M - 1);
  int best_n = 0;
  Eigen::Matrix3d T;
  best_.clear();
  for (int it = 0; it < config_.ransac_iterations; ++it) {
    int sub[2] = {pick(rng_), pick(rng_)};
    if (sub[0] == sub[1]) continue;
    // Subsets whose two points nearly coincide fix the rotation poorly.
    if ((p1_[sub[0]] - p1_[sub[1]]).squaredNorm() < 1.0) continue;
    if (!fitRigid2d(p1_.data(), p2_.data(), sub, 2, T)) continue;
    const int n = countInliers(T, nullptr);
    if (n > best_n) {
      best_n = n;
      countInliers(T, &best_);
    }
  }
  if (best_n < 2) return false;
  if (!fitRigid2d(p1_.data(), p2_.data(), best_.data(), best_n, T)) return false;

  // Covariance of the left perturbation of T_12 from the point-to-point normal equations,
  // with the noise variance estimated from the inlier residuals.
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  double chi2 = 0.0;
  for (int i : best_) {
    const Eigen::Vector2d q = T.topLeftCorner<2, 2>() * p2_[i] + T.topRightCorner<2, 1>();
    const Eigen::Matrix<double, 2, 3> G = se2::odot2(q);
    A += G.transpose() * G;
    chi2 += (p1_[i] - q).squaredNorm();
  }
  const int dof = 2 * best_n - 3;
  const double s2 = dof > 0 ? std::max(chi2 / dof, 1e-6) : 1.0;
  Eigen::LDLT<Eigen::Matrix3d> ldlt(A);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 1e-12)) return false;
  const Eigen::Matrix3d cov_xi = s2 * ldlt.solve(Eigen::Matrix3d::Identity());

  // cov_xi is over the left perturbation of T_12; velocity = log(T_12)/dt_ref moves it
  // through the inverse left Jacobian.
  const Eigen::Vector3d xi = se2::log(T);
  const Eigen::Matrix3d Jinv = se2::leftJacobian(xi).inverse();
  const Eigen::Matrix3d L = se2::leftPerturbationToXyYaw(T);
  out.T_12 = T;
  out.T_12_cov = L * cov_xi * L.transpose();
  out.velocity = xi / dt_ref;
  out.velocity_cov = Jinv * cov_xi * Jinv.transpose() / (dt_ref * dt_ref);
  out.inliers.assign(best_.begin(), best_.end());
  out.ok = true;
  return true;
}

}  // namespace spinradar
