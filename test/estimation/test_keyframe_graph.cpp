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

#include "support/glint_drive.hpp"

using namespace spinradar;

namespace {

constexpr double kDeg = M_PI / 180.0;

using Drive = spinradar::testing::GlintDrive;

Drive drive(uint32_t seed, double glint, int graph) {
  EstimatorConfig cfg;
  cfg.keyframe_graph = graph;
  return spinradar::testing::glintDrive(seed, glint, cfg);
}

}  // namespace

constexpr int kWindow = 6;

TEST(KeyframeGraph, AveragesTheHeadingWalkUnderGlintAndLosesNothingWithout) {
  spinradar::testing::GlintTally t;
  for (uint32_t seed = 1; seed <= 5; ++seed) {
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
    t.add(one, two, clean, clean_f);
  }
  t.print();
  EXPECT_GT(t.fused, 5 * t.seeds);
  EXPECT_GE(t.lower, t.seeds - 1);
  EXPECT_GE(t.lower_key, t.seeds - 1);  // and at the keyframes the later scans are chained from
  EXPECT_LT(t.sum_f, 0.9 * t.sum);
  EXPECT_LT(t.sum_cf, 1.1 * t.sum_c + 0.005 * kDeg * t.seeds);
  EXPECT_LT(t.nees_f, 3.0 * 1.5);
  EXPECT_LT(t.hnees_f, 1.5);
}
