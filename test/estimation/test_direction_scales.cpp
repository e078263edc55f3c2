// DirectionScales (issue 19) against known truth: synthetic matches whose residuals have a
// known radial and tangential standard deviation, solved by weighted least squares with a
// covariance S that does not know them; the sandwich covariance built from the per-direction
// scales must recover the spread of the estimates (Monte Carlo), where one chi2/dof factor
// for both directions cannot.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Dense>

#include "spinradar/estimation/direction_scales.hpp"
#include "spinradar/estimation/mc_ransac.hpp"

using namespace spinradar;

namespace {

struct Point {
  Eigen::Vector2d p, u;  ///< position, radial direction (unit)
};

/// Residual of point i under noise: radial sd sr, tangential sd st (m).
Eigen::Vector2d noise(const Point& pt, double sr, double st, std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  const Eigen::Vector2d t(-pt.u.y(), pt.u.x());
  return sr * n(rng) * pt.u + st * n(rng) * t;
}

struct Outcome {
  Eigen::MatrixXd mc;        ///< Monte Carlo covariance of the estimates
  Eigen::MatrixXd sandwich;  ///< mean of the per-direction sandwich covariances
  Eigen::MatrixXd one;       ///< mean of the one-factor (chi2/dof) covariances
  double k_r = 0.0, k_t = 0.0;
};

/// Linear problem e = y - J x (J per point: translation, or translation and small rotation),
/// weights S^-1 with S = cartesianCovariance(p, range_sigma, azimuth_sigma); true residuals
/// radial sd true_r, tangential sd true_t (times |p| azimuth_sigma when relative).
template <int N>
Outcome simulate(const std::vector<Point>& pts, double range_sigma, double azimuth_sigma,
                 double k_r_true, double k_t_true, int trials) {
  using MatN = Eigen::Matrix<double, N, N>;
  using VecN = Eigen::Matrix<double, N, 1>;
  std::mt19937 rng(7);
  std::vector<VecN> est;
  MatN sandwich = MatN::Zero(), one = MatN::Zero();
  double k_r = 0.0, k_t = 0.0;
  DirectionScales<N> dirs;
  dirs.reserve(pts.size());
  for (int trial = 0; trial < trials; ++trial) {
    MatN A = MatN::Zero();
    VecN b = VecN::Zero();
    std::vector<Eigen::Vector2d> y(pts.size());
    auto jac = [](const Point& pt) {
      Eigen::Matrix<double, 2, N> J;
      J.template leftCols<2>().setIdentity();
      if (N == 3) J.col(N - 1) = Eigen::Vector2d(-pt.p.y(), pt.p.x());  // small rotation
      return J;
    };
    for (size_t i = 0; i < pts.size(); ++i) {
      const double sr = range_sigma * std::sqrt(k_r_true);
      const double st = pts[i].p.norm() * azimuth_sigma * std::sqrt(k_t_true);
      y[i] = noise(pts[i], sr, st, rng);  // truth x = 0
      const Eigen::Matrix2d Si = cartesianCovariance(pts[i].p, range_sigma, azimuth_sigma).inverse();
      const Eigen::Matrix<double, 2, N> J = jac(pts[i]);
      A += J.transpose() * Si * J;
      b += J.transpose() * Si * y[i];
    }
    const VecN x = A.ldlt().solve(b);
    est.push_back(x);
    dirs.clear();
    double chi2 = 0.0;
    for (size_t i = 0; i < pts.size(); ++i) {
      const Eigen::Matrix2d S = cartesianCovariance(pts[i].p, range_sigma, azimuth_sigma);
      const Eigen::Matrix<double, 2, N> J = jac(pts[i]);
      const Eigen::Vector2d e = y[i] - J * x;
      const Eigen::Matrix<double, N, 2> JtW = J.transpose() * S.inverse();
      dirs.add(e, S, pts[i].u, JtW);
      chi2 += e.dot(S.inverse() * e);
    }
    dirs.estimate(N, 1e-3);
    const MatN Ai = A.inverse();
    sandwich += Ai * dirs.meat() * Ai;
    one += Ai * (chi2 / (2.0 * pts.size() - N));
    k_r += dirs.radialScale();
    k_t += dirs.tangentialScale();
  }
  Outcome o;
  MatN mc = MatN::Zero();
  for (const VecN& x : est) mc += x * x.transpose();
  o.mc = mc / trials;
  o.sandwich = sandwich / trials;
  o.one = one / trials;
  o.k_r = k_r / trials;
  o.k_t = k_t / trials;
  return o;
}

}  // namespace

