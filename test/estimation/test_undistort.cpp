// Undistortion: a straight wall seen while turning is bent by the motion during the sweep;
// moving every point to the scan's reference time makes it straight again.
#include <gtest/gtest.h>

#include <iostream>

#include <Eigen/LU>

#include "support/synthetic_scene.hpp"
#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/mc_ransac.hpp"
#include "spinradar/estimation/undistort.hpp"

using namespace spinradar;
using spinradar::testing::SceneOptions;
using spinradar::testing::SyntheticScene;

namespace {

/// RMS distance of points to their total-least-squares line.
double lineRms(const std::vector<Eigen::Vector2d>& pts) {
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (const auto& p : pts) c += p / pts.size();
  Eigen::Matrix2d S = Eigen::Matrix2d::Zero();
  for (const auto& p : pts) S += (p - c) * (p - c).transpose() / pts.size();
  // Smallest eigenvalue of the 2x2 scatter matrix.
  const double tr = S.trace(), det = S.determinant();
  return std::sqrt(std::max(0.0, 0.5 * (tr - std::sqrt(std::max(0.0, tr * tr - 4 * det)))));
}

}  // namespace

TEST(Undistort, StraightWallWhileTurningBecomesStraight) {
  const Eigen::Vector3d truth(10.0, 0.0, 20.0 * M_PI / 180.0);
  SceneOptions o;
  o.landmarks = 600;  // random landmarks for the velocity estimate
  SyntheticScene scene(o, {truth});
  // A wall x = 30 m, y in [-60, 60] m, in the sensor frame at the start of scan 1; it lies
  // ahead and to both sides, so it is swept over a wide span of the rotation (azimuths
  // 297 deg .. 63 deg across the wrap: early and late rows of the scan).
  const Eigen::Matrix3d T_w1 = scene.pose(scene.scanStart(1));
  const size_t first_wall = scene.landmarks().size();
  for (int i = 0; i <= 240; ++i) {
    const Eigen::Vector2d q(30.0, -60.0 + 0.5 * i);
    scene.landmarks().push_back(T_w1.topLeftCorner<2, 2>() * q + T_w1.topRightCorner<2, 1>());
  }
  std::vector<int> ids0, ids1;
  const FeatureFrame f0 = scene.observe(0, &ids0);
  const FeatureFrame f1 = scene.observe(1, &ids1);

  std::vector<Keypoint> wall;
  for (size_t i = 0; i < f1.keypoints.size(); ++i)
    if (ids1[i] >= static_cast<int>(first_wall)) wall.push_back(f1.keypoints[i]);
  ASSERT_GT(wall.size(), 200u);
  std::vector<Eigen::Vector2d> raw;
  for (const auto& k : wall) raw.emplace_back(k.x, k.y);

  // With the true velocity: exactly back on x = 30.
  std::vector<Eigen::Vector2d> fixed;
  undistortPoints(wall, truth, f1.stamp_ns, fixed);
  double worst_raw = 0.0, worst_fixed = 0.0;
  for (size_t i = 0; i < wall.size(); ++i) {
    worst_raw = std::max(worst_raw, std::abs(raw[i].x() - 30.0));
    worst_fixed = std::max(worst_fixed, std::abs(fixed[i].x() - 30.0));
  }
  EXPECT_GT(worst_raw, 1.0);
  EXPECT_LT(worst_fixed, 1e-6);

  // With the MC-RANSAC velocity estimated from scans 0 and 1: straight to a few cm.
  McRansac mc;
  MotionEstimate est;
  ASSERT_TRUE(mc.estimate(f0.keypoints, f1.keypoints, scene.matches(ids0, ids1, 0.3),
                          f0.stamp_ns, f1.stamp_ns, est));
  std::vector<Eigen::Vector2d> est_fixed;
  undistortPoints(wall, est.velocity, f1.stamp_ns, est_fixed);
  const double rms_raw = lineRms(raw), rms_est = lineRms(est_fixed);
  std::cout << "[ info ] wall line RMS: raw " << rms_raw << " m, undistorted " << rms_est
            << " m (worst |x - 30|: raw " << worst_raw << " m)\n";
  EXPECT_GT(rms_raw, 0.3);
  EXPECT_LT(rms_est, 0.01);

  // In-place keypoint form agrees and keeps polar fields consistent (clockwise azimuth).
  std::vector<Keypoint> moved = wall;
  undistortKeypoints(moved, truth, f1.stamp_ns);
  for (size_t i = 0; i < moved.size(); ++i) {
    EXPECT_NEAR(moved[i].x, fixed[i].x(), 1e-9);
    EXPECT_NEAR(moved[i].range * std::cos(moved[i].azimuth), moved[i].x, 1e-9);
    EXPECT_NEAR(-moved[i].range * std::sin(moved[i].azimuth), moved[i].y, 1e-9);
  }
}

TEST(Undistort, ZeroVelocityOrReferenceTimeIsIdentity) {
  std::vector<Keypoint> k(3);
  for (int i = 0; i < 3; ++i) {
    k[i].x = 5.0 + i;
    k[i].y = -2.0 * i;
    k[i].stamp_ns = 1000 + 1'000'000 * i;
  }
  std::vector<Eigen::Vector2d> out;
  undistortPoints(k, Eigen::Vector3d::Zero(), 0, out);
  for (int i = 0; i < 3; ++i) EXPECT_LT((out[i] - Eigen::Vector2d(k[i].x, k[i].y)).norm(), 1e-15);
  undistortPoints(k, Eigen::Vector3d(10, 0, 1), k[1].stamp_ns, out);
  EXPECT_LT((out[1] - Eigen::Vector2d(k[1].x, k[1].y)).norm(), 1e-15);
  // A point seen 0.1 s after the reference while driving 10 m/s forward lies 1 m further
  // ahead in the reference frame.
  k[0].stamp_ns = 100'000'000;
  undistortPoints(k, Eigen::Vector3d(10, 0, 0), 0, out);
  EXPECT_NEAR(out[0].x(), k[0].x + 1.0, 1e-12);
}
