// Hot-path check: once warmed up on a scan pair, the estimators, Doppler correction and
// undistortion do not allocate.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "support/count_allocations.hpp"
#include "support/synthetic_scene.hpp"
#include "spinradar/estimation/doppler.hpp"
#include "spinradar/estimation/mc_ransac.hpp"
#include "spinradar/estimation/refined_estimator.hpp"
#include "spinradar/estimation/rigid_ransac.hpp"
#include "spinradar/estimation/undistort.hpp"

using namespace spinradar;

TEST(EstimatorAllocations, NoneAfterWarmUp) {
  spinradar::testing::SceneOptions o;
  o.landmarks = 900;
  o.range_sigma = 0.04;
  o.azimuth_sigma = 0.001;
  o.beta = 0.049;
  spinradar::testing::SyntheticScene scene(o, {Eigen::Vector3d(10.0, 0.0, 0.3)});
  std::vector<int> id1, id2;
  const FeatureFrame f1 = scene.observe(0, &id1), f2 = scene.observe(1, &id2);
  const std::vector<Match> m = scene.matches(id1, id2, 0.3);

  McRansac mc;
  RigidRansac rigid;
  RefinedEstimator refined;
  MotionEstimate est;
  std::vector<Keypoint> c1, c2;
  std::vector<Eigen::Vector2d> pts;
  auto run = [&] {
    bool ok = rigid.estimate(f1.keypoints, f2.keypoints, m, f1.stamp_ns, f2.stamp_ns, est);
    ok &= mc.estimate(f1.keypoints, f2.keypoints, m, f1.stamp_ns, f2.stamp_ns, est);
    ok &= estimateMcDoppler(mc, f1.keypoints, f2.keypoints, m, f1.stamp_ns, f2.stamp_ns, 0.049,
                            c1, c2, est);
    ok &= refined.estimate(f1, f2, m, c1, c2, est);
    dopplerCorrect(f2.keypoints, est.velocity, 0.049, c2);
    undistortPoints(c2, est.velocity, f2.stamp_ns, pts);
    return ok;
  };
  ASSERT_TRUE(run());  // warm-up
  ASSERT_TRUE(run());
  const long before = g_allocations;
  ASSERT_TRUE(run());
  EXPECT_EQ(g_allocations - before, 0);
}
