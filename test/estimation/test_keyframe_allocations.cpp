// Hot-path check for the keyframe estimator: once warmed up (keyframe taken, buffers grown),
// a scan through Odometry::process(FeatureFrame) does not allocate.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <iostream>
#include <new>

#include "support/count_allocations.hpp"
#include "support/synthetic_scene.hpp"
#include "spinradar/estimation/odometry.hpp"

using namespace spinradar;

TEST(KeyframeAllocations, NoneAfterWarmUp) {
  spinradar::testing::SceneOptions o;
  o.landmarks = 900;
  o.range_sigma = 0.03;
  o.azimuth_sigma = 0.001;
  o.beta = 0.049;
  spinradar::testing::SyntheticScene scene(o, {Eigen::Vector3d(10.0, 0.0, 0.2)});
  std::vector<FeatureFrame> frames;
  for (int k = 0; k < 16; ++k) frames.push_back(scene.observe(k));
  auto perScan = [&](const char* estimator) {
    PipelineConfig cfg;
    cfg.estimator.estimator = estimator;
    Odometry odo(cfg);
    // Warm-up: 2.5 m per scan, a new keyframe every 5 scans (scans 1, 6, 11).
    for (int k = 0; k < 8; ++k) EXPECT_EQ(odo.process(frames[k]).ok, k > 0);
    const long before = g_allocations;
    for (int k = 8; k < 16; ++k) EXPECT_TRUE(odo.process(frames[k]).ok);  // one more switch
    return g_allocations - before;
  };
  // Odometry::process returns an OdometryResult by value (its inlier vector allocates):
  // the keyframe estimator (matching against the keyframe, registration, new keyframes)
  // must not add any allocation to what refined needs.
  const long refined = perScan("refined"), keyframe = perScan("keyframe"),
             surface = perScan("surface");
  std::cout << "[ info ] allocations over 8 scans: refined " << refined << ", keyframe " << keyframe
            << ", surface " << surface << "\n";
  EXPECT_LE(keyframe, refined);
  EXPECT_LE(surface, refined);  // surface points, submap and its index reuse their buffers
}
