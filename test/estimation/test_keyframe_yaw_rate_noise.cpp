// A registration's own yaw rate and the published pose (issue 19). Each scan is solved at
// mid-scan and its published scan-start pose worked back over half a rotation with a yaw
// rate: the pair velocity's, or the registration's own where the two differ by over
// kRegisteredYawRateGap (0.05 rad/s; a yaw-rate step inside the scan shows there first).
// Within one scan the yaw rate trades against the yaw, so where the returns scatter across
// the beam (real RADIATE scans: tangential floor 0.04-0.2 m, azimuth jitter 0.29 deg) the
// registration measures it to 0.02-0.07 rad/s (its covariance): 0.079 rad/s off the pair's
// there (2.2 sigma) moved one published yaw by 0.57 deg (RADIATE consistency, skip run 1,
// scan 12). yaw_rate_sigmas: the difference must also be that many of its standard
// deviations. Known truth: a synthetic drive at 2 Hz (a 4 Hz
// sensor read every other scan, as the consistency column's direct runs) with returns
// scattered 0.35 m across the beam and an honest frame-to-frame prior; the published step
// yaw errors against the truth, with and without the test. And a yaw-rate step inside a
// scan (clean returns), where the registration's own rate must still win.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>

#include "support/laid_out_keyframes.hpp"
#include "support/synthetic_scene.hpp"
#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/keyframe_tracker.hpp"

using namespace spinradar;
using spinradar::testing::SceneOptions;
using spinradar::testing::SyntheticScene;

namespace {

constexpr double kDeg = M_PI / 180.0;
const double kDefault = EstimatorConfig{}.yaw_rate_sigmas;  ///< the test as shipped

struct Result {
  double step_yaw_rms = 0.0;  ///< rad, published step k-stride -> k against the truth
  double worst_step_yaw = 0.0;
};

/// `scans` scans (every `stride`-th of a 4 Hz sensor) with body velocities `vel` (per 0.25 s
/// rotation), returns scattered `tangential` m across the beam plus `azimuth` rad; the prior
/// is the true step and velocity with Gaussian errors of the covariance it states.
Result drive(uint32_t seed, double yaw_rate_sigmas, double tangential, double azimuth,
             int landmarks, const std::vector<Eigen::Vector3d>& vel, int stride, int scans) {
  SceneOptions o;
  o.landmarks = landmarks;
  o.min_range = 4.0;
  o.max_range = 120.0;
  o.visible_range = 100.0;
  o.range_sigma = 0.05;
  o.azimuth_sigma = azimuth;
  o.tangential_sigma = tangential;
  o.clutter = 50;
  o.seed = seed;
  SyntheticScene scene(o, vel);
  EstimatorConfig cfg;
  cfg.beta = 0.0;
  cfg.yaw_rate_sigmas = yaw_rate_sigmas;
  // As this drive was laid out (support/laid_out_keyframes.hpp).
  cfg.keyframe_distance = spinradar::testing::kLaidOutKeyframeDistance;
  // Measured without the turn-heading blend (start_rate_pair_weight, default 0.25 since the
  // twentieth round): it mixes this harness's noisy pair step into the scans after turn
  // switches in every arm alike; its own test is KeyframeStartRate.
  cfg.start_rate_pair_weight = 0.0;
  KeyframeTracker kt(cfg);
  std::mt19937 rng(seed + 11);
  std::normal_distribution<double> n(0.0, 1.0);
  const double sxy = 0.03, syaw = 0.1 * kDeg, sv = 0.03, sw = 0.003;
  Eigen::Matrix3d T_w = Eigen::Matrix3d::Identity(), P = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d prev_est = T_w;
  double sum2 = 0.0;
  Result res;
  for (int i = 0; i < scans; ++i) {
    const int k = i * stride;
    MotionEstimate pair;
    pair.ok = true;
    pair.T_12 = Eigen::Matrix3d::Identity();
    if (i > 0)
      pair.T_12 = scene.relative(k - stride, k) *
                  se2::exp(Eigen::Vector3d(sxy * n(rng), sxy * n(rng), syaw * n(rng)));
    pair.T_12_cov = Eigen::Vector3d(sxy * sxy, sxy * sxy, syaw * syaw).asDiagonal();
    // The pair velocity of the step ending at this scan: the truth over its last rotation.
    const Eigen::Vector3d v = scene.velocityAt(scene.scanStart(k) - 0.125);
    pair.velocity = v + Eigen::Vector3d(sv * n(rng), sv * n(rng), sw * n(rng));
    pair.velocity_cov = Eigen::Vector3d(sv * sv, sv * sv, sw * sw).asDiagonal();
    const Eigen::Matrix3d T_prev = T_w, P_prev = P;
    kt.track(scene.observe(k), T_prev, P_prev, 0.8, pair, T_w, P);
    if (i > 0) {
      const Eigen::Matrix3d step = se2::inverse(prev_est) * T_w;
      const double e = se2::log(se2::inverse(scene.relative(k - stride, k)) * step)(2);
      sum2 += e * e;
      res.worst_step_yaw = std::max(res.worst_step_yaw, std::abs(e));
    }
    prev_est = T_w;
  }
  res.step_yaw_rms = std::sqrt(sum2 / (scans - 1));
  return res;
}

}  // namespace

