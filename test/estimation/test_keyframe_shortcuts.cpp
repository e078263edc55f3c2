// The keyframe switch's shortcuts (keyframe_proximity.cpp: the pair's matches reused after a
// switch, proximity queries decided by anchors) change nothing: a tracker with them and one
// with every search and matching done in full (setExhaustiveSearch) give the same poses and
// covariances to the bit, scan by scan. Two drives: a circle under glint (graph window 6,
// registrations to past keyframes at every switch) and a turn with view-dependent
// descriptors (the proximity ICP against the keyframe and the past ones). The fast tracker's
// screen of the past keyframes' descriptor matchings (skipped where they cannot pass the first
// gate, else made in two parts and merged) and the solve's terms kept from its last iteration
// for the covariance pass are off in the full one.
#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <iostream>

#include "support/glint_scene.hpp"
#include "support/noisy_prior.hpp"
#include "support/synthetic_scene.hpp"
#include "support/view_dependent_descriptors.hpp"
#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/keyframe_tracker.hpp"
#include "spinradar/features/matcher.hpp"

using namespace spinradar;
using spinradar::testing::clutteredDopplerScene;
using spinradar::testing::glintSceneOptions;
using spinradar::testing::NoisyPrior;
using spinradar::testing::SceneOptions;
using spinradar::testing::SyntheticScene;

namespace {

bool sameBits(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return std::memcmp(a.data(), b.data(), sizeof(double) * 9) == 0;
}

using Hook = std::function<void(SyntheticScene&, int, FeatureFrame&, const std::vector<int>&)>;

// Runs both trackers over `scans` scans; returns the switches (and checks every scan).
int compareRuns(SyntheticScene& scene, const std::vector<Eigen::Vector3d>& v, int scans,
                const Hook& hook, int& past_registrations, int& skips, int& splits) {
  EstimatorConfig cfg;  // the defaults: keyframe_graph 6
  cfg.beta = 0.0;
  KeyframeTracker fast(cfg), full(cfg);
  full.setExhaustiveSearch(true);
  NoisyPrior prior(3);
  Eigen::Matrix3d Tf = Eigen::Matrix3d::Identity(), Pf = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d Te = Tf, Pe = Pf;
  FeatureFrame prev;
  std::vector<Match> pair_matches;
  for (int k = 0; k < scans; ++k) {
    std::vector<int> ids;
    FeatureFrame f = scene.observe(k, &ids);
    if (hook) hook(scene, k, f, ids);
    MotionEstimate pair = prior(scene, k, v[std::min<size_t>(k, v.size() - 1)]);
    MotionEstimate pair_e = pair;
    if (k > 0) {
      matchDescriptors(prev.descriptors, f.descriptors, 0.8, pair_matches);
      fast.offerPairMatches(prev.stamp_ns, f.stamp_ns, 0.8, pair_matches);
      full.offerPairMatches(prev.stamp_ns, f.stamp_ns, 0.8, pair_matches);  // ignored
    }
    Eigen::Matrix3d T, P;
    fast.track(f, Tf, Pf, 0.8, pair, T, P);
    Tf = T;
    Pf = P;
    full.track(f, Te, Pe, 0.8, pair_e, T, P);
    Te = T;
    Pe = P;
    EXPECT_TRUE(sameBits(Tf, Te) && sameBits(Pf, Pe)) << "scan " << k;
    EXPECT_TRUE(sameBits(fast.relativePose(), full.relativePose()) &&
                sameBits(fast.relativeCov(), full.relativeCov()))
        << "scan " << k;
    EXPECT_TRUE(sameBits(pair.T_12, pair_e.T_12)) << "scan " << k;
    prev = f;
  }
  EXPECT_EQ(fast.keyframeSwitches(), full.keyframeSwitches());
  EXPECT_EQ(fast.fusionsAccepted(), full.fusionsAccepted());
  EXPECT_EQ(full.screenSkips() + full.screenSplits(), 0);  // the full search matches every row
  past_registrations = full.fusionsAccepted() + full.fusionsRejected();
  skips += fast.screenSkips();
  splits += fast.screenSplits();
  return full.keyframeSwitches();
}

}  // namespace

TEST(KeyframeShortcuts, SamePosesAsTheFullSearchUnderGlint) {
  const std::vector<Eigen::Vector3d> v = {Eigen::Vector3d(6.0, 0.0, 0.15)};
  SyntheticScene scene(glintSceneOptions(2, 0.14), v);
  int past = 0, skips = 0, splits = 0;
  EXPECT_GE(compareRuns(scene, v, 90, nullptr, past, skips, splits), 10);
  EXPECT_GE(past, 20);  // the window's extra registrations ran
  EXPECT_GT(splits, 0);  // descriptor registrations to past keyframes that may pass: matched in two
  std::cout << "[ info ] screen: " << skips << " skipped, " << splits << " in two parts\n";
}

TEST(KeyframeShortcuts, SamePosesAsTheFullSearchInAViewDependentTurn) {
  std::vector<Eigen::Vector3d> v;
  for (int k = 0; k < 40; ++k) v.emplace_back(5.0, 0.0, (k >= 10 && k < 22) ? 0.625 : 0.0);
  SceneOptions o = clutteredDopplerScene(21);
  o.beta = 0.0;
  o.velocity_shift = 0.3 * o.period;
  SyntheticScene scene(o, v);
  // Descriptors lose bits with the heading: keyframes 15-20 deg back no longer match.
  const spinradar::testing::ViewDependentDescriptors flips(o.landmarks, 21);
  const Hook view = [&](SyntheticScene& sc, int k, FeatureFrame& f, const std::vector<int>& ids) {
    flips.apply(sc, k, f, ids);
  };
  int past = 0, skips = 0, splits = 0;
  EXPECT_GE(compareRuns(scene, v, 40, view, past, skips, splits), 4);
  EXPECT_GT(skips, 0);  // past keyframes turned away: their descriptor matchings skipped
  std::cout << "[ info ] screen: " << skips << " skipped, " << splits << " in two parts\n";
  EXPECT_GE(past, 5);
}
