// The keyframe registration's tangential noise floor (issue 19), measured from its residuals.
// Real returns (azimuth peaks) scatter across the beam by 0.13-0.20 m at every range (the
// scattering centre of a near extended object moves with the aspect angle), not by
// r x azimuth_sigma: weighed by the configured model alone, the near matches get 10-50x the
// weight their scatter deserves and carry the yaw. The simulator and the synthetic scenes of
// the other tests have no such scatter, and a fixed floor there cost them the near points'
// information (the yaw rate of a registration then followed the keyframe map's, and a
// yaw-rate step stayed in the chain: test_keyframe_tracker). Known truth here: a drive
// through landmarks with and without 0.15 m of scatter across the beam; the floor must be
// measured near 0.15 m with it and near 0 without, and lower the registrations' yaw error.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>

#include "support/noisy_prior.hpp"
#include "support/synthetic_scene.hpp"
#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/keyframe_tracker.hpp"
#include "spinradar/estimation/mc_ransac.hpp"

using namespace spinradar;
using spinradar::testing::NoisyPrior;
using spinradar::testing::SceneOptions;
using spinradar::testing::SyntheticScene;

namespace {

constexpr double kDeg = M_PI / 180.0;

struct Drive {
  double yaw_rms = 0.0;    ///< rad, registrations' yaw relative to their keyframe
  double mean_floor = 0.0; ///< m, the floor the registrations were weighed with
  int count = 0;
};

/// Registers `scans` scans of a drive at 8 m/s turning at 0.05 rad/s to keyframes; the
/// frame-to-frame prior is the truth with Gaussian errors of its stated covariance.
Drive drive(uint32_t seed, double scatter, double max_floor, int scans = 40) {
  SceneOptions o;
  o.landmarks = 300;
  o.min_range = 4.0;
  o.max_range = 80.0;
  o.range_sigma = 0.03;
  o.azimuth_sigma = 0.001;  // azimuth peaks: sub-row azimuths
  o.tangential_sigma = scatter;
  o.clutter = 100;
  o.seed = seed;
  const Eigen::Vector3d v(8.0, 0.0, 0.05);
  SyntheticScene scene(o, {v});
  EstimatorConfig cfg;
  cfg.beta = 0.0;
  KeyframeTracker kt(cfg);
  kt.setTangentialFloor(max_floor);
  NoisyPrior prior(seed + 7);
  Eigen::Matrix3d T_w = Eigen::Matrix3d::Identity(), P = Eigen::Matrix3d::Zero();
  Drive run;
  double sum2 = 0.0, floors = 0.0;
  for (int k = 0; k < scans; ++k) {
    const FeatureFrame f = scene.observe(k);
    MotionEstimate pair = prior(scene, k, v);
    const Eigen::Matrix3d T_prev = T_w, P_prev = P;
    kt.track(f, T_prev, P_prev, 0.8, pair, T_w, P);
    if (k == 0 || kt.keyframeStamp() == f.stamp_ns) continue;
    const double tk = 1e-9 * static_cast<double>(kt.keyframeStamp() - o.t0_ns);
    const Eigen::Matrix3d truth = se2::inverse(scene.pose(tk)) * scene.pose(scene.scanStart(k));
    const double e = se2::log(se2::inverse(truth) * kt.relativePose())(2);
    sum2 += e * e;
    floors += kt.lastTangentialFloor();
    ++run.count;
  }
  run.yaw_rms = std::sqrt(sum2 / std::max(run.count, 1));
  run.mean_floor = floors / std::max(run.count, 1);
  return run;
}

}  // namespace

TEST(KeyframeTangentialFloor, MeasuredFromTheResiduals) {
  for (const uint32_t seed : {1u, 2u}) {
    const Drive with = drive(seed, 0.15, kTangentialFloor, 16);
    const Drive without = drive(seed, 0.0, kTangentialFloor, 16);
    std::cout << "[ info ] seed " << seed << ": mean floor " << with.mean_floor
              << " m with 0.15 m of scatter, " << without.mean_floor << " m without\n";
    ASSERT_GE(with.count, 8);
    EXPECT_GT(with.mean_floor, 0.10) << "seed " << seed;
    EXPECT_LT(with.mean_floor, 0.20) << "seed " << seed;
    EXPECT_LT(without.mean_floor, 0.02) << "seed " << seed;
  }
}

TEST(KeyframeTangentialFloor, LowersTheYawErrorWithScatter) {
  double sum_floor = 0.0, sum_none = 0.0;
  // Registrations to one keyframe share its points' scatter: few independent samples per
  // drive, so 8 drives. Without scatter the yaw rms is 0.009-0.016 deg (the priors' errors);
  // with it 0.019-0.037 deg with the floor against 0.027-0.038 without (sums 0.79x).
  for (uint32_t seed = 3; seed <= 10; ++seed) {
    const Drive fl = drive(seed, 0.15, kTangentialFloor);
    const Drive none = drive(seed, 0.15, 0.0);
    std::cout << "[ info ] seed " << seed << ": yaw rms " << fl.yaw_rms / kDeg
              << " deg with the measured floor (" << fl.mean_floor << " m), "
              << none.yaw_rms / kDeg << " deg without, " << fl.count << " registrations\n";
    ASSERT_GE(fl.count, 20);
    sum_floor += fl.yaw_rms;
    sum_none += none.yaw_rms;
  }
  EXPECT_LT(sum_floor, 0.85 * sum_none);
}