TEST(KeyframeYawRateNoise, ScatteredReturnsKeepThePairYawRateInThePublishedPose) {
  // 6 m/s on a 40 m circle (0.15 rad/s), every other scan, 0.2 m across the beam.
  const std::vector<Eigen::Vector3d> circle{Eigen::Vector3d(6.0, 0.0, 0.15)};
  double sum_off = 0.0, sum_on = 0.0, worst_off = 0.0, worst_on = 0.0;
  int lower = 0, seeds = 0;
  for (uint32_t seed = 1; seed <= 5; ++seed, ++seeds) {
    const Result off = drive(seed, 0.0, 0.35, 0.005, 150, circle, 2, 60);
    const Result on = drive(seed, kDefault, 0.35, 0.005, 150, circle, 2, 60);
    std::cout << "[ info ] seed " << seed << ", published step yaw error rms / worst deg: "
              << off.step_yaw_rms / kDeg << " / " << off.worst_step_yaw / kDeg
              << " (0.05 rad/s only) -> " << on.step_yaw_rms / kDeg << " / "
              << on.worst_step_yaw / kDeg << " (and " << kDefault << " sigma)\n";
    sum_off += off.step_yaw_rms;
    sum_on += on.step_yaw_rms;
    worst_off += off.worst_step_yaw;
    worst_on += on.worst_step_yaw;
    lower += on.step_yaw_rms <= off.step_yaw_rms;
  }
  // Measured (4 sigma): summed rms 1.089 -> 0.922 deg, summed worst step 3.53 -> 2.53 deg;
  // no seed worse.
  EXPECT_EQ(lower, seeds);
  EXPECT_LT(sum_on, 0.92 * sum_off);
  EXPECT_LT(worst_on, 0.85 * worst_off);
}

TEST(KeyframeYawRateNoise, AYawRateStepInsideAScanStillUsesTheRegisteredRate) {
  // Clean returns, every scan: straight at 5 m/s, then the yaw rate steps to 0.625 rad/s at
  // scan 10 (the city route's turn entry); the pair velocity lags it by a scan, which the
  // registration's own rate must overrule with or without the test.
  std::vector<Eigen::Vector3d> v;
  for (int k = 0; k < 24; ++k) v.emplace_back(5.0, 0.0, k < 10 ? 0.0 : 0.625);
  for (uint32_t seed = 1; seed <= 3; ++seed) {
    const Result off = drive(seed, 0.0, 0.0, 0.001, 800, v, 1, 24);
    const Result on = drive(seed, kDefault, 0.0, 0.001, 800, v, 1, 24);
    // Never the registration's own rate (a test far beyond any difference): the step shows.
    const Result never = drive(seed, 1e9, 0.0, 0.001, 800, v, 1, 24);
    std::cout << "[ info ] seed " << seed << ", turn entry, worst published step yaw error deg: "
              << off.worst_step_yaw / kDeg << " -> " << on.worst_step_yaw / kDeg
              << " (never the registered rate: " << never.worst_step_yaw / kDeg << ")\n";
    EXPECT_GT(never.worst_step_yaw, 2.0 * kDeg) << "seed " << seed;  // measured 4.5 deg
    EXPECT_NEAR(on.worst_step_yaw, off.worst_step_yaw, 0.02 * kDeg) << "seed " << seed;
  }
}
