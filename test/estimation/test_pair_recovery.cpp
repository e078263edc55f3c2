// Frame-to-frame recovery without descriptors (pair_recovery.hpp) against known truth on
// synthetic scans: a turn too fast for the descriptors, a scene the map does not share, and
// the refined chain through a U-turn whose scans match nothing by descriptor.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <iostream>

#include "support/synthetic_scene.hpp"
#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/odometry.hpp"
#include "spinradar/estimation/pair_recovery.hpp"

using namespace spinradar;
using spinradar::testing::SceneOptions;
using spinradar::testing::SyntheticScene;

namespace {

constexpr double kDeg = M_PI / 180.0;

SceneOptions options(uint32_t seed) { return spinradar::testing::clutteredDopplerScene(seed); }

/// 8 m/s, slowing to 3 m/s, a U-turn at 1.5 rad/s over scans 12-19 (about 170 deg), back up
/// to 8 m/s: a velocity per scan.
std::vector<Eigen::Vector3d> uTurnDrive() {
  std::vector<Eigen::Vector3d> v;
  for (int k = 0; k < 10; ++k) v.emplace_back(8.0, 0.0, 0.0);
  for (int k = 0; k < 2; ++k) v.emplace_back(3.0, 0.0, 0.0);
  for (int k = 0; k < 8; ++k) v.emplace_back(3.0, 0.0, 1.5);
  for (int k = 0; k < 12; ++k) v.emplace_back(std::min(8.0, 3.0 + 0.5 * k), 0.0, 0.0);
  return v;
}

EstimatorConfig config() {
  EstimatorConfig c;
  c.beta = 0.049;
  return c;
}

}  // namespace

TEST(PairRecovery, FindsAFastTurnFromTheStraightVelocity) {
  // 3 m/s at 1.5 rad/s (a U-turn of radius 2 m): 21 deg per scan. The guess and the map's
  // velocity are the straight drive before it (yaw rate 0), 21 deg and 1.5 rad/s off.
  for (const uint32_t seed : {1u, 2u, 3u}) {
    const Eigen::Vector3d truth(3.0, 0.0, 1.5);
    SyntheticScene scene(options(seed), {truth});
    const FeatureFrame f1 = scene.observe(0), f2 = scene.observe(1);
    PairRecovery rec(config());
    MotionEstimate m;
    ASSERT_TRUE(rec.estimate(f1, f2, Eigen::Vector3d(3.0, 0.0, 0.0), m))
        << "seed " << seed;
    const Eigen::Vector3d step_err = se2::log(se2::inverse(scene.relative(0, 1)) * m.T_12);
    std::cout << "[ info ] seed " << seed << ": velocity " << m.velocity.transpose()
              << ", step yaw error " << step_err(2) / kDeg << " deg, " << rec.lastInliers()
              << " inliers\n";
    EXPECT_NEAR(m.velocity(2), truth(2), 0.01) << "seed " << seed;
    EXPECT_NEAR(m.velocity(0), truth(0), 0.1) << "seed " << seed;
    EXPECT_LT(std::abs(step_err(2)), 0.1 * kDeg) << "seed " << seed;
    EXPECT_LT(step_err.head<2>().norm(), 0.05) << "seed " << seed;
    // The covariance covers the error (3 sigma on the yaw rate).
    EXPECT_LT(std::abs(m.velocity(2) - truth(2)), 3.0 * std::sqrt(m.velocity_cov(2, 2)) + 1e-3);
  }
}

TEST(PairRecovery, RefusesAScanOfAnotherPlace) {
  SyntheticScene a(options(4), {Eigen::Vector3d(5.0, 0.0, 0.0)});
  SyntheticScene b(options(5), {Eigen::Vector3d(5.0, 0.0, 0.0)});
  const FeatureFrame f1 = a.observe(0), f2 = b.observe(1);
  PairRecovery rec(config());
  MotionEstimate m;
  EXPECT_FALSE(rec.estimate(f1, f2, Eigen::Vector3d(5.0, 0.0, 0.0), m));
  EXPECT_FALSE(m.ok);
}

