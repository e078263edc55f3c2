// The keyframe estimator's proximity ICP in dense clutter (issue 19, EstimatorConfig::
// proximity_settle_gate). Where the descriptors fail against a keyframe turned away from the
// scan (a turn), the scan is registered by nearest points to the prediction: 1.5 m, then
// 0.6 m until it settles, then one re-association at 0.3 m. Under the Oxford and MulRan
// sensor models most keypoints are clutter that is not found again
// (docs/sensor_columns/round06_far_field_not_refound.md), and at 0.6 m many pair by chance and
// hold the pose near the prediction; one re-association at 0.3 m keeps much of that
// (city_oxford layouts 1 / 2: those registrations 0.125 / 0.110 deg rms off in yaw; settled at
// 0.3 m 0.099 / 0.076; docs/sensor_columns/round09_weak_switches.md).
// Known truth: a synthetic drive (straight, a 0.6 rad/s turn, straight) through sparse
// landmarks and dense clutter, descriptors failing in the turn and the pair prior 0.5 deg
// off per step; the heading error against the truth with and without the settling.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>
#include <vector>

#include "support/laid_out_keyframes.hpp"
#include "support/noisy_prior.hpp"
#include "support/synthetic_scene.hpp"
#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/keyframe_tracker.hpp"

using namespace spinradar;
using spinradar::testing::NoisyPrior;
using spinradar::testing::PriorNoise;
using spinradar::testing::SceneOptions;
using spinradar::testing::SyntheticScene;

namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr int kStraight = 8, kTurn = 12;

/// rms over the drive of the accumulated heading error (rad).
double drive(uint32_t seed, double settle_gate) {
  SceneOptions o;
  o.landmarks = 350;  // sparse structure found again,
  o.clutter = 6000;   // dense clutter that is not (the Oxford model's x20 bands)
  o.min_range = 4.0;
  o.max_range = 80.0;
  o.visible_range = 80.0;
  o.range_sigma = 0.03;
  o.azimuth_sigma = 0.002;
  o.seed = seed;
  std::vector<Eigen::Vector3d> v;
  for (int k = 0; k < kStraight; ++k) v.emplace_back(6.0, 0.0, 0.0);
  for (int k = 0; k < kTurn; ++k) v.emplace_back(6.0, 0.0, 0.6);
  for (int k = 0; k < kStraight; ++k) v.emplace_back(6.0, 0.0, 0.0);
  SyntheticScene scene(o, v);
  EstimatorConfig cfg;
  cfg.beta = 0.0;
  cfg.proximity_settle_gate = settle_gate;
  // As this drive was laid out (support/laid_out_keyframes.hpp).
  cfg.keyframe_distance = spinradar::testing::kLaidOutKeyframeDistance;
  // The chain without the pose graph (default keyframe_graph 6 since 2026-11-27): the graph
  // averages the same heading walk over the window, both ways (measured with it: 4.23 -> 3.03
  // deg summed, lower on 4 of 6 seeds), and this checks the settling on its own.
  cfg.keyframe_graph = 0;
  // Measured without the turn-heading blend (start_rate_pair_weight, default 0.25 since the
  // twentieth round): it mixes this harness's noisy pair step into the scans after turn
  // switches in every arm alike; its own test is KeyframeStartRate.
  cfg.start_rate_pair_weight = 0.0;
  KeyframeTracker kt(cfg);
  PriorNoise noise;
  noise.yaw = 0.5 * kDeg;  // the pair step at turn entries (0.25-0.9 deg measured)
  NoisyPrior prior(seed + 7, noise);
  std::mt19937 rng(seed + 13);
  std::uniform_int_distribution<int> ub(0, 255);
  Eigen::Matrix3d T_w = Eigen::Matrix3d::Identity(), P = Eigen::Matrix3d::Zero();
  double sum2 = 0.0;
  const int scans = static_cast<int>(v.size());
  for (int k = 0; k < scans; ++k) {
    FeatureFrame f = scene.observe(k);
    if (k >= kStraight && k < kStraight + kTurn)  // descriptors fail in the turn
      for (int r = 0; r < f.descriptors.rows; ++r)
        for (int j = 0; j < f.descriptors.cols; ++j)
          f.descriptors.at<uint8_t>(r, j) = static_cast<uint8_t>(ub(rng));
    MotionEstimate pair = prior(scene, k, v[static_cast<size_t>(k)]);
    const Eigen::Matrix3d T_prev = T_w, P_prev = P;
    kt.track(f, T_prev, P_prev, 0.8, pair, T_w, P);
    const double e = se2::log(se2::inverse(scene.relative(0, k)) * T_w)(2);
    sum2 += e * e;
  }
  return std::sqrt(sum2 / scans);
}

}  // namespace

TEST(KeyframeProximitySettle, SettlingAtTheNarrowGateLowersTheHeadingError) {
  // Measured: summed heading rms 5.77 -> 3.27 deg, lower on five seeds (1.05 -> 0.70,
  // 0.74 -> 0.43, 1.12 -> 0.25, 0.95 -> 0.31, 0.68 -> 0.35 deg), the same on one (1.23).
  double sum_off = 0.0, sum_on = 0.0;
  int lower = 0, seeds = 0;
  for (uint32_t seed = 1; seed <= 6; ++seed, ++seeds) {
    const double off = drive(seed, 0.0), on = drive(seed, 0.3);
    std::cout << "[ info ] seed " << seed << ", heading rms deg: " << off / kDeg
              << " (one re-association at 0.3 m), " << on / kDeg << " (settled at 0.3 m)\n";
    sum_off += off;
    sum_on += on;
    lower += on < off;
  }
  std::cout << "[ info ] summed heading rms deg: " << sum_off / kDeg << " -> " << sum_on / kDeg
            << "\n";
  EXPECT_GE(lower, seeds - 1);
  EXPECT_LT(sum_on, 0.7 * sum_off);
}
