// The keyframe estimator's accumulated-pose covariance against the simulator's truth, on a
// drive of sustained turns and on a city drive (issue 19). The band is two-sided: the mean
// NEES over [x, y, yaw] (expected 3) must stay below the over-confident side (before the
// mid-scan chain with the estimate's own error, tight_turns was 6-10, city_narrow 9.3) and
// above the cautious side (the scan-start chain counted every keyframe's extrapolation twice;
// white-noise accelerations made the synthetic drives' final pose 16x cautious).
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

// Azimuth peaks (the default front end) come out cautious, NEES 1.5-1.6: the solve's residual
// covariance is rescaled by one chi2/dof, and with sub-row azimuths the tangential residuals are
// smaller against azimuth_sigma (one row / sqrt(12)) than the radial ones against range_sigma,
// so one factor cannot shrink the tangential (yaw) part alone. The band's lower end for them is
// 1.0 (sigmas at most 1.7x too large) until the solve scales the two directions apart; row
// keypoints keep 1.5.
TEST(KeyframeCovariance, HonestInSustainedTurns) {
  // tight_turns: slalom, two loops, a hairpin (~1500 deg of turning in 240 scans).
  for (bool peaks : {true, false}) {
    const Nees r = accumulatedNees("tight_turns", 0, 240, peaks);
    EXPECT_LT(r.mean, 6.0);                  // not over-confident
    EXPECT_GT(r.mean, peaks ? 1.0 : 1.5);   // not cautious beyond use
    EXPECT_GT(r.covered, 0.85);
  }
}

TEST(KeyframeCovariance, HonestOnACityDrive) {
  // City layout 2: long straights between right-angle turns (~600 m in 240 scans).
  for (bool peaks : {true, false}) {
    const Nees r = accumulatedNees("city", 2, 240, peaks);
    EXPECT_LT(r.mean, 6.0);
    EXPECT_GT(r.mean, peaks ? 1.0 : 1.5);
    EXPECT_GT(r.covered, 0.85);
  }
}
