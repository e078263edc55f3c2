// The keyframe estimator under glint (issue 19): every return's position scatters from scan to
// scan (the simulator's physics `glint`, real returns 0.13-0.25 m). Every scan registered to a
// keyframe shares that keyframe map's scatter, and a keyframe switch hands it on. Known truth:
// a synthetic drive on a circle through landmarks whose every observation is moved by an
// isotropic 0.14 m per axis (range and across the beam); the heading error against the truth
// over the drive, with the options of EstimatorConfig (submap_keyframes, floor_gate) and
// without. Several seeds: one drive's heading walk is a handful of keyframe switches.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>

#include "support/laid_out_keyframes.hpp"
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
  double heading_nees = 0.0;  ///< mean of e^2 / P_yaw over the drive (1 dof: honest ~1)
  int switches = 0;
};

/// `scans` scans at 6 m/s turning at 0.15 rad/s (a 40 m circle) through landmarks; the
/// frame-to-frame prior is the truth with Gaussian errors of its stated covariance.
Drive drive(uint32_t seed, double glint, int submap, double floor_gate, int scans = 120) {
  const SceneOptions o = spinradar::testing::glintSceneOptions(seed, glint);
  const Eigen::Vector3d v(6.0, 0.0, 0.15);
  SyntheticScene scene(o, {v});
  EstimatorConfig cfg;
  cfg.beta = 0.0;
  cfg.submap_keyframes = submap;
  cfg.floor_gate = floor_gate;
  // As this drive was laid out (support/laid_out_keyframes.hpp).
  cfg.keyframe_distance = spinradar::testing::kLaidOutKeyframeDistance;
  // Measured without the turn-heading blend (start_rate_pair_weight, default 0.25 since the
  // twentieth round): it mixes this harness's noisy pair step into the scans after turn
  // switches in every arm alike; its own test is KeyframeStartRate.
  cfg.start_rate_pair_weight = 0.0;
  KeyframeTracker kt(cfg);
  NoisyPrior prior(seed + 7);
  Eigen::Matrix3d T_w = Eigen::Matrix3d::Identity(), P = Eigen::Matrix3d::Zero();
  Drive run;
  double sum2 = 0.0, nees = 0.0;
  for (int k = 0; k < scans; ++k) {
    const FeatureFrame f = scene.observe(k);
    MotionEstimate pair = prior(scene, k, v);
    const Eigen::Matrix3d T_prev = T_w, P_prev = P;
    kt.track(f, T_prev, P_prev, 0.8, pair, T_w, P);
    const Eigen::Matrix3d truth = scene.relative(0, k);
    const double e = se2::log(se2::inverse(truth) * T_w)(2);
    sum2 += e * e;
    if (k > 0) nees += e * e / P(2, 2);
  }
  run.heading_rms = std::sqrt(sum2 / scans);
  run.heading_nees = nees / (scans - 1);
  run.switches = kt.keyframeSwitches();
  return run;
}

}  // namespace

TEST(KeyframeGlint, SubmapAndFloorGateLowerTheHeadingDrift) {
  // Measured: with glint 0.271 deg summed heading rms with neither option, 0.127 with a
  // submap of 3, 0.188 with floor_gate 5 (each lower on every seed); without glint 0.049 /
  // 0.050 / 0.049 deg (floor_gate: the same poses, the floor measures 0 there). Heading NEES
  // (the accumulated pose's yaw variance) 0.04-0.11 with neither, 0.01-0.06 with either:
  // cautious (the covariance model does not count the averaging). With 160 scans and seeds
  // 1-6: 0.38 -> 0.18 / 0.24 deg.
  Drive sum, sum_sub, sum_gate, sum_clean, sum_sub_clean, sum_gate_clean;
  int sub_lower = 0, gate_lower = 0, seeds = 0;
  for (uint32_t seed = 1; seed <= 5; ++seed, ++seeds) {
    const Drive one = drive(seed, 0.14, 1, 0.0), sub = drive(seed, 0.14, 3, 0.0),
                gate = drive(seed, 0.14, 1, 5.0);
    const Drive one_clean = drive(seed, 0.0, 1, 0.0), sub_clean = drive(seed, 0.0, 3, 0.0),
                gate_clean = drive(seed, 0.0, 1, 5.0);
    std::cout << "[ info ] seed " << seed << ", heading rms deg with 0.14 m glint: "
              << one.heading_rms / kDeg << " (neither), " << sub.heading_rms / kDeg
              << " (submap of 3), " << gate.heading_rms / kDeg << " (floor_gate 5); without: "
              << one_clean.heading_rms / kDeg << " / " << sub_clean.heading_rms / kDeg << " / "
              << gate_clean.heading_rms / kDeg << "; heading NEES " << one.heading_nees << " / "
              << sub.heading_nees << " / " << gate.heading_nees << "; " << one.switches
              << " switches\n";
    ASSERT_GE(one.switches, 10) << "seed " << seed;
    sub_lower += sub.heading_rms < one.heading_rms;
    gate_lower += gate.heading_rms < one.heading_rms;
    for (auto [acc, d] : {std::pair<Drive*, const Drive*>{&sum, &one}, {&sum_sub, &sub},
                          {&sum_gate, &gate}, {&sum_clean, &one_clean},
                          {&sum_sub_clean, &sub_clean}, {&sum_gate_clean, &gate_clean}}) {
      acc->heading_rms += d->heading_rms;
      acc->heading_nees = std::max(acc->heading_nees, d->heading_nees);
    }
  }
  std::cout << "[ info ] summed heading rms deg, glint: " << sum.heading_rms / kDeg << " -> "
            << sum_sub.heading_rms / kDeg << " (submap), " << sum_gate.heading_rms / kDeg
            << " (floor_gate); without: " << sum_clean.heading_rms / kDeg << " -> "
            << sum_sub_clean.heading_rms / kDeg << " / " << sum_gate_clean.heading_rms / kDeg
            << "\n";
  // Glint: each option lowers the heading walk on most seeds and clearly in sum.
  EXPECT_GE(sub_lower, seeds - 1);
  EXPECT_GE(gate_lower, seeds - 1);
  EXPECT_LT(sum_sub.heading_rms, 0.7 * sum.heading_rms);
  EXPECT_LT(sum_gate.heading_rms, 0.8 * sum.heading_rms);
  // Without glint neither loses.
  EXPECT_LT(sum_sub_clean.heading_rms, 1.15 * sum_clean.heading_rms);
  EXPECT_LT(sum_gate_clean.heading_rms, 1.05 * sum_clean.heading_rms);
  // And neither makes the accumulated pose's yaw covariance over-confident.
  EXPECT_LT(sum_sub.heading_nees, 1.0);
  EXPECT_LT(sum_gate.heading_nees, 1.0);
}
