// The keyframe estimator at yaw-rate changes (issue 19), against the synthetic scene's
// truth: a keyframe taken in a ramp must not hand a velocity error of its map on to the
// scans and keyframes after it (KeyframeTracker::key_ramp_), and a scan whose descriptors
// match nothing must not become the keyframe at the lagging prediction when its points can
// register it (the last-resort proximity ICP, KeyframeTracker::kLastResortChi2).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>
#include <vector>

#include "support/synthetic_scene.hpp"
#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/keyframe_tracker.hpp"
#include "spinradar/estimation/odometry.hpp"

using namespace spinradar;
using spinradar::testing::SceneOptions;
using spinradar::testing::SyntheticScene;

namespace {

constexpr double kDeg = M_PI / 180.0;

struct Errors {
  double worst_after = 0.0;  ///< rad, worst |yaw error| from scan `after` on
  double final_yaw = 0.0;    ///< rad
};

/// Runs keyframe odometry; `scramble` (if >= 0): that scan's descriptors are replaced by
/// random bits (nothing matches by descriptor, the points are unchanged).
Errors drive(uint32_t seed, const std::vector<Eigen::Vector3d>& v, int after, int scramble) {
  SceneOptions o = spinradar::testing::clutteredDopplerScene(seed);
  o.velocity_shift = 0.3 * o.period;
  SyntheticScene scene(o, v);
  PipelineConfig cfg;
  cfg.estimator.estimator = "keyframe";
  cfg.estimator.beta = o.beta;
  Odometry odo(cfg);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> byte(0, 255);
  Errors r;
  const int n = static_cast<int>(v.size());
  for (int k = 0; k < n; ++k) {
    FeatureFrame f = scene.observe(k);
    if (k == scramble)
      for (int i = 0; i < f.descriptors.rows; ++i)
        for (int j = 0; j < f.descriptors.cols; ++j)
          f.descriptors.at<uint8_t>(i, j) = static_cast<uint8_t>(byte(rng));
    const OdometryResult res = odo.process(f);
    if (k == 0) continue;
    EXPECT_TRUE(res.ok) << "scan " << k;
    const Eigen::Matrix3d truth = scene.pose(scene.scanStart(k));
    const double yaw_err = std::abs(se2::log(se2::inverse(truth) * res.T_world_sensor)(2));
    if (k >= after) r.worst_after = std::max(r.worst_after, yaw_err);
    r.final_yaw = yaw_err;
  }
  return r;
}

}  // namespace

