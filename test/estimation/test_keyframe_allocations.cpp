// Hot-path check for the keyframe estimator: once warmed up (keyframe taken, buffers grown),
// a scan through Odometry::process(FeatureFrame) does not allocate beyond its returned result,
// and none at all when the result is written into one kept across scans (as the CLI does).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <iostream>
#include <new>

#include "support/count_allocations.hpp"
#include "support/synthetic_scene.hpp"
#include "spinradar/estimation/odometry.hpp"

using namespace spinradar;

namespace {

// 2.5 m per scan, a new keyframe every 5 scans. The default keyframe_graph (6) keeps the last
// 5 keyframes before the current one in a ring whose buffers grow over the first switches, so
// warm-up takes in the window filled (8 switches) before anything is counted.
constexpr int kWarmUp = 40, kCounted = 8;

std::vector<FeatureFrame> simulatedSequence() {
  spinradar::testing::SceneOptions o;
  o.landmarks = 900;
  o.range_sigma = 0.03;
  o.azimuth_sigma = 0.001;
  o.beta = 0.049;
  spinradar::testing::SyntheticScene scene(o, {Eigen::Vector3d(10.0, 0.0, 0.2)});
  std::vector<FeatureFrame> frames;
  for (int k = 0; k < kWarmUp + kCounted; ++k) frames.push_back(scene.observe(k));
  return frames;
}

}  // namespace

TEST(KeyframeAllocations, NoneAfterWarmUp) {
  const std::vector<FeatureFrame> frames = simulatedSequence();
  auto perScan = [&](const char* estimator, bool graph_step = false) {
    PipelineConfig cfg;
    cfg.estimator.estimator = estimator;
    cfg.estimator.keyframe_graph_step = graph_step;
    Odometry odo(cfg);
    for (int k = 0; k < kWarmUp; ++k) EXPECT_EQ(odo.process(frames[k]).ok, k > 0);
    const long before = g_allocations;
    for (int k = kWarmUp; k < kWarmUp + kCounted; ++k)
      EXPECT_TRUE(odo.process(frames[k]).ok);  // one or two more switches
    return g_allocations - before;
  };
  // Odometry::process returns an OdometryResult by value (its inlier vector allocates):
  // the keyframe estimator (matching against the keyframe, registration, new keyframes)
  // must not add any allocation to what refined needs.
  const long refined = perScan("refined"), keyframe = perScan("keyframe"),
             surface = perScan("surface"), keyframe_step = perScan("keyframe", true);
  std::cout << "[ info ] allocations over " << kCounted << " scans: refined " << refined << ", keyframe " << keyframe
            << ", surface " << surface << ", keyframe with keyframe_graph_step " << keyframe_step << "\n";
  EXPECT_LE(keyframe, refined);
  EXPECT_LE(keyframe_step, refined);
  EXPECT_LE(surface, refined);  // surface points, submap and its index reuse their buffers
}

// The odometry loop's way (cmd_odometry.cpp): one OdometryResult written every scan. Warm-up
// is one pass over the sequence (its buffers grow to the sequence's largest scan, keyframe
// and inlier set); after reset() a second pass over the same scans, keyframe switches
// included, makes no allocation at all: matching, the refined pair, registration to the
// keyframe, new keyframes and the result's inliers all reuse their buffers. (With a fresh
// result per scan: one allocation per scan, McRansac's inliers.)
TEST(KeyframeAllocations, NoneIntoAKeptResult) {
  const std::vector<FeatureFrame> frames = simulatedSequence();
  auto secondPass = [&](const char* estimator) {
    PipelineConfig cfg;
    cfg.estimator.estimator = estimator;
    Odometry odo(cfg);
    OdometryResult r;
    std::vector<OdometryResult> first;
    for (const FeatureFrame& f : frames) {
      odo.process(f, {}, r);
      first.push_back(r);
    }
    odo.reset();
    long allocations = 0;
    for (size_t k = 0; k < frames.size(); ++k) {
      const long before = g_allocations;
      odo.process(frames[k], {}, r);
      allocations += g_allocations - before;
      // Same outcome as the first pass (the reused buffers carry nothing over).
      EXPECT_EQ(r.ok, k > 0);
      EXPECT_EQ(r.T_world_sensor, first[k].T_world_sensor) << k;
      EXPECT_EQ(r.motion.inliers, first[k].motion.inliers) << k;
      if (k > 0) {
        EXPECT_GT(r.motion.inliers.size(), 100u);  // filled, not left empty
      }
    }
    return allocations;
  };
  const PipelineConfig defaults;
  ASSERT_EQ(defaults.estimator.estimator, "keyframe");  // the default is the one checked
  EXPECT_EQ(secondPass("keyframe"), 0);
  EXPECT_EQ(secondPass("refined"), 0);
}
