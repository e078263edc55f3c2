// The keyframe estimator (issue 9) against known truth on synthetic drives: drift against
// MC-RANSAC, a sharp turn at speed, standing still, moving cars, a street of repetitive
// facades (aliased matches along track) and the honesty of its pose covariance.
#include <gtest/gtest.h>

#include <functional>
#include <iostream>
#include <cmath>
#include <random>

#include <Eigen/Cholesky>

#include "support/synthetic_scene.hpp"
#include "support/view_dependent_descriptors.hpp"
#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/odometry.hpp"

using namespace spinradar;
using spinradar::testing::SceneOptions;
using spinradar::testing::SyntheticScene;

namespace {

constexpr double kDeg = M_PI / 180.0;

SceneOptions options(uint32_t seed = 42) { return spinradar::testing::clutteredDopplerScene(seed); }

struct Drive {
  double final_err = 0.0, worst_err = 0.0, final_yaw_err = 0.0, length = 0.0;
  double worst_along = 0.0;  ///< m, worst |along-track error| of a step
  double nees = 0.0;         ///< of the final pose, over [x, y, yaw]
  /// NEES of every scan's pose relative to its keyframe (keyframe estimator), over [x, y, yaw].
  std::vector<double> key_nees;
};

using Hook = std::function<void(SyntheticScene&, int k, FeatureFrame&, const std::vector<int>&)>;

Drive run(const std::string& estimator, SyntheticScene& scene, int scans, const Hook& hook = {}) {
  PipelineConfig cfg;
  cfg.estimator.estimator = estimator;
  cfg.estimator.beta = scene.options().beta;
  Odometry odo(cfg);
  Drive d;
  Eigen::Matrix3d prev_truth = Eigen::Matrix3d::Identity(), prev_est = prev_truth;
  for (int k = 0; k < scans; ++k) {
    std::vector<int> ids;
    FeatureFrame f = scene.observe(k, &ids);
    if (hook) hook(scene, k, f, ids);
    const OdometryResult res = odo.process(f);
    if (k == 0) continue;
    EXPECT_TRUE(res.ok) << estimator << " scan " << k;
    const Eigen::Matrix3d truth = scene.pose(scene.scanStart(k));
    const Eigen::Matrix3d& est = res.T_world_sensor;
    const Eigen::Vector2d e = est.topRightCorner<2, 1>() - truth.topRightCorner<2, 1>();
    d.final_err = e.norm();
    d.worst_err = std::max(d.worst_err, d.final_err);
    const double yaw_err = se2::log(se2::inverse(truth) * est)(2);
    d.final_yaw_err = std::abs(yaw_err);
    d.length += (truth.topRightCorner<2, 1>() - prev_truth.topRightCorner<2, 1>()).norm();
    const Eigen::Matrix3d step_t = se2::inverse(prev_truth) * truth;
    const Eigen::Matrix3d step_e = se2::inverse(prev_est) * est;
    d.worst_along = std::max(d.worst_along, std::abs(step_e(0, 2) - step_t(0, 2)));
    prev_truth = truth;
    prev_est = est;
    const Eigen::Vector3d ev(e.x(), e.y(), yaw_err);
    d.nees = ev.dot(res.pose_cov.ldlt().solve(ev));
    if (res.keyframe_stamp_ns != 0 && res.keyframe_stamp_ns != res.stamp_ns) {
      const double tk = 1e-9 * static_cast<double>(res.keyframe_stamp_ns - scene.options().t0_ns);
      const Eigen::Matrix3d rel_t = se2::inverse(scene.pose(tk)) * truth;
      const Eigen::Matrix3d& rel_e = res.T_keyframe_sensor;
      Eigen::Vector3d er = se2::toXyYaw(rel_e) - se2::toXyYaw(rel_t);
      er(2) = std::remainder(er(2), 2.0 * M_PI);
      d.key_nees.push_back(er.dot(res.keyframe_cov.ldlt().solve(er)));
    }
  }
  std::cout << "[ info ] " << estimator << ": " << d.length << " m, final error " << d.final_err
            << " m (" << 100.0 * d.final_err / d.length << " %), worst " << d.worst_err
            << " m, yaw " << d.final_yaw_err / kDeg << " deg, worst along-track step error "
            << d.worst_along << " m, NEES " << d.nees << "\n";
  return d;
}

/// Speed 8-12 m/s and yaw rate swinging +-15 deg/s, changing every scan after the first
/// two (the very first pair has no previous one to take out its half-scan lag: a start-up
/// error of ~0.26 deg there that every estimator keeps).
std::vector<Eigen::Vector3d> varyingProfile(int n, double phase = 0.0) {
  std::vector<Eigen::Vector3d> v;
  for (int k = 0; k < n + 1; ++k) {
    const double t = std::max(k, 1) + phase;
    v.emplace_back(10.0 + 2.0 * std::sin(0.2 * t), 0.0, 15.0 * kDeg * std::sin(0.15 * t));
  }
  return v;
}

}  // namespace