TEST(KeyframeTurnExit, RampKeyframeDoesNotPassAVelocityErrorOn) {
  // A registration's yaw rate follows its keyframe map's (the map was moved to mid-scan with
  // the keyframe's velocity): a map moved with a yaw rate e off gives registered yaw rates e
  // off, over kRegisteredYawRateGap they move the scans' frames and the next keyframes' maps,
  // and the error is handed on from keyframe to keyframe (city_narrow layout 2: a turn-exit
  // keyframe at 0.07 rad/s against about 0.2, then -0.08..-0.16 rad/s registered on the
  // straight after it, truth and pair 0). Emulated with the tracker fed exact pairs (the
  // scene's velocity constant within each scan) except the first scan's velocity, e = 0.15
  // rad/s off: the first keyframe's map. 16 m/s, keyframes every third scan
  // (keyframe_distance); scan 9, a keyframe, is a ramp (0 -> 0.2 rad/s -> 0). The scans
  // registered to it are as far from the pair as it was, no change of the yaw rate, so from
  // there on the pair velocity moves them and the keyframes after it: the registered yaw
  // rate is back to the truth and the heading error stops growing (what the chain had
  // gathered until then stays). Before, the registered yaw rate grew 0.15 -> 0.21 rad/s over
  // the 20 scans and the heading error with it: 0.46 deg at scan 12, 0.77 deg at scan 19;
  // with it 0.88 and 0.88 deg.
  const double e = 0.15;
  std::vector<Eigen::Vector3d> v;
  for (int k = 0; k < 20; ++k) v.emplace_back(16.0, 0.0, k == 9 ? 0.2 : 0.0);
  SceneOptions o;
  o.landmarks = 1500;
  o.min_range = 5.0;
  o.max_range = 150.0;
  o.beta = 0.049;
  o.seed = 51;
  SyntheticScene scene(o, v);
  EstimatorConfig cfg;
  cfg.beta = o.beta;
  cfg.range_sigma = 0.02;
  cfg.azimuth_sigma = 0.001;
  KeyframeTracker kt(cfg);
  Eigen::Matrix3d T_w = Eigen::Matrix3d::Identity(), P = Eigen::Matrix3d::Zero();
  double before_ramp = 0.0, at12 = 0.0, at19 = 0.0;
  std::vector<int64_t> keys;
  for (int k = 0; k < 20; ++k) {
    const FeatureFrame f = scene.observe(k);
    MotionEstimate pair;
    pair.ok = true;
    pair.T_12 = k > 0 ? scene.relative(k - 1, k) : Eigen::Matrix3d::Identity();
    pair.T_12_cov = Eigen::Vector3d(0.01, 0.01, 3e-5).asDiagonal();
    pair.velocity = scene.velocityAt(scene.scanStart(k) + 0.5 * o.period);
    if (k == 0) pair.velocity(2) += e;
    pair.velocity_cov = Eigen::Vector3d(1e-4, 1e-4, 1e-6).asDiagonal();
    const Eigen::Matrix3d T_prev = T_w, P_prev = P;
    kt.track(f, T_prev, P_prev, 0.9, pair, T_w, P);
    if (keys.empty() || keys.back() != kt.keyframeStamp()) keys.push_back(kt.keyframeStamp());
    const Eigen::Matrix3d truth = scene.pose(scene.scanStart(k));
    const double yaw_err = std::abs(se2::log(se2::inverse(truth) * T_w)(2));
    if (k == 8) before_ramp = yaw_err;
    if (k == 12) at12 = yaw_err;
    if (k == 19) at19 = yaw_err;
  }
  std::cout << "[ info ] keyframes at scans";
  for (const int64_t t : keys) std::cout << ' ' << std::lround(1e-9 * (t - o.t0_ns) / o.period);
  std::cout << "; yaw error at scans 8 / 12 / 19: " << before_ramp / kDeg << " / " << at12 / kDeg
            << " / " << at19 / kDeg << " deg\n";
  ASSERT_GE(keys.size(), 5u);  // the setup: keyframe 9 as described
  EXPECT_EQ(std::lround(1e-9 * (keys[3] - o.t0_ns) / o.period), 9);
  EXPECT_GT(before_ramp, 0.2 * kDeg);  // the emulated error grows before the ramp
  EXPECT_LT(std::abs(at19 - at12), 0.05 * kDeg);  // and no longer after it
}

TEST(KeyframeTurnExit, FailedScanAtAYawRateStepIsRegisteredByProximity) {
  // 5 m/s; the yaw rate steps 0 -> 0.3 rad/s 30 % into scan 12 (a gentle turn entry: the
  // keyframe stays within kProximityMinAngle) and that scan's descriptors match nothing:
  // no descriptor or weak registration, no regular proximity fallback. Before the
  // last-resort proximity ICP it became the keyframe at the prediction (the pair step,
  // which lags the step), and so did the next scan (its descriptors match nothing in that
  // keyframe): their errors stayed in the chain. Worst yaw error from two scans after the
  // failed one: 0.119 / 0.063 / 0.122 deg before, 0.039 / 0.016 / 0.025 deg with it.
  for (const uint32_t seed : {41u, 42u, 43u}) {
    std::vector<Eigen::Vector3d> v;
    for (int k = 0; k < 24; ++k) v.emplace_back(5.0, 0.0, k >= 12 ? 0.3 : 0.0);
    const Errors e = drive(seed, v, 14, 12);
    std::cout << "[ info ] seed " << seed << ": worst yaw error after the failed scan "
              << e.worst_after / kDeg << " deg, final " << e.final_yaw / kDeg << " deg\n";
    EXPECT_LT(e.worst_after, 0.06 * kDeg) << "seed " << seed;
  }
}
