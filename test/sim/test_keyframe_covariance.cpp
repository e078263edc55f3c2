// The keyframe estimator's accumulated-pose covariance against the simulator's truth, on a
// drive of sustained turns and on a city drive (issue 19), with azimuth peaks (the default)
// and row keypoints. The band is two-sided: the mean NEES over [x, y, yaw] (expected 3) must
// stay below the over-confident side (before the mid-scan chain with the estimate's own error,
// tight_turns was 6-10, city_narrow 9.3) and above the cautious side (one chi2/dof for both
// residual directions and a white-noise velocity lag left azimuth peaks at 1.5-1.6).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>

#include <Eigen/Cholesky>

#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/odometry.hpp"
#include "spinradar/sim/scenes.hpp"
#include "spinradar/sim/simulator.hpp"

using namespace spinradar;

namespace {

struct Nees {
  double mean = 0.0, covered = 0.0, yaw_err_deg = 0.0;
};

/// Default pipeline (keyframe; azimuth peaks, or row keypoints with peaks = false), full
/// physics, `scans` scans of a built-in scene: the accumulated pose (relative to the first
/// scan) against the truth.
Nees accumulatedNees(const std::string& scene, uint64_t variant, int scans, bool peaks) {
  sim::PhysicsConfig physics;
  physics.motion_distortion = true;
  physics.doppler = 0.049;
  physics.moving_objects = true;
  const sim::Scene sc = sim::builtinScene(scene, variant);
  const sim::Simulator s(sc.world, sc.trajectory, sim::SensorConfig{}, physics, 1);
  PipelineConfig cfg;
  cfg.detector.azimuth_peaks = peaks;
  Odometry odo(cfg);
  Eigen::Matrix3d T0 = Eigen::Matrix3d::Identity();
  Nees r;
  int n = 0;
  for (int k = 0; k < scans; ++k) {
    const OdometryResult res = odo.process(s.renderScan(k));
    const sim::Pose2 p = sc.trajectory.at(1e-9 * static_cast<double>(res.stamp_ns));
    const Eigen::Matrix3d T = se2::fromXyYaw(Eigen::Vector3d(p.x, p.y, p.yaw));
    if (k == 0) {
      T0 = T;
      continue;
    }
    if (!res.ok) continue;
    Eigen::Vector3d e = se2::toXyYaw(res.T_world_sensor) - se2::toXyYaw(se2::inverse(T0) * T);
    e(2) = std::remainder(e(2), 2 * M_PI);
    const double nees = e.dot(res.pose_cov.ldlt().solve(e));
    r.mean += nees;
    r.covered += nees < 7.815;  // chi2, 3 dof, 95 %
    r.yaw_err_deg = e(2) * 180.0 / M_PI;
    ++n;
  }
  EXPECT_GT(n, scans / 2) << scene;
  r.mean /= n;
  r.covered /= n;
  std::cout << "[ info ] " << scene << " layout " << variant << (peaks ? ", peaks" : ", rows")
            << ", " << scans
            << " scans: accumulated-pose NEES mean " << r.mean << " (expected 3), inside the 95 % bound "
            << 100.0 * r.covered << " %, final yaw error " << r.yaw_err_deg << " deg\n";
  return r;
}

}  // namespace

// The band is [2, 4.5] for both front ends. Before the residual scales per direction and the
// velocity prior's lag error from the seen acceleration (keyframe_tracker.cpp, solve()),
// azimuth peaks came out cautious: 1.50 (tight_turns) / 1.58 (city), row keypoints 1.52 /
// 2.79; now 3.18 / 2.66 and 2.43 / 3.31.
constexpr double kNeesLow = 2.0, kNeesHigh = 4.5;

TEST(KeyframeCovariance, HonestInSustainedTurns) {
  // tight_turns: slalom, two loops, a hairpin (~1500 deg of turning in 240 scans).
  for (bool peaks : {true, false}) {
    const Nees r = accumulatedNees("tight_turns", 0, 240, peaks);
    EXPECT_LT(r.mean, kNeesHigh) << (peaks ? "peaks" : "rows");  // not over-confident
    EXPECT_GT(r.mean, kNeesLow) << (peaks ? "peaks" : "rows");   // not cautious
    EXPECT_GT(r.covered, 0.85);
  }
}

TEST(KeyframeCovariance, HonestOnACityDrive) {
  // City layout 2: long straights between right-angle turns (~600 m in 240 scans).
  for (bool peaks : {true, false}) {
    const Nees r = accumulatedNees("city", 2, 240, peaks);
    EXPECT_LT(r.mean, kNeesHigh) << (peaks ? "peaks" : "rows");
    EXPECT_GT(r.mean, kNeesLow) << (peaks ? "peaks" : "rows");
    // Peaks: 78 % since weak registrations become keyframes (issue 19, sixth round): their
    // errors are heavier-tailed than the Gaussian the bound assumes.
    EXPECT_GT(r.covered, 0.75);
  }
}
