// The keyframe switch distance and inlier ratio (issue 19, EstimatorConfig::keyframe_distance
// and keyframe_inlier_ratio; docs/sensor_columns/round21_keyframe_spacing.md). Known truth: on
// a straight drive at 4 m/s (1 m per scan) a scan becomes the next keyframe once it is further
// than keyframe_distance from the keyframe, so one is taken every floor(d) + 1 scans; the
// inlier rule, off, takes none, and at its strictest takes at least as many.
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

/// Keyframe switches over kScans scans of a straight drive at 4 m/s (exact scene, honest prior).
int switchesOnStraight(double distance, double inlier_ratio, uint32_t seed) {
  SceneOptions o = spinradar::testing::clutteredDopplerScene(seed);
  o.beta = 0.0;
  const Eigen::Vector3d v(4.0, 0.0, 0.0);
  SyntheticScene scene(o, {v});
  EstimatorConfig cfg;
  cfg.estimator = "keyframe";
  cfg.beta = 0.0;
  cfg.keyframe_graph = 0;  // the switch rules alone
  cfg.keyframe_distance = distance;
  cfg.keyframe_inlier_ratio = inlier_ratio;
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

/// The first scan is the first keyframe; then one every `every` scans.
int expectedSwitches(int every) { return 1 + (kScans - 1) / every; }

}  // namespace

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
