// Dropped scans (issue 19): a 4 Hz sensor read every other scan, or one losing scans on the
// network, gives stamp steps of two rotation periods. Known truth: a synthetic drive that
// enters a turn (yaw rate 0 -> 0.625 rad/s at 1 rad/s^2, as the city route's turns), read
// at every scan and at every other one. A pair velocity stands for [t1, t2 + period], centred
// half a rotation PERIOD after the step's middle; interpolating two pairs with equal weights
// (right only for one-period steps) lagged by a quarter step less half a period (0.125 s at
// 2 Hz) and the turn-entry step came out 3-4 deg short (refined_estimator.cpp, item 5).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "support/synthetic_scene.hpp"
#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/odometry.hpp"
#include "spinradar/estimation/scan_period.hpp"

using namespace spinradar;
using spinradar::testing::SceneOptions;
using spinradar::testing::SyntheticScene;

namespace {

constexpr double kDeg = M_PI / 180.0;

/// 5 m/s; straight for 8 scans, then the yaw rate ramps 0 -> 0.625 rad/s over 2.5 scans and
/// holds (a turn entry); 32 scans of 0.25 s.
std::vector<Eigen::Vector3d> turnEntry() {
  std::vector<Eigen::Vector3d> v;
  for (int k = 0; k < 32; ++k) v.emplace_back(5.0, 0.0, std::clamp(0.25 * (k - 7), 0.0, 0.625));
  return v;
}

struct StepErrors {
  double worst_yaw = 0.0;   ///< rad, worst per-step yaw error
  double final_yaw = 0.0;   ///< rad, accumulated
  double final_pos = 0.0;   ///< m, accumulated
};

/// Runs `estimator` on scans 0, stride, 2 stride, ... and compares every published step with
/// the truth between the two scans' starts.
StepErrors run(const std::string& estimator, int stride, uint32_t seed) {
  SceneOptions o = spinradar::testing::clutteredDopplerScene(seed);
  o.max_range = 120.0;
  SyntheticScene scene(o, turnEntry());
  PipelineConfig cfg;
  cfg.estimator.estimator = estimator;
  cfg.estimator.beta = o.beta;
  Odometry odo(cfg);
  StepErrors e;
  Eigen::Matrix3d prev_est = Eigen::Matrix3d::Identity();
  int prev_k = 0;
  for (int k = 0; k < 32; k += stride) {
    const OdometryResult r = odo.process(scene.observe(k));
    if (k > 0) {
      EXPECT_TRUE(r.ok) << estimator << " scan " << k;
      const Eigen::Matrix3d step = se2::inverse(prev_est) * r.T_world_sensor;
      const Eigen::Vector3d err = se2::log(se2::inverse(scene.relative(prev_k, k)) * step);
      e.worst_yaw = std::max(e.worst_yaw, std::abs(err(2)));
      const Eigen::Vector3d acc = se2::log(se2::inverse(scene.relative(0, k)) * r.T_world_sensor);
      e.final_yaw = std::abs(acc(2));
      e.final_pos = acc.head<2>().norm();
    }
    prev_est = r.T_world_sensor;
    prev_k = k;
  }
  std::cout << "[ info ] " << estimator << (stride == 1 ? ", every scan" : ", every other scan")
            << ": worst step yaw error " << e.worst_yaw / kDeg << " deg, final yaw error "
            << e.final_yaw / kDeg << " deg, position " << e.final_pos << " m\n";
  return e;
}

}  // namespace

TEST(ScanPeriod, EarlierPairWeight) {
  // Steps of one period: the mean. Two periods each (every other scan): 1/4, the current pair
  // 3/4. One period then a dropped scan: 1/3.
  EXPECT_DOUBLE_EQ(ScanPeriod::earlierPairWeight(0.25, 0.25, 0.25), 0.5);
  EXPECT_DOUBLE_EQ(ScanPeriod::earlierPairWeight(0.26, 0.24, 0.25), 0.5);
  EXPECT_DOUBLE_EQ(ScanPeriod::earlierPairWeight(0.5, 0.5, 0.25), 0.25);
  EXPECT_DOUBLE_EQ(ScanPeriod::earlierPairWeight(0.25, 0.5, 0.25), 0.25 / 0.75);
  EXPECT_DOUBLE_EQ(ScanPeriod::earlierPairWeight(0.5, 0.5, 0.0), 0.5);  // period unknown
}

TEST(DroppedScans, TurnEntryStepsAreLagFreeEveryOtherScan) {
  // refined (its steps are published) and keyframe (the refined step is its prior and, where
  // a registration fails, its step).
  for (const std::string est : {"refined", "keyframe"}) {
    const StepErrors full = run(est, 1, 11), skip = run(est, 2, 11);
    // refined every other scan, equal weights (before): worst step 3.07 deg, final yaw 4.36 deg
    // (the lag holds through the turn), 1.21 m; now 1.30 deg, 0.13 deg, 0.09 m (every scan
    // 0.90 deg, 0.05 deg, 0.04 m). keyframe: 0.02-0.03 deg either way (its synthetic
    // registrations never fail; the simulator test test_odometry_dropped_scans does).
    EXPECT_LT(skip.worst_yaw, std::max(2.0 * full.worst_yaw, 0.3 * kDeg)) << est;
    EXPECT_LT(skip.final_yaw, std::max(2.0 * full.final_yaw, 0.3 * kDeg)) << est;
    EXPECT_LT(skip.final_pos, std::max(2.0 * full.final_pos, 0.3)) << est;
  }
}

TEST(ScanPeriod, RotationPeriodFromTheRowStamps) {
  PolarScan s;
  s.resize(400, 10);
  const int64_t t0 = 1'700'000'000'000'000'000LL;
  for (int a = 0; a < 400; ++a) s.stamp_ns[a] = t0 + a * 625'000LL;  // 4 Hz
  EXPECT_EQ(rotationPeriodNs(s), 250'000'000);
  // Packet-arrival stamps (Oxford): rows arrive in bursts of 8, stamped at the burst's end,
  // and a missing row: still the period (a line, not first-to-last).
  for (int a = 0; a < 400; ++a) s.stamp_ns[a] = t0 + (a / 8 * 8 + 7) * 625'000LL;
  s.valid[17] = 0;
  s.stamp_ns[17] = 0;
  EXPECT_NEAR(1e-9 * static_cast<double>(rotationPeriodNs(s)), 0.25, 1e-4);
  s.resize(1, 10);
  EXPECT_EQ(rotationPeriodNs(s), 0);  // cannot be told
}

TEST(ScanPeriod, AGapUsesTheScansOwnRotation) {
  // A frame that knows its rotation (0.25 s): a step of two periods is a gap from the first
  // scan on, and the period is the rotation's, not half the step or the keypoint span.
  FeatureFrame f;
  f.stamp_ns = 0;
  f.period_ns = 250'000'000;
  Keypoint k;
  k.stamp_ns = 100'000'000;  // keypoints only in the first 0.1 s
  f.keypoints.push_back(k);
  ScanPeriod p;
  EXPECT_DOUBLE_EQ(p.update(f, 0.5), 0.25);
  EXPECT_DOUBLE_EQ(p.update(f, 0.25), 0.25);
  EXPECT_DOUBLE_EQ(p.update(f, 0.26), 0.26);  // no gap: the step, as before
  EXPECT_DOUBLE_EQ(ScanPeriod::rotation(f), 0.25);
}