TEST(KeyframeTracker, DriftsLessThanMcOnAVaryingDrive) {
  const int n = 40;
  SyntheticScene s1(options(), varyingProfile(n)), s2(options(), varyingProfile(n));
  const Drive mc = run("mc_doppler", s1, n);
  const Drive kf = run("keyframe", s2, n);
  EXPECT_LT(kf.worst_err, 0.5 * mc.worst_err);
  EXPECT_LT(kf.final_err / kf.length, 0.005);
  EXPECT_LT(kf.final_yaw_err, 0.3 * kDeg);
}

TEST(KeyframeTracker, SharpTurnAtSpeed) {
  // 15 m/s; the yaw rate steps from 0 to 40 deg/s (90 deg in 2.25 s) and back, mid-scan
  // discontinuities that break the constant-velocity model of a scan pair.
  std::vector<Eigen::Vector3d> v;
  for (int k = 0; k < 30; ++k)
    v.emplace_back(15.0, 0.0, (k >= 8 && k < 17) ? 40.0 * kDeg : 0.0);
  SyntheticScene s1(options(7), v), s2(options(7), v);
  const Drive mc = run("mc_doppler", s1, 30);
  const Drive kf = run("keyframe", s2, 30);
  EXPECT_LT(kf.final_err / kf.length, 0.01);
  EXPECT_LT(kf.final_yaw_err, 0.5 * kDeg);
  EXPECT_LT(kf.final_err, mc.final_err);
}

TEST(KeyframeTracker, YawRateStepInsideAScanStaysOutOfTheChain) {
  // The city route's corners: 5 m/s, the yaw rate steps 0 -> 0.625 rad/s (R = 8 m) and back
  // 30 % into a scan (not at a scan start), a 90 deg turn. The velocity prior (the refined
  // pair) is wrong for the scans holding a step, and a yaw-rate error dw of a scan moves its
  // scan-start pose by about c dw. Solved at the scan start, that error went into the
  // keyframe chain and stayed: heading error after the turn 0.29 / 0.19 / 0.02 deg for the
  // three seeds (0.5-1.5 deg per corner on the city route). Solved at mid-scan (kMidScan),
  // only that scan's published pose carries it: 0.062 / 0.054 / 0.019 deg. (Inside the turn
  // the error is still up to 0.3-0.5 deg with both, against 0.43-0.57 deg before.)
  const double w = 0.625;
  for (const uint32_t seed : {11u, 12u, 13u}) {
    std::vector<Eigen::Vector3d> v;
    for (int k = 0; k < 34; ++k) v.emplace_back(5.0, 0.0, (k >= 10 && k < 20) ? w : 0.0);
    SceneOptions o = options(seed);
    o.velocity_shift = 0.3 * o.period;
    SyntheticScene scene(o, v);
    PipelineConfig cfg;
    cfg.estimator.estimator = "keyframe";
    cfg.estimator.beta = o.beta;
    Odometry odo(cfg);
    double worst_after = 0.0, worst_turn = 0.0;
    for (int k = 0; k < 34; ++k) {
      const OdometryResult res = odo.process(scene.observe(k));
      if (k == 0) continue;
      ASSERT_TRUE(res.ok) << "scan " << k;
      const Eigen::Matrix3d truth = scene.pose(scene.scanStart(k));
      const double yaw_err = std::abs(se2::log(se2::inverse(truth) * res.T_world_sensor)(2));
      // In the turn, away from the two scans holding a step (10, 20) and the next one each.
      if (k >= 12 && k < 20) worst_turn = std::max(worst_turn, yaw_err);
      if (k >= 22) worst_after = std::max(worst_after, yaw_err);
    }
    std::cout << "[ info ] seed " << seed << ": worst yaw error in the turn " << worst_turn / kDeg
              << " deg, after it " << worst_after / kDeg << " deg\n";
    EXPECT_LT(worst_after, 0.12 * kDeg) << "seed " << seed;
  }
}

