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
  double sum = 0.0, sum_f = 0.0, sum_c = 0.0, sum_cf = 0.0, nees_f = 0.0, hnees_f = 0.0;
  double nees = 0.0;
  int lower = 0, seeds = 0, fused = 0;
  for (uint32_t seed = 1; seed <= 5; ++seed, ++seeds) {
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
    lower += two.heading_rms < one.heading_rms;
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
  EXPECT_GT(fused, 5 * seeds);  // most switches fuse
  // Glint: the fusion lowers the heading walk on most seeds and clearly in sum.
  EXPECT_GE(lower, seeds - 1);
  EXPECT_LT(sum_f, 0.9 * sum);
  // Without glint no loss (within a tenth).
  EXPECT_LT(sum_cf, 1.1 * sum_c + 0.005 * kDeg * seeds);
  // The published covariance stays honest: not over-confident (3 dof, and the heading's).
  EXPECT_LT(nees_f, 3.0 * 1.5);
  EXPECT_LT(hnees_f, 1.5);
}
