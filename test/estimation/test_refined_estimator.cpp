// The refined estimator on the cases that break frame-to-frame matching (issue 9):
// standing still, moving objects, and its covariance.
#include <gtest/gtest.h>

#include <iostream>

#include <Eigen/Cholesky>

#include "support/synthetic_scene.hpp"
#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/odometry.hpp"
#include "spinradar/estimation/keyframe_tracker.hpp"
#include "spinradar/estimation/refined_estimator.hpp"

using namespace spinradar;
using spinradar::testing::SceneOptions;
using spinradar::testing::SyntheticScene;

namespace {
constexpr double kDeg = M_PI / 180.0;

SceneOptions noisyScene(uint32_t seed) {
  SceneOptions o;
  o.landmarks = 1000;
  o.range_sigma = 0.0438;
  o.azimuth_sigma = 0.002;
  o.beta = 0.049;
  o.seed = seed;
  return o;
}
}  // namespace

TEST(RefinedEstimator, NoDriftWhileStandingStill) {
  SyntheticScene scene(noisyScene(3), {Eigen::Vector3d::Zero()});
  PipelineConfig cr, cm;
  cr.estimator.estimator = "refined";
  cm.estimator.estimator = "mc_doppler";
  Odometry refined(cr), mc(cm);
  OdometryResult rr, rm;
  for (int k = 0; k < 20; ++k) {
    const FeatureFrame f = scene.observe(k);
    rr = refined.process(f);
    rm = mc.process(f);
  }
  ASSERT_TRUE(rr.ok);
  const double drift_r = rr.T_world_sensor.topRightCorner<2, 1>().norm();
  const double drift_m = rm.T_world_sensor.topRightCorner<2, 1>().norm();
  std::cout << "[ info ] 5 s standing still: refined drift " << drift_r << " m, mc_doppler "
            << drift_m << " m\n";
  EXPECT_LT(drift_r, 1e-9);
  EXPECT_EQ(rr.motion.velocity.norm(), 0.0);
}

TEST(RefinedEstimator, MovingObjectsDoNotPullTheEstimate) {
  // 20 % of the landmarks belong to "cars" that move 3 m per scan sideways between the two
  // observations: consistent but wrong matches.
  const Eigen::Vector3d truth(12.0, 0.0, 10.0 * kDeg);
  SyntheticScene scene(noisyScene(4), {truth});
  std::vector<int> ids1, ids2;
  const FeatureFrame f1 = scene.observe(0, &ids1);
  for (size_t i = 0; i < scene.landmarks().size(); i += 5) scene.landmarks()[i].y() += 3.0;
  const FeatureFrame f2 = scene.observe(1, &ids2);
  const std::vector<Match> m = scene.matches(ids1, ids2, 0.1);
  RefinedEstimator est;
  MotionEstimate out;
  std::vector<Keypoint> c1, c2;
  ASSERT_TRUE(est.estimate(f1, f2, m, c1, c2, out));
  std::cout << "[ info ] moving objects: velocity error " << (out.velocity - truth).transpose() << "\n";
  EXPECT_LT((out.velocity - truth).head<2>().norm(), 0.1);
  EXPECT_LT(std::abs(out.velocity(2) - truth(2)), 0.1 * kDeg);
  int moving_in = 0;
  for (int i : out.inliers) moving_in += ids1[m[i].i1] % 5 == 0;
  EXPECT_LT(moving_in, 3);
}

TEST(RefinedEstimator, CovarianceIsHonest) {
  const Eigen::Vector3d truth(10.0, 0.0, 20.0 * kDeg);
  EstimatorConfig cfg;
  double nees = 0.0;
  const int n = 20;
  for (uint32_t seed = 1; seed <= n; ++seed) {
    SceneOptions o = noisyScene(600 + seed);
    o.azimuth_sigma = cfg.azimuth_sigma;
    SyntheticScene scene(o, {truth});
    std::vector<int> ids1, ids2;
    const FeatureFrame f1 = scene.observe(0, &ids1), f2 = scene.observe(1, &ids2);
    RefinedEstimator est(cfg);
    MotionEstimate out;
    std::vector<Keypoint> c1, c2;
    ASSERT_TRUE(est.estimate(f1, f2, scene.matches(ids1, ids2, 0.3), c1, c2, out));
    const Eigen::Vector3d e = out.velocity - truth;
    nees += e.dot(out.velocity_cov.ldlt().solve(e)) / n;
  }
  std::cout << "[ info ] refined mean NEES over " << n << " pairs: " << nees << " (expected 3)\n";
  EXPECT_GT(nees, 1.0);
  EXPECT_LT(nees, 6.0);
}

TEST(RefinedEstimator, PublishedStepCovarianceIsHonestOnAVaryingDrive) {
  // Through Odometry: speed 8-12 m/s and yaw rate swinging +-15 deg/s, changing every scan
  // (the constant-velocity pair model leaves that out; the published step covariance adds
  // it). NEES of every step [x, y, yaw] from the previous scan against the truth.
  double sum = 0.0, sum_raw = 0.0, covered = 0.0;
  int samples = 0;
  for (uint32_t seed = 1; seed <= 6; ++seed) {
    std::vector<Eigen::Vector3d> v;
    for (int k = 0; k < 17; ++k) {
      const double t = std::max(k, 1) + 3.0 * seed;
      v.emplace_back(10.0 + 2.0 * std::sin(0.2 * t), 0.0, 15.0 * kDeg * std::sin(0.15 * t));
    }
    SyntheticScene scene(noisyScene(700 + seed), v);
    PipelineConfig cfg;
    cfg.estimator.estimator = "refined";
    cfg.estimator.beta = scene.options().beta;
    Odometry odo(cfg);
    for (int k = 0; k < 16; ++k) {
      const OdometryResult res = odo.process(scene.observe(k));
      if (k == 0) continue;
      ASSERT_TRUE(res.ok) << k;
      // The step as compounded: T_world_sensor(k) = T_world_sensor(k-1) T_12.
      const Eigen::Matrix3d step_t = scene.relative(k - 1, k);
      Eigen::Vector3d e = se2::toXyYaw(res.motion.T_12) - se2::toXyYaw(step_t);
      e(2) = std::remainder(e(2), 2.0 * M_PI);
      const double n = e.dot(res.motion.T_12_cov.ldlt().solve(e));
      Eigen::Matrix3d raw = res.motion.T_12_cov;  // without the model term
      raw.diagonal() -= KeyframeTracker::stepModelNoise(scene.options().period);
      sum_raw += e.dot(raw.ldlt().solve(e));
      sum += n;
      covered += n < 7.815;
      ++samples;
    }
  }
  const double mean = sum / samples;
  std::cout << "[ info ] refined published step NEES over " << samples << " steps: mean " << mean
            << " (expected 3), 95 % bound covers " << 100.0 * covered / samples
            << " %; without the constant-velocity model term " << sum_raw / samples << "\n";
  // Cautious on this gentle drive (0.67; the term is sized on the city route, where it
  // gives 2.4) but no longer over-confident (26 without it).
  EXPECT_LT(mean, 4.0);
  EXPECT_GT(mean, 0.4);
  EXPECT_GT(covered / samples, 0.9);
}