namespace {

struct UTurnResult {
  double yaw_err = 0.0, pos_err = 0.0, length = 0.0;  ///< final errors (rad, m), path (m)
};

/// The chain `estimator` through uTurnDrive(), `corrupt(k, frame)` applied to each scan's
/// features before it is processed.
UTurnResult runUTurn(const std::string& estimator,
                     const std::function<void(int, FeatureFrame&)>& corrupt) {
  const std::vector<Eigen::Vector3d> v = uTurnDrive();
  SyntheticScene scene(options(9), v);
  PipelineConfig cfg;
  cfg.estimator.estimator = estimator;
  cfg.estimator.beta = scene.options().beta;
  Odometry odo(cfg);
  UTurnResult out;
  for (int k = 0; k < static_cast<int>(v.size()); ++k) {
    FeatureFrame f = scene.observe(k);
    corrupt(k, f);
    const OdometryResult res = odo.process(f);
    const Eigen::Matrix3d truth = scene.pose(scene.scanStart(k));
    if (k > 0) out.length += (truth.topRightCorner<2, 1>() -
                              scene.pose(scene.scanStart(k - 1)).topRightCorner<2, 1>()).norm();
    out.yaw_err = std::abs(se2::log(se2::inverse(truth) * res.T_world_sensor)(2));
    out.pos_err = (res.T_world_sensor.topRightCorner<2, 1>() - truth.topRightCorner<2, 1>()).norm();
  }
  std::cout << "[ info ] " << estimator << ": final yaw error " << out.yaw_err / kDeg
            << " deg, position error " << out.pos_err << " m over " << out.length << " m\n";
  return out;
}

}  // namespace

TEST(PairRecovery, RefinedChainHoldsAUTurnWhoseScansMatchNothing) {
  // 8 m/s, slowing to 3 m/s, a U-turn at 1.5 rad/s (about 170 deg), back up to 8 m/s. The
  // turn's scans carry one descriptor for every keypoint (the ratio test passes none): no
  // pair from the turn's entry to its exit matches by descriptor, as upright ORB beyond
  // ~15 deg per scan. Before the recovery the chain predicted with the straight velocity
  // and came out of the turn 87-91 deg off (refined, keyframe); with it about 0.3 / 0.03 deg.
  for (const std::string estimator : {"refined", "keyframe"}) {
    const UTurnResult r = runUTurn(estimator, [](int k, FeatureFrame& f) {
      if (k >= 12 && k < 20)
        for (int i = 1; i < f.descriptors.rows; ++i) f.descriptors.row(0).copyTo(f.descriptors.row(i));
    });
    EXPECT_LT(r.yaw_err, 0.5 * kDeg) << estimator;
    EXPECT_LT(r.pos_err / r.length, estimator == "keyframe" ? 0.005 : 0.02) << estimator;
  }
}

TEST(PairRecovery, AFewChanceMatchesAreNoRegistration) {
  // The U-turn above, but inside the turn four keypoints per scan keep matching by
  // descriptor, placed as a straight drive at 3 m/s would move them: MC-RANSAC "registers"
  // each turn pair on those 4 matches at zero yaw rate (at the simulator's eased U-turn it
  // returned 9 deg for 21 on 3 inliers). With fewer than kMinPairInliers inliers the pair is
  // re-registered by the recovery; without that rule the chain came out of the turn 157 deg
  // off.
  static_assert(PairRecovery::kMinPairInliers > 4, "the test's chance matches must count as none");
  const Eigen::Vector2d fake[4] = {{25.0, 10.0}, {-20.0, 30.0}, {-30.0, -15.0}, {15.0, -35.0}};
  for (const std::string estimator : {"refined", "keyframe"}) {
    const UTurnResult r = runUTurn(estimator, [&](int k, FeatureFrame& f) {
      if (k < 12 || k >= 20) return;
      ASSERT_GT(f.keypoints.size(), 4u);
      f.descriptors.setTo(cv::Scalar(0x55));  // one descriptor for all: the ratio test passes none
      for (int i = 0; i < 4; ++i) {
        f.descriptors.row(i).setTo(cv::Scalar(17 * (i + 1)));  // ... but these four
        Keypoint& kp = f.keypoints[i];
        kp.x = fake[i].x() - 0.75 * (k - 12);  // a straight drive: 0.75 m per scan
        kp.y = fake[i].y();
        kp.range = std::hypot(kp.x, kp.y);
        kp.azimuth = std::atan2(-kp.y, kp.x);
        if (kp.azimuth < 0) kp.azimuth += 2.0 * M_PI;
      }
    });
    EXPECT_LT(r.yaw_err, 0.5 * kDeg) << estimator;
  }
}