TEST(KeyframeTracker, TurnWithViewDependentDescriptors) {
  // ORB on the Cartesian image changes as the scene turns under the sensor: descriptors of a
  // landmark lose bits with the heading (each bit flips once the heading passes its own
  // random threshold within 45 deg). A scan pair 9 deg apart still matches; a keyframe
  // 15-20 deg back mostly does not, as at the city route's corners and on tight_turns.
  // Then keypoints are paired by proximity to the prediction (kProximityGate) instead of
  // falling back to the frame-to-frame step, which lags each yaw-rate step.
  for (const uint32_t seed : {21u, 22u, 23u}) {
    std::vector<Eigen::Vector3d> v;
    for (int k = 0; k < 34; ++k) v.emplace_back(5.0, 0.0, (k >= 10 && k < 20) ? 0.625 : 0.0);
    SceneOptions o = options(seed);
    o.velocity_shift = 0.3 * o.period;
    SyntheticScene scene(o, v);
    const spinradar::testing::ViewDependentDescriptors flips(o.landmarks, seed);
    const Hook view = [&](SyntheticScene& sc, int k, FeatureFrame& f, const std::vector<int>& ids) {
      flips.apply(sc, k, f, ids);
    };
    const Drive kf = run("keyframe", scene, 34, view);
    EXPECT_LT(kf.final_yaw_err, 0.2 * kDeg) << "seed " << seed;
    EXPECT_LT(kf.final_err / kf.length, 0.01) << "seed " << seed;
  }
}

TEST(KeyframeTracker, NoDriftWhileStandingStill) {
  SyntheticScene scene(options(3), {Eigen::Vector3d::Zero()});
  const Drive kf = run("keyframe", scene, 20);
  EXPECT_LT(kf.final_err, 1e-9);
  EXPECT_LT(kf.final_yaw_err, 1e-9);
}

TEST(KeyframeTracker, MovingCarsAreRejected) {
  // Every 6th landmark is a car driving at 8 m/s along y (2 m per scan): matches to it are
  // consistent with each other but not with the static world.
  const int n = 30;
  SyntheticScene scene(options(5), {Eigen::Vector3d(10.0, 0.0, 5.0 * kDeg)});
  const Drive kf = run("keyframe", scene, n, [](SyntheticScene& s, int, FeatureFrame&, const std::vector<int>&) {
    for (size_t i = 0; i < s.landmarks().size(); i += 6) s.landmarks()[i].y() += 2.0;
  });
  EXPECT_LT(kf.final_err / kf.length, 0.005);
  EXPECT_LT(kf.final_yaw_err, 0.2 * kDeg);
}

