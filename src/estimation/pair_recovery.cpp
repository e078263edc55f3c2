#include "spinradar/estimation/pair_recovery.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "spinradar/core/lie.hpp"
#include "spinradar/core/normal_equations.hpp"
#include "spinradar/estimation/mc_ransac.hpp"

namespace spinradar {

namespace {

/// Linear velocity prior (m/s) around the guess: over one scan pair the speed changes by
/// about acceleration x period (3 m/s^2 x 0.25 s); it only matters along degenerate streets.
constexpr double kSpeedPriorSigma = 1.0;

/// Keypoint k Doppler-corrected with velocity xi and moved by s seconds of it:
/// y = exp(s xi) (p + beta (u . v) u). J (optional) receives dy/dxi: the left Jacobian of
/// exp(s xi) (exp(s (xi + d)) ~ exp(s J_l(s xi) d) exp(s xi)) plus the Doppler term.
Eigen::Vector2d movePoint(const PairRecovery::Point& k, double s, const Eigen::Vector3d& xi,
                          double beta, Eigen::Matrix<double, 2, 3>* J = nullptr) {
  const double ux = k.ux, uy = k.uy;
  const double d = beta * (ux * xi(0) + uy * xi(1));
  const Eigen::Vector3d sx = s * xi;
  const Eigen::Matrix3d E = se2::exp(sx);
  const Eigen::Matrix2d R = E.topLeftCorner<2, 2>();
  const Eigen::Vector2d y = R * Eigen::Vector2d(k.x + d * ux, k.y + d * uy) + E.topRightCorner<2, 1>();
  if (J) {
    *J = s * se2::odot2(y) * se2::leftJacobian(sx);
    Eigen::Matrix<double, 2, 3> D;
    D << beta * ux * ux, beta * ux * uy, 0.0, beta * uy * ux, beta * uy * uy, 0.0;
    J->noalias() += R * D;
  }
  return y;
}

void toPoints(const FeatureFrame& f, std::vector<PairRecovery::Point>& out) {
  out.resize(f.keypoints.size());
  for (size_t i = 0; i < out.size(); ++i) {
    const Keypoint& k = f.keypoints[i];
    out[i] = {k.x, k.y, std::cos(k.azimuth), -std::sin(k.azimuth),
              1e-9 * static_cast<double>(k.stamp_ns - f.stamp_ns)};
  }
}

}  // namespace

void DenseGrid::build(const std::vector<Eigen::Vector2d>& pts, double cell) {
  pts_ = &pts;
  nx_ = ny_ = 0;
  if (pts.empty()) return;
  double x1 = pts[0].x(), y1 = pts[0].y();
  x0_ = x1;
  y0_ = y1;
  for (const Eigen::Vector2d& p : pts) {
    x0_ = std::min(x0_, p.x()); x1 = std::max(x1, p.x());
    y0_ = std::min(y0_, p.y()); y1 = std::max(y1, p.y());
  }
  // Cells no smaller than `cell` (lookups visit 3x3), at most 1024 a side.
  const double c = std::max({cell, (x1 - x0_) / 1024.0, (y1 - y0_) / 1024.0});
  inv_cell_ = 1.0 / c;
  nx_ = static_cast<int>((x1 - x0_) * inv_cell_) + 1;
  ny_ = static_cast<int>((y1 - y0_) * inv_cell_) + 1;
  start_.assign(static_cast<size_t>(nx_) * ny_ + 1, 0);
  auto cellOf = [&](const Eigen::Vector2d& p) {
    const int cx = std::min(nx_ - 1, static_cast<int>((p.x() - x0_) * inv_cell_));
    const int cy = std::min(ny_ - 1, static_cast<int>((p.y() - y0_) * inv_cell_));
    return cy * nx_ + cx;
  };
  for (const Eigen::Vector2d& p : pts) ++start_[cellOf(p) + 1];
  for (size_t i = 1; i < start_.size(); ++i) start_[i] += start_[i - 1];
  order_.resize(pts.size());
  // Fill by walking a cursor copy of the starts (start_ shifted one to the left afterwards).
  for (size_t i = 0; i < pts.size(); ++i) order_[start_[cellOf(pts[i])]++] = static_cast<int>(i);
  for (size_t i = start_.size() - 1; i > 0; --i) start_[i] = start_[i - 1];
  start_[0] = 0;
}

int DenseGrid::nearest(const Eigen::Vector2d& q, double radius) const {
  if (nx_ == 0) return -1;
  const double fx = (q.x() - x0_) * inv_cell_, fy = (q.y() - y0_) * inv_cell_;
  if (fx < -1.0 || fy < -1.0 || fx > nx_ + 1.0 || fy > ny_ + 1.0) return -1;
  const int cx = static_cast<int>(std::floor(fx)), cy = static_cast<int>(std::floor(fy));
  double best = radius * radius;
  int best_i = -1;
  for (int y = std::max(0, cy - 1); y <= std::min(ny_ - 1, cy + 1); ++y)
    for (int x = std::max(0, cx - 1); x <= std::min(nx_ - 1, cx + 1); ++x) {
      const int c = y * nx_ + x;
      for (int k = start_[c]; k < start_[c + 1]; ++k) {
        const double d2 = ((*pts_)[order_[k]] - q).squaredNorm();
        if (d2 < best) {
          best = d2;
          best_i = order_[k];
        }
      }
    }
  return best_i;
}

void PairRecovery::buildMap(const Eigen::Vector3d& xi, int stride) {
  map_.clear();
  map_idx_.clear();
  for (size_t i = 0; i < p1_.size(); i += static_cast<size_t>(stride)) {
    map_.push_back(movePoint(p1_[i], p1_[i].t, xi, config_.beta));
    map_idx_.push_back(static_cast<int>(i));
  }
  index_.build(map_, kSearchGate);
}

int PairRecovery::score(const Eigen::Vector3d& xi1, const Eigen::Vector3d& xi2, double dt,
                        int stride) const {
  const Eigen::Matrix3d T = se2::exp(dt * xi1);
  int n = 0;
  for (size_t i = 0; i < p2_.size(); i += static_cast<size_t>(stride)) {
    const Eigen::Vector2d p = movePoint(p2_[i], p2_[i].t, xi2, config_.beta);
    n += index_.nearest(T.topLeftCorner<2, 2>() * p + T.topRightCorner<2, 1>(), kSearchGate) >= 0 ? 1 : 0;
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
  toPoints(f1, p1_);
  toPoints(f2, p2_);

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
    if (!both) buildMap(xi_guess, map_stride);
    for (int s = -steps; s <= steps; ++s) {
      Eigen::Vector3d xi = centre;
      xi(2) += s * step / dt;
      if (both) buildMap(xi, map_stride);
      const Eigen::Vector3d& xi1 = both ? xi : xi_guess;
      const int n = score(xi1, xi, dt, stride);
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
  //    inlier_threshold.
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  const double sr = config_.range_sigma, sa = config_.azimuth_sigma, beta = config_.beta;
  const double w_speed = 1.0 / (kSpeedPriorSigma * kSpeedPriorSigma);
  Vec6 x;
  x << best1, best2;
  Mat6 A = Mat6::Zero();
  double chi2 = 0.0;
  int n_in = 0;
  for (int it = 0; it < kIterations; ++it) {
    const double gate = std::max(config_.inlier_threshold,
                                 kSearchGate * std::pow(0.5, static_cast<double>(it)));
    buildMap(x.head<3>(), 1);
    A.setZero();
    Vec6 b = Vec6::Zero();
    for (int c : {0, 1, 3, 4}) {
      A(c, c) += w_speed;
      b(c) -= w_speed * (x(c) - xi_guess(c % 3));
    }
    chi2 = 0.0;
    n_in = 0;
    const Eigen::Vector3d xi1 = x.head<3>(), xi2 = x.tail<3>();
    const Eigen::Matrix3d T = se2::exp(dt * xi1);
    const Eigen::Matrix2d RT = T.topLeftCorner<2, 2>();
    const Eigen::Matrix3d Jl = se2::leftJacobian(dt * xi1);
    Eigen::Matrix<double, 2, 3> Jg, Jm;
    for (const Point& k : p2_) {
      // q = T_12 g, g = scan 2's point moved with xi2; e = m - q, m = scan 1's point.
      const Eigen::Vector2d g = movePoint(k, k.t, xi2, beta, &Jg);
      const Eigen::Vector2d q = RT * g + T.topRightCorner<2, 1>();
      const int j = index_.nearest(q, gate);
      if (j < 0) continue;
      const Point& kj = p1_[map_idx_[j]];
      movePoint(kj, kj.t, xi1, beta, &Jm);
      const Eigen::Vector2d e = map_[j] - q;
      Eigen::Matrix<double, 2, 6> J;
      J.leftCols<3>() = Jm - dt * se2::odot2(q) * Jl;
      J.rightCols<3>() = -RT * Jg;
      const Eigen::Matrix2d Si =
          (cartesianCovariance(map_[j], sr, sa, kTangentialFloor) +
           cartesianCovariance(q, sr, sa, kTangentialFloor)).inverse();
      const Eigen::Matrix<double, 6, 2> JtW = J.transpose() * Si;
      A.noalias() += JtW * J;
      b.noalias() -= JtW * e;
      chi2 += e.dot(Si * e);
      ++n_in;
    }
    if (n_in < kMinInliers) return false;
    Vec6 dx;
    if (!solveNormalEquations(A, b, dx)) return false;
    x += dx;
    if (gate <= config_.inlier_threshold && dx.segment<2>(0).norm() + dx.segment<2>(3).norm() < 1e-3 &&
        std::abs(dx(2)) + std::abs(dx(5)) < 1e-5)
      break;
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
