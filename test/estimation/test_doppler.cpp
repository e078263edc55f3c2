// Doppler range correction: sign conventions, removal of an injected beta*u shift, and the
// mc_doppler estimate -> correct -> re-estimate loop on a synthetic scan pair.
#include <gtest/gtest.h>

#include <iostream>

#include "support/synthetic_scene.hpp"
#include "spinradar/estimation/doppler.hpp"
#include "spinradar/core/lie.hpp"

using namespace spinradar;
using spinradar::testing::SceneOptions;
using spinradar::testing::SyntheticScene;

namespace {
constexpr double kBeta = 0.049;

Keypoint makeKeypoint(double r, double phi) {
  Keypoint k;
  k.range = r;
  k.azimuth = phi;
  k.x = r * std::cos(phi);
  k.y = -r * std::sin(phi);
  return k;
}
}  // namespace

TEST(Doppler, BeamVelocityFollowsRep103) {
  const Eigen::Vector3d forward(10.0, 0.0, 0.0), left(0.0, 3.0, 0.0);
  EXPECT_DOUBLE_EQ(beamVelocity(forward, 0.0), 10.0);          // target ahead: closing
  EXPECT_NEAR(beamVelocity(forward, M_PI), -10.0, 1e-12);      // target behind: receding
  // Clockwise azimuth pi/2 is the right-hand side (y < 0): moving left recedes from it.
  EXPECT_NEAR(beamVelocity(left, M_PI / 2), -3.0, 1e-12);
  EXPECT_NEAR(beamVelocity(left, 3 * M_PI / 2), 3.0, 1e-12);
}

TEST(Doppler, RemovesAnInjectedShift) {
  const Eigen::Vector3d v(12.0, -1.5, 0.2);
  std::vector<Keypoint> truth, measured;
  for (int i = 0; i < 400; ++i) {
    const double phi = i * 2 * M_PI / 400, r = 10.0 + 0.3 * i;
    truth.push_back(makeKeypoint(r, phi));
    // Apparent range = true range - beta u.
    measured.push_back(makeKeypoint(r - kBeta * beamVelocity(v, phi), phi));
  }
  double before = 0.0;
  for (size_t i = 0; i < truth.size(); ++i)
    before = std::max(before, std::abs(measured[i].range - truth[i].range));
  EXPECT_GT(before, 0.5);  // 0.049 s * 12.1 m/s
  dopplerCorrect(measured, v, kBeta);
  for (size_t i = 0; i < truth.size(); ++i) {
    EXPECT_NEAR(measured[i].range, truth[i].range, 1e-12);
    EXPECT_NEAR(measured[i].x, truth[i].x, 1e-12);
    EXPECT_NEAR(measured[i].y, truth[i].y, 1e-12);
  }
  // Copying form gives the same.
  std::vector<Keypoint> again;
  dopplerCorrect(measured, Eigen::Vector3d::Zero(), kBeta, again);
  EXPECT_EQ(again.size(), measured.size());
  EXPECT_DOUBLE_EQ(again[7].range, measured[7].range);
}

TEST(Doppler, McDopplerRecoversVelocityAndTrueRanges) {
  // Same scene twice (same seed): once with the Doppler shift injected, once without.
  const Eigen::Vector3d truth(15.0, 0.0, 15.0 * M_PI / 180.0);
  SceneOptions o;
  o.landmarks = 800;
  o.beta = kBeta;
  SyntheticScene shifted(o, {truth});
  o.beta = 0.0;
  SyntheticScene clean(o, {truth});
  std::vector<int> ids1, ids2;
  const FeatureFrame f1 = shifted.observe(0, &ids1), f2 = shifted.observe(1, &ids2);
  const FeatureFrame g1 = clean.observe(0), g2 = clean.observe(1);
  ASSERT_EQ(f1.keypoints.size(), g1.keypoints.size());
  const std::vector<Match> matches = shifted.matches(ids1, ids2, 0.3);

  McRansac mc;
  MotionEstimate est_mc, est_dopp;
  ASSERT_TRUE(mc.estimate(f1.keypoints, f2.keypoints, matches, f1.stamp_ns, f2.stamp_ns, est_mc));
  std::vector<Keypoint> c1, c2;
  ASSERT_TRUE(estimateMcDoppler(mc, f1.keypoints, f2.keypoints, matches, f1.stamp_ns,
                                f2.stamp_ns, kBeta, c1, c2, est_dopp));
  const double err_mc = (est_mc.velocity - truth).norm();
  const double err_dopp = (est_dopp.velocity - truth).norm();
  std::cout << "[ info ] velocity error with injected Doppler (beta 0.049, 15 m/s): MC " << err_mc
            << ", MC+Doppler " << err_dopp << "\n";
  EXPECT_LT(err_dopp, 1e-4);
  EXPECT_LE(err_dopp, err_mc + 1e-9);

  // Ranges after correction match the unshifted scene to within beta * velocity error.
  double worst_before = 0.0, worst_after = 0.0;
  for (size_t i = 0; i < c1.size(); ++i) {
    worst_before = std::max(worst_before, std::abs(f1.keypoints[i].range - g1.keypoints[i].range));
    worst_after = std::max(worst_after, std::abs(c1[i].range - g1.keypoints[i].range));
  }
  for (size_t i = 0; i < c2.size(); ++i)
    worst_after = std::max(worst_after, std::abs(c2[i].range - g2.keypoints[i].range));
  std::cout << "[ info ] worst range error: raw " << worst_before << " m, corrected " << worst_after << " m\n";
  EXPECT_GT(worst_before, 0.7);   // 0.049 s * 15 m/s = 0.735 m
  EXPECT_LT(worst_after, 1e-5);
}
