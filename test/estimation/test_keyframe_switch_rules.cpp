// The keyframe switch rules (issue 19) against known geometry.
// - Angle (EstimatorConfig::keyframe_angle and keyframe_angle_fast), constant-rate turns: a scan
//   becomes the next keyframe once it has turned further than keyframe_angle from the keyframe,
//   and where one scan alone turns further than keyframe_angle, once it has turned further than
//   keyframe_angle_fast. At 4 m/s (10 m, the distance rule, is 10 scans away) a turn of w rad/s
//   turns w * 0.25 rad per scan, so a keyframe is taken every floor(angle / (w * 0.25)) + 1 scans.
// - Distance and inlier ratio (keyframe_distance, keyframe_inlier_ratio;
//   docs/sensor_columns/round21_keyframe_spacing.md), a straight drive at 4 m/s (1 m per scan):
//   a keyframe every floor(d) + 1 scans; the inlier rule, off, takes none, and at its strictest
//   takes at least as many as at 0.5.
#include <gtest/gtest.h>

#include <iostream>

#include "support/noisy_prior.hpp"
#include "support/synthetic_scene.hpp"
#include "spinradar/estimation/keyframe_tracker.hpp"

using namespace spinradar;
using spinradar::testing::NoisyPrior;
using spinradar::testing::SceneOptions;
using spinradar::testing::SyntheticScene;

namespace {

constexpr int kScans = 25;

/// Keyframe switches over kScans scans at constant body velocity v (exact scene, honest prior),
/// with the graph off: the switch rules alone.
int switches(const Eigen::Vector3d& v, EstimatorConfig cfg, uint32_t seed) {
  SceneOptions o = spinradar::testing::clutteredDopplerScene(seed);
  o.beta = 0.0;
  SyntheticScene scene(o, {v});
  cfg.estimator = "keyframe";
  cfg.beta = 0.0;
  cfg.keyframe_graph = 0;
  KeyframeTracker kt(cfg);
  NoisyPrior prior(seed + 11);
  Eigen::Matrix3d T_w = Eigen::Matrix3d::Identity(), P = Eigen::Matrix3d::Zero();
  for (int k = 0; k < kScans; ++k) {
    MotionEstimate pair = prior(scene, k, v);
    const Eigen::Matrix3d T_prev = T_w, P_prev = P;
    kt.track(scene.observe(k), T_prev, P_prev, 0.8, pair, T_w, P);
  }
  return kt.keyframeSwitches();
}

int switchesInTurn(double yaw_rate, double angle, double fast, uint32_t seed) {
  EstimatorConfig cfg;
  cfg.keyframe_angle = angle;
  cfg.keyframe_angle_fast = fast;
  return switches(Eigen::Vector3d(4.0, 0.0, yaw_rate), cfg, seed);
}

int switchesOnStraight(double distance, double inlier_ratio, uint32_t seed) {
  EstimatorConfig cfg;
  cfg.keyframe_distance = distance;
  cfg.keyframe_inlier_ratio = inlier_ratio;
  return switches(Eigen::Vector3d(4.0, 0.0, 0.0), cfg, seed);
}

/// The first scan is the first keyframe; then one every `every` scans.
int expectedSwitches(int every) { return 1 + (kScans - 1) / every; }

}  // namespace

TEST(KeyframeSwitchAngle, GentleTurnSwitchesAtKeyframeAngle) {
  // 0.6 rad/s: 0.15 rad per scan, under both angles; the fast angle does not apply.
  for (uint32_t seed : {1u, 2u}) {
    EXPECT_EQ(switchesInTurn(0.6, 0.25, 0.35, seed), expectedSwitches(2)) << "seed " << seed;
    EXPECT_EQ(switchesInTurn(0.6, 0.35, 0.35, seed), expectedSwitches(3)) << "seed " << seed;
  }
}

TEST(KeyframeSwitchAngle, FastTurnSwitchesAtTheFastAngle) {
  // 1.2 rad/s: 0.30 rad per scan, beyond 0.25. Without the fast angle every scan would be a
  // keyframe; with it (0.35) every second scan (0.60 rad).
  for (uint32_t seed : {1u, 2u}) {
    const int with_fast = switchesInTurn(1.2, 0.25, 0.35, seed);
    const int without = switchesInTurn(1.2, 0.25, 0.25, seed);
    std::cout << "[ info ] seed " << seed << ": 1.2 rad/s, switches " << without << " -> "
              << with_fast << " with keyframe_angle_fast 0.35\n";
    EXPECT_EQ(without, expectedSwitches(1)) << "seed " << seed;
    EXPECT_EQ(with_fast, expectedSwitches(2)) << "seed " << seed;
  }
}

TEST(KeyframeSwitchDistance, StraightDriveSwitchesAtKeyframeDistance) {
  for (uint32_t seed : {1u, 2u}) {
    EXPECT_EQ(switchesOnStraight(2.5, 0.0, seed), expectedSwitches(3)) << "seed " << seed;
    EXPECT_EQ(switchesOnStraight(5.5, 0.0, seed), expectedSwitches(6)) << "seed " << seed;
    EXPECT_EQ(switchesOnStraight(10.0, 0.0, seed), expectedSwitches(11)) << "seed " << seed;
  }
}

TEST(KeyframeSwitchDistance, InlierRatioAddsSwitchesOnlyWhenOn) {
  for (uint32_t seed : {1u, 2u}) {
    const int off = switchesOnStraight(100.0, 0.0, seed);
    const int mid = switchesOnStraight(100.0, 0.5, seed);
    const int strict = switchesOnStraight(100.0, 1.0, seed);
    std::cout << "[ info ] seed " << seed << ": switches over " << kScans
              << " m with keyframe_inlier_ratio 0 / 0.5 / 1: " << off << " / " << mid << " / "
              << strict << "\n";
    EXPECT_EQ(off, 1) << "seed " << seed;  // the registrations stay strong: the first keyframe only
    EXPECT_GE(mid, off) << "seed " << seed;
    EXPECT_GT(strict, mid) << "seed " << seed;
  }
}
