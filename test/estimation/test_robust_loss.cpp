// robust_loss: the Cauchy refit of `refined` against matches with a coherent error inside the
// inlier gate (a second return, a moving car), on a known constant body velocity; mc stays the
// paper's least squares.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "support/synthetic_scene.hpp"
#include "spinradar/estimation/mc_ransac.hpp"
#include "spinradar/estimation/refined_estimator.hpp"

using namespace spinradar;
using spinradar::testing::SceneOptions;
using spinradar::testing::SyntheticScene;

namespace {

constexpr double kDeg = M_PI / 180.0;
const Eigen::Vector3d kTruth(9.0, 0.0, 10.0 * kDeg);  // m/s, m/s, rad/s

struct Pair {
  FeatureFrame f1, f2;
  std::vector<Match> matches;
};

/// A pair of scans with small noise; every 4th match of the second scan is moved `shift` m
/// across the beam, counter-clockwise: inside the inlier gate (0.35 m plus a row across the
/// beam), so RANSAC keeps it, and all in one rotational sense, so it biases the yaw rate.
Pair makePair(uint32_t seed, double shift) {
  SceneOptions o;
  o.seed = seed;
  o.landmarks = 600;
  o.range_sigma = 0.04;
  o.azimuth_sigma = 0.001;
  SyntheticScene scene(o, {kTruth});
  Pair p;
  std::vector<int> id1, id2;
  p.f1 = scene.observe(0, &id1);
  p.f2 = scene.observe(1, &id2);
  p.matches = scene.matches(id1, id2, 0.0, nullptr);
  for (size_t i = 0; i < p.matches.size(); i += 4) {
    Keypoint& k = p.f2.keypoints[p.matches[i].i2];
    const double r = std::hypot(k.x, k.y);
    // REP 103 counter-clockwise tangent at (x, y): (-y, x) / r.
    const double tx = -k.y / r, ty = k.x / r;
    k.x += shift * tx;
    k.y += shift * ty;
  }
  return p;
}

/// Yaw-rate error (deg/s) of refined (or mc) with and without the robust loss.
double yawRateError(const Pair& p, bool refined, bool robust) {
  EstimatorConfig cfg;
  cfg.robust_loss = robust;
  MotionEstimate est;
  if (refined) {
    RefinedEstimator re(cfg);
    std::vector<Keypoint> c1, c2;
    EXPECT_TRUE(re.estimate(p.f1, p.f2, p.matches, c1, c2, est));
  } else {
    McRansac mc(cfg);
    EXPECT_TRUE(mc.estimate(p.f1.keypoints, p.f2.keypoints, p.matches, p.f1.stamp_ns,
                            p.f2.stamp_ns, est));
  }
  return std::abs(est.velocity(2) - kTruth(2)) / kDeg;
}

}  // namespace

TEST(RobustLoss, CoherentErrorsInsideTheGateDoNotPullTheYaw) {
  for (uint32_t seed = 1; seed <= 3; ++seed) {
    const Pair p = makePair(seed, 0.25);
    ASSERT_GT(p.matches.size(), 300u);
    const double plain = yawRateError(p, true, false);
    const double robust = yawRateError(p, true, true);
    std::cout << "[ info ] refined seed " << seed << ": yaw-rate error plain " << plain
              << " deg/s, Cauchy " << robust << "\n";
    // The shifted quarter biased plain least squares by about a quarter of its mean angular
    // offset (0.38-0.48 deg/s) under the paper's weights; the Cauchy weights, scaled by the
    // median residual, took off about 40 % of it (0.22-0.27). With the tangential noise floor
    // (kTangentialFloor, issue 19) the near matches no longer carry the yaw and the plain
    // refit is already there (0.23 deg/s); the Cauchy weights still take off 3-9 % (0.21-0.23)
    // (Cauchy weights never reach zero: 25 % of coherent errors still pull).
    EXPECT_GT(plain, 0.15) << "the planted error must bias plain least squares";
    EXPECT_LT(robust, plain);
    EXPECT_LT(robust, 0.27);
  }
}

TEST(RobustLoss, McStaysThePapersLeastSquares) {
  const Pair p = makePair(2, 0.25);
  EXPECT_DOUBLE_EQ(yawRateError(p, false, true), yawRateError(p, false, false));
}

TEST(RobustLoss, CleanMatchesGiveThePlainSolution) {
  for (uint32_t seed : {5u, 6u}) {
    const Pair p = makePair(seed, 0.0);
    EXPECT_LT(yawRateError(p, true, false), 0.05);
    EXPECT_LT(yawRateError(p, true, true), 0.05);
  }
}

TEST(RobustLoss, QuantizedRowsInASteadyTurn) {
  // Row keypoints (azimuth and time of their row) turning at 0.625 rad/s: the rounding of the
  // far matches is correlated, which biased a Cauchy refit of mc by 2-3 % (see
  // cauchy_weights.hpp). refined starts from mc's inliers and keeps its Doppler and prior;
  // its yaw rate must stay right to 0.5 %.
  for (double w : {0.625, -0.625}) {
    SceneOptions o;
    o.seed = 5;
    o.landmarks = 800;
    o.quantize_azimuth = true;
    SyntheticScene scene(o, {Eigen::Vector3d(5.0, 0.0, w)});
    RefinedEstimator re;
    std::vector<Keypoint> c1, c2;
    std::vector<int> id1, id2;
    FeatureFrame f1 = scene.observe(0, &id1);
    double sum_w = 0.0;
    const int pairs = 6;
    for (int k = 1; k <= pairs; ++k) {
      FeatureFrame f2 = scene.observe(k, &id2);
      MotionEstimate est;
      ASSERT_TRUE(re.estimate(f1, f2, scene.matches(id1, id2, 0.0), c1, c2, est));
      sum_w += est.velocity(2) / pairs;
      f1 = std::move(f2);
      id1.swap(id2);
    }
    std::cout << "[ info ] refined, row keypoints, yaw rate " << w << " rad/s: estimated "
              << sum_w / w << " of it\n";
    EXPECT_NEAR(sum_w / w, 1.0, 0.005) << "yaw rate " << w;
  }
}