TEST(KeyframeTracker, RepetitiveFacadesDoNotMakeItJump) {
  // A straight street between two facades of identical elements every 1.5 m: 35 % of the
  // facade keypoints carry their neighbour's descriptor (aliasing), so that many matches
  // are off by one period along track. The estimate must not jump along the street.
  SceneOptions o = options(9);
  o.landmarks = 2 * 200;
  o.clutter = 50;
  SyntheticScene scene(o, {Eigen::Vector3d(12.0, 0.0, 0.0)});
  for (int i = 0; i < 200; ++i) {
    scene.landmarks()[2 * i] = Eigen::Vector2d(-60.0 + 1.5 * i, 12.0);
    scene.landmarks()[2 * i + 1] = Eigen::Vector2d(-60.0 + 1.5 * i, -12.0);
  }
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const Hook alias = [&](SyntheticScene& s, int, FeatureFrame& f, const std::vector<int>& ids) {
    std::vector<int> row(s.landmarks().size(), -1);
    for (size_t r = 0; r < ids.size(); ++r)
      if (ids[r] >= 0) row[ids[r]] = static_cast<int>(r);
    cv::Mat src = f.descriptors.clone();
    for (size_t r = 0; r < ids.size(); ++r) {
      const int id = ids[r];
      if (id < 0 || id + 2 >= static_cast<int>(row.size()) || row[id + 2] < 0) continue;
      if (u01(rng) < 0.35) src.row(row[id + 2]).copyTo(f.descriptors.row(static_cast<int>(r)));
    }
  };
  const Drive kf = run("keyframe", scene, 30, alias);
  EXPECT_LT(kf.worst_along, 0.1);
  EXPECT_LT(kf.final_err, 0.5);
}

TEST(KeyframeTracker, PoseCovarianceIsHonest) {
  // What one registration measures is the pose relative to its keyframe: its errors are
  // independent between keyframes (the published pose covariance compounds them). Checked
  // over every scan of 8 drives: mean NEES near 3 (neither over- nor under-confident) and
  // the 95 % chi2 bound covering about 95 %. The final pose's NEES (one sample per drive)
  // only loosely.
  const int n = 16, seeds = 8;
  double nees = 0.0, key_mean = 0.0, covered = 0.0;
  int samples = 0;
  for (uint32_t seed = 1; seed <= seeds; ++seed) {
    SyntheticScene scene(options(100 + seed), varyingProfile(n, 3.0 * seed));
    const Drive d = run("keyframe", scene, n);
    nees += d.nees / seeds;
    for (double v : d.key_nees) {
      key_mean += v;
      covered += v < 7.815;  // chi2, 3 dof, 95 %
      ++samples;
    }
  }
  ASSERT_GT(samples, 50);
  key_mean /= samples;
  covered /= samples;
  std::cout << "[ info ] keyframe NEES of the pose relative to the keyframe over " << samples
            << " scans: mean " << key_mean << " (expected 3), 95 % bound covers "
            << 100.0 * covered << " %; final pose over " << seeds << " drives: " << nees << "\n";
  // Not over-cautious (was 1.46 before the calibration; 1.68 since straights publish the pair
  // velocity, whose lag term takes the step model's acceleration noise in full).
  EXPECT_GT(key_mean, 1.5);
  EXPECT_LT(key_mean, 4.0);  // not over-confident
  EXPECT_GT(covered, 0.90);
  EXPECT_LT(covered, 0.99);
  EXPECT_GT(nees, 0.5);
  EXPECT_LT(nees, 9.0);
}

TEST(KeyframeTracker, SwitchingEstimatorsKeepsThePoseContinuous) {
  // keyframe -> mc_doppler -> keyframe through setConfig (dynamic_reconfigure): the old
  // keyframe chain must not be reused after the switch back.
  SyntheticScene scene(options(13), {Eigen::Vector3d(10.0, 0.0, 8.0 * kDeg)});
  PipelineConfig cfg;
  cfg.estimator.estimator = "keyframe";
  Odometry odo(cfg);
  OdometryResult res;
  for (int k = 0; k < 18; ++k) {
    if (k == 6 || k == 11) {
      cfg.estimator.estimator = k == 6 ? "mc_doppler" : "keyframe";
      odo.setConfig(cfg);
    }
    res = odo.process(scene.observe(k));
    if (k > 0) {
      EXPECT_TRUE(res.ok) << k;
    }
  }
  const Eigen::Matrix3d truth = scene.pose(scene.scanStart(17));
  EXPECT_LT((res.T_world_sensor.topRightCorner<2, 1>() - truth.topRightCorner<2, 1>()).norm(), 0.1);
}
