// Does the keyframe estimator's rotation come out to scale? (issue 19, round 17:
// docs/sensor_columns/round17_no_rotation_scale_bias.md). The sensor spins in place in the city
// world at a constant yaw rate, so the true heading is known exactly and every registration is
// a pure rotation of up to keyframe_angle, made under the full within-scan sweep (0.15 rad per
// scan at 0.6 rad/s). With the default pipeline (azimuth peaks, keyframe graph) the heading
// after 404 deg of spin is within 0.1 % of the truth in both directions (measured -0.008 /
// +0.0003 %): no under-rotation, neither from the registration's geometry (peaks, Cartesian
// grid, gates, robust weights) nor from the motion compensation's time model (row stamps
// i / 400 of the period from the scan start, as the simulator renders them).
// The measurement can see a compensation error: rendered without motion distortion (each scan
// a snapshot at mid-scan) the estimator's compensation is wrong by the whole sweep and the
// heading comes out off by the sweep's azimuth stretch, 0.15 rad / 2 pi = 2.39 % (measured
// -2.35 % spinning CCW, +2.38 % CW, over 163 deg). So the time model is right to within 0.3 %
// of the sweep; i / 399 instead of i / 400 (0.25 %) would move the rotation by 0.006 %.
// (Rendered without distortion for 48 scans the CCW spin lost its track at scan 23.)
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/odometry.hpp"
#include "spinradar/sim/scenes.hpp"
#include "spinradar/sim/simulator.hpp"

using namespace spinradar;

namespace {

struct Spin {
  double turned = 0.0;  ///< rad, true heading change from the first scan to the last
  double error = 0.0;   ///< rad, estimated minus true heading change
};

/// Spins at yaw_rate (rad/s) in place on the city route's first street for `scans` scans.
Spin spinInPlace(double yaw_rate, bool motion_distortion, int scans) {
  const sim::Scene city = sim::builtinScene("city", 0);
  const sim::Trajectory spin = sim::Trajectory::fromProfile(
      {{0.25 * (scans + 2), 0.0, yaw_rate}}, sim::Pose2{86.7, 0.0, 0.0}, 0.0);
  sim::PhysicsConfig physics;
  physics.motion_distortion = motion_distortion;
  physics.doppler = 0.049;
  physics.moving_objects = true;
  const sim::Simulator s(city.world, spin, sim::SensorConfig{}, physics, 1);
  Odometry odo(PipelineConfig{});
  Spin out;
  double est = 0.0, prev_est = 0.0, prev_truth = 0.0;
  for (int k = 0; k < scans; ++k) {
    const OdometryResult r = odo.process(s.renderScan(k));
    const double truth = spin.at(1e-9 * static_cast<double>(r.stamp_ns)).yaw;
    const double yaw = se2::toXyYaw(r.T_world_sensor)(2);
    if (k == 0) {
      prev_truth = truth;
      prev_est = yaw;
    }
    // Both unwrapped: the spin passes 2 pi.
    out.turned += std::remainder(truth - prev_truth, 2 * M_PI);
    est += std::remainder(yaw - prev_est, 2 * M_PI);
    prev_truth = truth;
    prev_est = yaw;
    out.error = est - out.turned;
  }
  return out;
}

}  // namespace

TEST(KeyframeRotationScale, InPlaceSpinIsNotUnderRotated) {
  for (const double w : {0.6, -0.6}) {
    const Spin with = spinInPlace(w, true, 48);
    const Spin without = spinInPlace(w, false, 20);
    std::cout << "[ info ] spin " << w << " rad/s, " << with.turned * 180 / M_PI
              << " deg: heading error " << 100 * with.error / with.turned
              << " % of the turned angle; rendered without motion distortion, "
              << without.turned * 180 / M_PI << " deg: " << 100 * without.error / without.turned
              << " %\n";
    EXPECT_GT(std::abs(with.turned), 7.0);  // the sensor did spin (12 s at 0.6 rad/s)
    EXPECT_LT(std::abs(with.error / with.turned), 0.001) << "yaw rate " << w;
    // The compensation is what keeps it to scale: applied to snapshots it stretches every scan's
    // azimuths by about the sweep (the sensor sweeps clockwise: a CCW spin comes out short, a
    // CW one long).
    EXPECT_LT((w > 0 ? 1 : -1) * without.error / without.turned, -0.01) << "yaw rate " << w;
  }
}