// Translation from points along the x axis (ahead and behind): x is measured by the radial
// residuals alone, y by the tangential ones. Radial sd twice the tangential one (the weights
// assume them equal): the covariance's xx / yy ratio must come out 4.
TEST(DirectionScales, RecoversRadialToTangentialRatio) {
  std::vector<Point> pts;
  for (int i = 0; i < 200; ++i) {
    const double r = 60.0, s = i % 2 ? 1.0 : -1.0;  // at 60 m the assumed S is isotropic
    pts.push_back({Eigen::Vector2d(s * r, 0.0), Eigen::Vector2d(s, 0.0)});
  }
  // range_sigma 0.1 m; azimuth_sigma 0.1 m / 60 m: the assumed S is 0.1^2 I. True radial sd
  // 0.1 m, tangential 0.05 m (k_t 1/4).
  const Outcome o = simulate<2>(pts, 0.1, 0.1 / 60.0, 1.0, 0.25, 2000);
  EXPECT_NEAR(o.k_r, 1.0, 0.08);
  EXPECT_NEAR(o.k_t, 0.25, 0.02);
  const double ratio = o.sandwich(0, 0) / o.sandwich(1, 1);
  const double ratio_mc = o.mc(0, 0) / o.mc(1, 1);
  EXPECT_NEAR(ratio_mc, 4.0, 0.5);  // the truth the test is built on
  EXPECT_NEAR(ratio, ratio_mc, 0.12 * ratio_mc);
  EXPECT_NEAR(o.sandwich(0, 0), o.mc(0, 0), 0.1 * o.mc(0, 0));
  EXPECT_NEAR(o.sandwich(1, 1), o.mc(1, 1), 0.1 * o.mc(1, 1));
  // One factor for both directions cannot: xx / yy stays at the weights' own ratio (~1).
  EXPECT_LT(o.one(0, 0) / o.one(1, 1), 1.5);
}

// Pose (x, y, small yaw) from points all around the sensor, like a scan: half the azimuth
// error the weights assume (azimuth peaks against row keypoints), the configured radial one.
// The yaw rests on the tangential residuals: one chi2/dof factor ((1 + 1/4) / 2) leaves its
// variance 2.5x too large; the per-direction sandwich matches the Monte Carlo spread.
TEST(DirectionScales, YawFromTangentialScale) {
  std::vector<Point> pts;
  for (int i = 0; i < 300; ++i) {
    const double a = 2.0 * M_PI * i / 300.0, r = 15.0 + 0.3 * (i % 200);
    const Eigen::Vector2d u(std::cos(a), -std::sin(a));
    pts.push_back({r * u, u});
  }
  const Outcome o = simulate<3>(pts, 0.0438, 0.0045, 1.0, 0.25, 2000);
  EXPECT_NEAR(o.k_r, 1.0, 0.08);
  EXPECT_NEAR(o.k_t, 0.25, 0.02);
  EXPECT_NEAR(o.sandwich(2, 2), o.mc(2, 2), 0.1 * o.mc(2, 2));
  EXPECT_NEAR(o.sandwich(0, 0), o.mc(0, 0), 0.1 * o.mc(0, 0));
  EXPECT_NEAR(o.sandwich(1, 1), o.mc(1, 1), 0.1 * o.mc(1, 1));
  EXPECT_GT(o.one(2, 2), 2.0 * o.mc(2, 2));  // the one-factor covariance: cautious in yaw
}

// Equal scales reduce to the one-factor covariance k A^-1 (the old behaviour).
TEST(DirectionScales, EqualScalesGiveOneFactor) {
  std::vector<Point> pts;
  for (int i = 0; i < 100; ++i) {
    const double a = 0.3 * i, r = 10.0 + i;
    const Eigen::Vector2d u(std::cos(a), -std::sin(a));
    pts.push_back({r * u, u});
  }
  DirectionScales<3> d;
  d.clear();
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  for (const Point& pt : pts) {
    const Eigen::Matrix2d S = cartesianCovariance(pt.p, 0.05, 0.003);
    Eigen::Matrix<double, 2, 3> J;
    J << 1, 0, -pt.p.y(), 0, 1, pt.p.x();
    const Eigen::Matrix<double, 3, 2> JtW = J.transpose() * S.inverse();
    A += JtW * J;
    // Residual 1.5 sd along both directions (same normalised size): k_r = k_t.
    const Eigen::Vector2d t(-pt.u.y(), pt.u.x());
    const Eigen::Vector2d e =
        1.5 * std::sqrt(pt.u.dot(S * pt.u)) * pt.u - 1.5 * std::sqrt(t.dot(S * t)) * t;
    d.add(e, S, pt.u, JtW);
  }
  d.estimate(0, 1e-3);
  EXPECT_NEAR(d.radialScale(), d.tangentialScale(), 1e-9);
  const Eigen::Matrix3d diff = d.meat() - d.radialScale() * A;
  EXPECT_LT(diff.norm(), 1e-9 * A.norm());
}
