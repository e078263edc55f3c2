// EstimatorConfig::keyframe_fusion (issue 19): a scan that becomes the keyframe is registered
// against the keyframe before the current one too, and the two estimates of its pose are
// fused by their covariances (keyframe_fusion.cpp). Known truth: synthetic drives on a circle
// through landmarks (as test_keyframe_glint). Where the chain's error dominates (glint: every
// return scatters by 0.14 m per axis from scan to scan, and each keyframe switch hands its
// registration's error on) the heading walk must shrink; without glint (little to hand on) it
// must not grow; and the published pose's covariance must stay honest (NEES over the drive,
// 3 degrees of freedom, and the heading's alone).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "support/laid_out_keyframes.hpp"
#include "support/glint_drive.hpp"

using namespace spinradar;

namespace {

constexpr double kDeg = M_PI / 180.0;

using Drive = spinradar::testing::GlintDrive;

Drive drive(uint32_t seed, double glint, int fusion) {
  EstimatorConfig cfg;
  cfg.keyframe_fusion = fusion;
  // keyframe_fusion acts only without the pose graph (keyframe_tracker.cpp: the graph takes
  // the switch when keyframe_graph > 0, the default since 2026-11-27): pinned off here.
  cfg.keyframe_graph = 0;
  // As the drive was laid out (support/laid_out_keyframes.hpp).
  cfg.keyframe_distance = spinradar::testing::kLaidOutKeyframeDistance;
  return spinradar::testing::glintDrive(seed, glint, cfg);
}

}  // namespace

TEST(KeyframeFusion, LowersTheChainsWalkWhereItDominatesAndLosesNothingElse) {
  spinradar::testing::GlintTally t;
  for (uint32_t seed = 1; seed <= 5; ++seed) {
    const Drive one = drive(seed, 0.14, 0), two = drive(seed, 0.14, 1);
    const Drive clean = drive(seed, 0.0, 0), clean_f = drive(seed, 0.0, 1);
    std::cout << "[ info ] seed " << seed << ", heading rms deg with 0.14 m glint: "
              << one.heading_rms / kDeg << " -> " << two.heading_rms / kDeg << " (fused "
              << two.fused << ", refused " << two.refused << " of " << two.switches
              << " switches); without glint " << clean.heading_rms / kDeg << " -> "
              << clean_f.heading_rms / kDeg << "; NEES " << one.nees << " -> " << two.nees
              << ", heading " << one.heading_nees << " -> " << two.heading_nees << "\n";
    ASSERT_GE(one.switches, 10) << "seed " << seed;
    EXPECT_EQ(one.fused + one.refused, 0);  // off: no extra registration
    t.add(one, two, clean, clean_f);
  }
  t.print();
  EXPECT_GT(t.fused, 5 * t.seeds);  // most switches fuse
  // Glint: the fusion lowers the heading walk on most seeds and clearly in sum.
  EXPECT_GE(t.lower, t.seeds - 1);
  EXPECT_LT(t.sum_f, 0.9 * t.sum);
  // Without glint no loss (within a tenth).
  EXPECT_LT(t.sum_cf, 1.1 * t.sum_c + 0.005 * kDeg * t.seeds);
  // The published covariance stays honest: not over-confident (3 dof, and the heading's).
  EXPECT_LT(t.nees_f, 3.0 * 1.5);
  EXPECT_LT(t.hnees_f, 1.5);
}
