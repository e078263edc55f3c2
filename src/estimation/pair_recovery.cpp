#include "spinradar/estimation/pair_recovery.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/mc_ransac.hpp"

namespace spinradar {

namespace {

/// Linear velocity prior (m/s) around the guess: over one scan pair the speed changes by
/// about acceleration x period (3 m/s^2 x 0.25 s); it only matters along degenerate streets.
constexpr double kSpeedPriorSigma = 1.0;

/// f2's keypoint k with velocity xi in f1's scan-start frame: Doppler-corrected, moved by its
/// own time after f2's start and the pair interval dt (constant velocity).
Eigen::Vector2d predictPoint(const Keypoint& k, int64_t stamp2, const Eigen::Vector3d& xi,
                             double dt, double beta) {
  const double ux = std::cos(k.azimuth), uy = -std::sin(k.azimuth);
  const double d = beta * (ux * xi(0) + uy * xi(1));
  const double s = dt + 1e-9 * static_cast<double>(k.stamp_ns - stamp2);
  const Eigen::Matrix3d E = se2::exp(s * xi);
  return E.topLeftCorner<2, 2>() * Eigen::Vector2d(k.x + d * ux, k.y + d * uy) +
         E.topRightCorner<2, 1>();
}

}  // namespace

void PairRecovery::buildMap(const FeatureFrame& f1, const Eigen::Vector3d& xi, int stride) {
  map_.clear();
  map_idx_.clear();
  for (size_t i = 0; i < f1.keypoints.size(); i += static_cast<size_t>(stride)) {
    map_.push_back(predictPoint(f1.keypoints[i], f1.stamp_ns, xi, 0.0, config_.beta));
    map_idx_.push_back(static_cast<int>(i));
  }
  index_.build(map_.data(), static_cast<int>(map_.size()), kSearchGate);
}

int PairRecovery::score(const FeatureFrame& f2, const Eigen::Vector3d& xi1,
                        const Eigen::Vector3d& xi2, double dt, int stride) const {
  const Eigen::Matrix3d T = se2::exp(dt * xi1);
  int n = 0;
  for (size_t i = 0; i < f2.keypoints.size(); i += static_cast<size_t>(stride)) {
    const Eigen::Vector2d p = predictPoint(f2.keypoints[i], f2.stamp_ns, xi2, 0.0, config_.beta);
    n += index_.nearest(T.topLeftCorner<2, 2>() * p + T.topRightCorner<2, 1>(), kSearchGate) >= 0;
  }
  return n;
}

bool PairRecovery::estimate(const FeatureFrame& f1, const FeatureFrame& f2,
                            const Eigen::Vector3d& xi_guess, MotionEstimate& out) {
  out.ok = false;
  inliers_ = 0;
  const double dt = 1e-9 * static_cast<double>(f2.stamp_ns - f1.stamp_ns);
  const size_t n1 = f1.keypoints.size(), n2 = f2.keypoints.size();
  if (!(dt > 0.0) || n1 < kMinInliers || n2 < kMinInliers) return false;

  // 1. Yaw-rate search around the guess (linear velocity kept), coarse steps, then fine
  //    around the best; both point sets strided to about kSearchPoints. Two families of
  //    candidates, each scan with its own velocity (xi1 moves scan 1's points and makes the
  //    step T_12 = exp(dt xi1), xi2 moves scan 2's): one velocity over the pair
  //    (MC-RANSAC's model: right inside a turn and at its entry, where the guess, scan 1's
  //    own estimate, is still the straight one), and the guess kept for scan 1 with scan 2's
  //    yaw rate searched (a turn's exit). The best count wins.
  const int stride = std::max<int>(1, static_cast<int>(n2) / kSearchPoints);
  const int map_stride = std::max<int>(1, static_cast<int>(n1) / (2 * kSearchPoints));
  const int scored = static_cast<int>((n2 + stride - 1) / stride);
  Eigen::Vector3d best1 = xi_guess, best2 = xi_guess;
  int best = -1;
  auto search = [&](bool both, const Eigen::Vector3d& centre, double step, int steps) {
    if (!both) buildMap(f1, xi_guess, map_stride);
    for (int s = -steps; s <= steps; ++s) {
      Eigen::Vector3d xi = centre;
      xi(2) += s * step / dt;
      if (both) buildMap(f1, xi, map_stride);
      const Eigen::Vector3d& xi1 = both ? xi : xi_guess;
      const int n = score(f2, xi1, xi, dt, stride);
      if (n > best) {
        best = n;
        best1 = xi1;
        best2 = xi;
      }
    }
  };
  const int coarse = static_cast<int>(std::lround(kMaxYaw / kYawStep));
  search(true, xi_guess, kYawStep, coarse);
  const int best_both = best;
  search(false, xi_guess, kYawStep, coarse);
  search(best > best_both ? false : true, best2, 0.25 * kYawStep, 3);
  if (best * stride < kMinInliers || best < kMinFraction * scored) return false;

  // 2. Gauss-Newton with a velocity of its own for each scan, x = [xi1, xi2]: the pose step
  //    is scan 1's motion, T_12 = exp(dt xi1), scan 1's points are moved with xi1 and scan
  //    2's with xi2. One velocity over the pair (MC-RANSAC's model) is wrong for the pair
  //    holding a turn's entry or exit, which is where descriptors fail; Gauss-Newton
  //    separates the two yaw rates (each is observable from the rotation of its scan's
  //    points over the sweep). Nearest map
  //    point re-associated every iteration, gate from the search's down to
  //    inlier_threshold. Numeric Jacobian: each point's time scales its motion, so the exact
  //    one is long, and this runs only on failed pairs.
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  const double sr = config_.range_sigma, sa = config_.azimuth_sigma, beta = config_.beta;
  const double w_speed = 1.0 / (kSpeedPriorSigma * kSpeedPriorSigma);
  Vec6 x;
  x << best1, best2;
  Mat6 A = Mat6::Zero();
  double chi2 = 0.0;
  int n_in = 0;
  const std::vector<Keypoint>& kps = f2.keypoints;
  auto mapPoint = [&](const Keypoint& k, const Vec6& v) {
    return predictPoint(k, f1.stamp_ns, v.head<3>(), 0.0, beta);
  };
  auto scanPoint = [&](const Keypoint& k, const Vec6& v) {
    const Eigen::Vector2d p = predictPoint(k, f2.stamp_ns, v.tail<3>(), 0.0, beta);
    const Eigen::Matrix3d T = se2::exp(dt * v.head<3>());
    return Eigen::Vector2d(T.topLeftCorner<2, 2>() * p + T.topRightCorner<2, 1>());
  };
  for (int it = 0; it < kIterations; ++it) {
    const double gate = std::max(config_.inlier_threshold,
                                 kSearchGate * std::pow(0.5, static_cast<double>(it)));
    buildMap(f1, x.head<3>(), 1);
    A.setZero();
    Vec6 b = Vec6::Zero();
    for (int c : {0, 1, 3, 4}) {
      A(c, c) += w_speed;
      b(c) -= w_speed * (x(c) - xi_guess(c % 3));
    }
    chi2 = 0.0;
    n_in = 0;
    for (const Keypoint& k : kps) {
      const Eigen::Vector2d q = scanPoint(k, x);
      const int j = index_.nearest(q, gate);
      if (j < 0) continue;
      const Keypoint& kj = f1.keypoints[map_idx_[j]];
      const Eigen::Vector2d e = map_[j] - q;
      Eigen::Matrix<double, 2, 6> J;
      for (int c = 0; c < 6; ++c) {
        const double h = c % 3 < 2 ? 1e-4 : 1e-6;
        Vec6 xh = x;
        xh(c) += h;
        J.col(c) = (mapPoint(kj, xh) - map_[j] - (scanPoint(k, xh) - q)) / h;
      }
      const Eigen::Matrix2d Si =
          (cartesianCovariance(map_[j], sr, sa) + cartesianCovariance(q, sr, sa)).inverse();
      const Eigen::Matrix<double, 6, 2> JtW = J.transpose() * Si;
      A.noalias() += JtW * J;
      b.noalias() -= JtW * e;
      chi2 += e.dot(Si * e);
      ++n_in;
    }
    if (n_in < kMinInliers) return false;
    Eigen::LDLT<Mat6> ldlt(A);
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) return false;
    const Vec6 dx = ldlt.solve(b);
    if (!dx.allFinite()) return false;
    x += dx;
    if (gate <= config_.inlier_threshold && dx.cwiseAbs().maxCoeff() < 1e-6) break;
  }
  const double dof = std::max(1.0, 2.0 * n_in - 6.0);
  const Mat6 cov = A.inverse() * std::max(1.0, chi2 / dof);
  if (!cov.allFinite() || !x.allFinite()) return false;
  inliers_ = n_in;
  // The step is scan 1's motion; the velocity published (and the next pair's guess) is
  // scan 2's.
  setMotionFromVelocity(x.head<3>(), cov.topLeftCorner<3, 3>(), dt, out);
  out.velocity = x.tail<3>();
  out.velocity_cov = cov.bottomRightCorner<3, 3>();
  out.matches = n_in;
  out.inliers.clear();
  out.ok = true;
  return true;
}

}  // namespace spinradar
