// The default odometry (keyframe, azimuth peaks) on a simulated city drive with full physics
// read every other scan (a 4 Hz sensor delivering 2 Hz, i.e. dropped scans: stamp steps of two
// rotation periods), against the same drive read at every scan (issue 19). Known truth: the
// simulator's trajectory. Two right-angle turns (t = 55..77 s of city layout 0, where the
// every-other-scan recordings drifted 3 %): before the fix a registration failed at each turn
// entry and the scan became the keyframe at the refined pair's step, which interpolated the
// pair velocities with equal weights and so lagged 0.125 s: 3.4 and 4.9 deg short (README:
// refined_estimator.cpp item 5, scan_period.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>

#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/odometry.hpp"
#include "spinradar/sim/scenes.hpp"
#include "spinradar/sim/simulator.hpp"

using namespace spinradar;

namespace {

constexpr double kDeg = M_PI / 180.0;

struct DriveErrors {
  double final_yaw = 0.0;   ///< rad, |accumulated yaw error| at the last scan
  double worst_yaw = 0.0;   ///< rad, worst accumulated yaw error over the run
  double final_pos = 0.0;   ///< m
  double path = 0.0;        ///< m, true path length
};

/// The matrix's full physics: motion distortion, Doppler beta 0.049 s, moving cars.
sim::PhysicsConfig fullPhysics() {
  sim::PhysicsConfig physics;
  physics.motion_distortion = true;
  physics.doppler = 0.049;
  physics.moving_objects = true;
  return physics;
}

/// Scans k0, k0 + stride, ... up to k1 of city layout 0 with full physics through the default
/// pipeline; the accumulated pose (relative to the first scan) against the truth.
DriveErrors drive(const sim::Simulator& s, const sim::Trajectory& traj, int k0, int k1, int stride,
                  const char* name = "city layout 0") {
  Odometry odo(PipelineConfig{});
  DriveErrors r;
  Eigen::Matrix3d T0 = Eigen::Matrix3d::Identity();
  Eigen::Vector2d last(0, 0);
  for (int k = k0; k <= k1; k += stride) {
    const PolarScan scan = s.renderScan(k);
    EXPECT_EQ(rotationPeriodNs(scan), 250'000'000) << "scan " << k;  // 4 Hz whatever is read
    const OdometryResult res = odo.process(scan);
    const sim::Pose2 p = traj.at(1e-9 * static_cast<double>(res.stamp_ns));
    const Eigen::Matrix3d T = se2::fromXyYaw(Eigen::Vector3d(p.x, p.y, p.yaw));
    if (k == k0) {
      T0 = T;
      last = T.topRightCorner<2, 1>();
      continue;
    }
    EXPECT_TRUE(res.ok) << "scan " << k;
    r.path += (T.topRightCorner<2, 1>() - last).norm();
    last = T.topRightCorner<2, 1>();
    const Eigen::Vector3d e = se2::log(se2::inverse(se2::inverse(T0) * T) * res.T_world_sensor);
    r.final_yaw = std::abs(e(2));
    r.worst_yaw = std::max(r.worst_yaw, r.final_yaw);
    r.final_pos = e.head<2>().norm();
  }
  std::cout << "[ info ] " << name << ", scans " << k0 << ".." << k1
            << (stride == 1 ? " (4 Hz)" : " every other one (2 Hz)") << ": " << r.path
            << " m, final yaw error " << r.final_yaw / kDeg << " deg (worst " << r.worst_yaw / kDeg
            << "), position error " << r.final_pos << " m (" << 100.0 * r.final_pos / r.path
            << " %)\n";
  return r;
}

}  // namespace

TEST(OdometryDroppedScans, EveryOtherScanDriftsAsLittleAsEveryScan) {
  const sim::PhysicsConfig physics = fullPhysics();
  const sim::Scene sc = sim::builtinScene("city", 0);
  const sim::Simulator s(sc.world, sc.trajectory, sim::SensorConfig{}, physics, 1);
  // t = 55..77 s: two right-angle right turns (58-61 s, 72-75 s) and the straights around.
  const DriveErrors full = drive(s, sc.trajectory, 220, 308, 1);
  const DriveErrors skip = drive(s, sc.trajectory, 220, 308, 2);
  // Every other scan, before the fix: final yaw error 10.9 deg, position 13.4 m (7.6 %); now
  // 0.17 deg, 0.48 m (0.27 %). Every scan (identical before and after): 0.08 deg, 0.02 m.
  EXPECT_LT(skip.worst_yaw, std::max(2.0 * full.worst_yaw, 0.5 * kDeg));
  EXPECT_LT(skip.final_yaw, std::max(2.0 * full.final_yaw, 0.3 * kDeg));
  EXPECT_LT(skip.final_pos, std::max(2.0 * full.final_pos, 0.005 * skip.path));
}

TEST(OdometryDroppedScans, WeakRegistrationsDoNotPassAYawRateOn) {
  // The calibrated Oxford sensor model: dim far structure, few descriptor inliers, so every
  // other scan most registrations are weak and every such scan becomes the keyframe. A
  // keyframe whose map was moved with its registration's yaw rate passed that rate's offset
  // on to the next at every scan (a straight at t = 18-21 s: -0.06 -> -0.15 rad/s, truth 0),
  // unless the registered yaw rate's gap counts relative to the keyframe's own across a gap
  // (keyframe_tracker.cpp). t = 10..25.5 s: straights and the first left turn's entry.
  // Every other scan without that: worst yaw error 2.0 deg (1.8 deg for 3 s on the
  // straight); with it 0.62 deg; every scan 0.33 deg. (The turn exit that follows, t = 26 s,
  // still puts 4.8 deg into the chain every other scan under this model: docs/dropped_scans.md.)
  const sim::PhysicsConfig physics = fullPhysics();
  const sim::Scene sc = sim::builtinScene("city", 0);
  // The Oxford model as calibrated at main b0cda56 (config/sensors/oxford.json then), kept
  // here so the test does not move with recalibration (as test_near_band does): with the
  // regenerated file (glint terms) the old rule reached only 1.47 deg against 1.11.
  const sim::SensorConfig oxford = sim::SensorConfig::load(
      std::string(SPINRADAR_SOURCE_DIR) + "/test/sim/dropped_scans_oxford_sensor.json");
  const sim::Simulator s(sc.world, sc.trajectory, oxford, physics, 1);
  const DriveErrors full = drive(s, sc.trajectory, 40, 102, 1, "city layout 0, Oxford model");
  const DriveErrors skip = drive(s, sc.trajectory, 40, 102, 2, "city layout 0, Oxford model");
  EXPECT_LT(skip.worst_yaw, std::max(3.0 * full.worst_yaw, 0.5 * kDeg));
  EXPECT_LT(skip.final_pos, std::max(2.0 * full.final_pos, 0.005 * skip.path));
}
