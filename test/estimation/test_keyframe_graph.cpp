// EstimatorConfig::keyframe_graph (issue 19): a scan that becomes the keyframe is registered
// against every keyframe of a sliding window, and the window is solved as a pose graph
// (keyframe_graph.cpp). Known truth: synthetic drives on a circle
// through landmarks (as test_keyframe_glint). Where the chain's error dominates (glint: every
// return scatters by 0.14 m per axis from scan to scan, and each keyframe switch hands its
// registration's error on) the heading walk must shrink; without glint (little to hand on) it
// must not grow; and the published pose's covariance must stay honest (NEES over the drive,
// 3 degrees of freedom, and the heading's alone).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include <Eigen/Cholesky>

#include "support/noisy_prior.hpp"
#include "support/glint_scene.hpp"
#include "support/synthetic_scene.hpp"
#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/keyframe_tracker.hpp"

using namespace spinradar;
using spinradar::testing::NoisyPrior;
using spinradar::testing::SceneOptions;
using spinradar::testing::SyntheticScene;

namespace {

constexpr double kDeg = M_PI / 180.0;

struct Drive {
  double heading_rms = 0.0;  ///< rad, accumulated heading error over the drive
  double key_heading_rms = 0.0;  ///< rad, the same at the scans that became keyframes
  double nees = 0.0;         ///< mean e^T P^-1 e over [x, y, yaw] (honest: ~3)
  double heading_nees = 0.0;  ///< mean e_yaw^2 / P_yaw (honest: ~1)
  int switches = 0, fused = 0, refused = 0;
};

Drive drive(uint32_t seed, double glint, int graph, int scans = 120) {
  const SceneOptions o = spinradar::testing::glintSceneOptions(seed, glint);
  const Eigen::Vector3d v(6.0, 0.0, 0.15);
  SyntheticScene scene(o, {v});
  EstimatorConfig cfg;
  cfg.beta = 0.0;
  cfg.keyframe_graph = graph;
  KeyframeTracker kt(cfg);
  NoisyPrior prior(seed + 7);
  Eigen::Matrix3d T_w = Eigen::Matrix3d::Identity(), P = Eigen::Matrix3d::Zero();
  Drive run;
  double sum2 = 0.0, key2 = 0.0;
  int keys = 0;
  for (int k = 0; k < scans; ++k) {
    const FeatureFrame f = scene.observe(k);
    MotionEstimate pair = prior(scene, k, v);
    const Eigen::Matrix3d T_prev = T_w, P_prev = P;
    const int switches_was = kt.keyframeSwitches();
    kt.track(f, T_prev, P_prev, 0.8, pair, T_w, P);
    const Eigen::Matrix3d truth = scene.relative(0, k);
    const Eigen::Vector3d t = se2::toXyYaw(truth), p = se2::toXyYaw(T_w);
    Eigen::Vector3d e = p - t;
    e(2) = std::atan2(std::sin(e(2)), std::cos(e(2)));
    sum2 += e(2) * e(2);
    if (k > 0 && kt.keyframeSwitches() != switches_was) {
      key2 += e(2) * e(2);
      ++keys;
    }
    if (k > 0) {
      run.nees += e.dot(P.ldlt().solve(e));
      run.heading_nees += e(2) * e(2) / P(2, 2);
    }
  }
  run.heading_rms = std::sqrt(sum2 / scans);
  run.key_heading_rms = keys > 0 ? std::sqrt(key2 / keys) : 0.0;
  run.nees /= scans - 1;
  run.heading_nees /= scans - 1;
  run.switches = kt.keyframeSwitches();
  run.fused = kt.fusionsAccepted();
  run.refused = kt.fusionsRejected();
  return run;
}

}  // namespace

constexpr int kWindow = 6;

TEST(KeyframeGraph, AveragesTheHeadingWalkUnderGlintAndLosesNothingWithout) {
  double sum = 0.0, sum_f = 0.0, sum_c = 0.0, sum_cf = 0.0, nees_f = 0.0, hnees_f = 0.0;
  double nees = 0.0;
  int lower = 0, lower_key = 0, seeds = 0, fused = 0;
  for (uint32_t seed = 1; seed <= 5; ++seed, ++seeds) {
    const Drive one = drive(seed, 0.14, 0), two = drive(seed, 0.14, kWindow);
    const Drive clean = drive(seed, 0.0, 0), clean_f = drive(seed, 0.0, kWindow);
    std::cout << "[ info ] seed " << seed << ", heading rms deg with 0.14 m glint: "
              << one.heading_rms / kDeg << " -> " << two.heading_rms / kDeg << " (edges "
              << two.fused << ", refused " << two.refused << ", " << two.switches
              << " switches; at the keyframes " << one.key_heading_rms / kDeg << " -> "
              << two.key_heading_rms / kDeg << "); without glint " << clean.heading_rms / kDeg
              << " -> "
              << clean_f.heading_rms / kDeg << "; NEES " << one.nees << " -> " << two.nees
              << " (clean " << clean.nees << " -> " << clean_f.nees << "), heading "
              << one.heading_nees << " -> " << two.heading_nees << "\n";
    ASSERT_GE(one.switches, 10) << "seed " << seed;
    EXPECT_EQ(one.fused + one.refused, 0);  // off: no extra registration
    lower += two.heading_rms < one.heading_rms;
    lower_key += two.key_heading_rms < one.key_heading_rms;
    sum += one.heading_rms;
    sum_f += two.heading_rms;
    sum_c += clean.heading_rms;
    sum_cf += clean_f.heading_rms;
    nees = std::max(nees, one.nees);
    nees_f = std::max({nees_f, two.nees, clean_f.nees});
    hnees_f = std::max({hnees_f, two.heading_nees, clean_f.heading_nees});
    fused += two.fused;
  }
  std::cout << "[ info ] summed heading rms deg, glint: " << sum / kDeg << " -> " << sum_f / kDeg
            << "; without: " << sum_c / kDeg << " -> " << sum_cf / kDeg
            << "; largest NEES " << nees << " -> " << nees_f << ", heading " << hnees_f << "\n";
  EXPECT_GT(fused, 5 * seeds);
  EXPECT_GE(lower, seeds - 1);
  EXPECT_GE(lower_key, seeds - 1);  // and at the keyframes the later scans are chained from
  EXPECT_LT(sum_f, 0.9 * sum);
  EXPECT_LT(sum_cf, 1.1 * sum_c + 0.005 * kDeg * seeds);
  EXPECT_LT(nees_f, 3.0 * 1.5);
  EXPECT_LT(hnees_f, 1.5);
}
