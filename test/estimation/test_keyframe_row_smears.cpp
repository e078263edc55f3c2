// Row keypoints (the detector without azimuth_peaks) put a return on every row its beam
// covers, each at the row's angle: a short arc of keypoints ~1 row apart along the
// rotation direction. Paired by proximity (the fallback when the descriptors fail against a
// keyframe turned away), arcs slide along arcs: a rotation about the sensor is nearly free,
// and one solve from the prediction keeps most of the prediction's yaw error (issue 19:
// tight_turns, 69 % of the prior's yaw error kept by those registrations, which carried 58
// of the 72 keyframe switches). Known truth here: a constant turn, true velocity, the
// prior's yaw off by 0.5 deg, descriptors that never match; the registration must find
// the truth.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>

#include "support/synthetic_scene.hpp"
#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/keyframe_tracker.hpp"

using namespace spinradar;
using spinradar::testing::SceneOptions;
using spinradar::testing::SyntheticScene;

namespace {

constexpr double kDeg = M_PI / 180.0;

/// Every keypoint becomes a row arc: the rows a-2 .. a+2 around its nearest row a, each at
/// the row's angle and time, same range; descriptors random (no descriptor match).
FeatureFrame rowSmears(const FeatureFrame& f, const SceneOptions& o, std::mt19937& rng) {
  FeatureFrame g;
  g.stamp_ns = f.stamp_ns;
  const double dphi = 2.0 * M_PI / o.azimuths;
  const int64_t row_ns = std::llround(1e9 * o.period / o.azimuths);
  for (const Keypoint& k : f.keypoints) {
    const int a = static_cast<int>(std::lround(k.azimuth / dphi));
    for (int d = -2; d <= 2; ++d) {
      const int r = a + d;
      if (r < 0 || r >= o.azimuths) continue;
      Keypoint s = k;
      s.azimuth = r * dphi;
      s.azimuth_index = r;
      s.x = k.range * std::cos(s.azimuth);
      s.y = -k.range * std::sin(s.azimuth);
      s.stamp_ns = f.stamp_ns + r * row_ns;
      g.keypoints.push_back(s);
    }
  }
  std::uniform_int_distribution<int> ub(0, 255);
  g.descriptors = cv::Mat(static_cast<int>(g.keypoints.size()), 32, CV_8U);
  for (int i = 0; i < g.descriptors.rows; ++i)
    for (int j = 0; j < 32; ++j) g.descriptors.at<uint8_t>(i, j) = static_cast<uint8_t>(ub(rng));
  return g;
}

}  // namespace

TEST(KeyframeRowSmears, ProximityRegistrationOverrulesAWrongPrior) {
  SceneOptions o;
  o.landmarks = 400;
  o.min_range = 8.0;
  o.max_range = 100.0;
  o.seed = 23;
  const int n = 12;
  std::vector<Eigen::Vector3d> v(n, Eigen::Vector3d(6.0, 0.0, 0.8));  // 0.2 rad per scan
  SyntheticScene scene(o, v);
  std::mt19937 rng(5);
  EstimatorConfig cfg;
  // Maps of one keyframe: the averaging of the default (submap_keyframes 2) is measured with
  // azimuth peaks; with row keypoints its nearest-point pairs mix the rows of one arc (here
  // worst 0.509 deg, mean -0.05: docs/sensor_columns/round19_map_rate_bias.md).
  cfg.submap_keyframes = 1;
  cfg.range_sigma = 0.02;
  cfg.azimuth_sigma = 0.002;
  KeyframeTracker kt(cfg);
  Eigen::Matrix3d T_w = Eigen::Matrix3d::Identity(), P = Eigen::Matrix3d::Zero();
  double worst = 0.0, sum = 0.0;
  int count = 0;
  for (int k = 0; k < n; ++k) {
    const FeatureFrame f = rowSmears(scene.observe(k), o, rng);
    MotionEstimate pair;
    pair.ok = true;
    const Eigen::Matrix3d off = se2::exp(Eigen::Vector3d(0.0, 0.0, 0.5 * kDeg));
    pair.T_12 = Eigen::Matrix3d::Identity();
    if (k > 0) pair.T_12 = scene.relative(k - 1, k) * off;
    pair.T_12_cov = Eigen::Vector3d(1e-4, 1e-4, std::pow(0.5 * kDeg, 2)).asDiagonal();
    pair.velocity = v[k];
    pair.velocity_cov = Eigen::Vector3d(1e-4, 1e-4, 1e-6).asDiagonal();
    const Eigen::Matrix3d T_prev = T_w, P_prev = P;
    kt.track(f, T_prev, P_prev, 0.8, pair, T_w, P);
    if (k == 0 || kt.keyframeStamp() == f.stamp_ns) continue;
    ASSERT_GE(kt.lastInliers(), KeyframeTracker::kMinInliers) << "scan " << k;
    const double tk = 1e-9 * static_cast<double>(kt.keyframeStamp() - o.t0_ns);
    const Eigen::Matrix3d truth = se2::inverse(scene.pose(tk)) * scene.pose(scene.scanStart(k));
    const double e = se2::log(se2::inverse(truth) * kt.relativePose())(2);
    worst = std::max(worst, std::abs(e));
    sum += e;
    ++count;
  }
  std::cout << "[ info ] " << count
            << " proximity registrations, prior off by 0.5 deg: mean yaw error "
            << sum / std::max(count, 1) / kDeg << " deg, worst " << worst / kDeg << " deg\n";
  // The prior's 0.5 deg must not survive on average (one solve from the prediction, before
  // issue 19: mean 0.61 deg, worst 0.92); single registrations scatter by a row's rounding.
  EXPECT_GE(count, 8);
  EXPECT_LT(std::abs(sum / count), 0.1 * kDeg);
  EXPECT_LT(worst, 0.5 * kDeg);
}
