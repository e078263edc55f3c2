// The localizer nodelet's path without a master: live scans of the simulator localized
// against a map drive the other way (Localizer::process with the odometry's velocity and an
// initial pose, as the nodelet runs it), then map -> odom from a drifting odometry and a
// non-identity radar mounting (map_odom.hpp). map -> odom must put the radar near the truth.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "spinradar/core/lie.hpp"
#include "spinradar/localization/localizer.hpp"
#include "spinradar/sim/scenes.hpp"
#include "spinradar/sim/simulator.hpp"
#include "spinradar_ros/map_odom.hpp"

namespace spinradar_ros {
namespace {

namespace se2 = spinradar::se2;
using spinradar::sim::Trajectory;

constexpr double kSpeed = 10.0;
constexpr int kMapScans = 24;   // 60 m of road
constexpr int kLiveScans = 10;  // 25 m back through the middle of it

Eigen::Matrix3d truthPose(const Trajectory& tr, double t) {
  const spinradar::sim::Pose2 p = tr.at(t);
  return se2::fromXyYaw(Eigen::Vector3d(p.x, p.y, p.yaw));
}

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

TEST(OdomHistory, InterpolatesOnSe2AndRejectsOutside) {
  OdomHistory h(3);
  EXPECT_TRUE(h.empty());
  h.add(0, se2::fromXyYaw(Eigen::Vector3d(0, 0, 0)));
  h.add(1000, se2::fromXyYaw(Eigen::Vector3d(2, 0, 0.2)));
  Eigen::Matrix3d T;
  ASSERT_TRUE(h.at(500, T));
  const Eigen::Vector3d m = se2::toXyYaw(T);
  EXPECT_NEAR(m(2), 0.1, 1e-12);
  EXPECT_NEAR(m(0), 1.0, 0.01);  // on the arc, not the chord
  EXPECT_FALSE(h.at(2000, T));
  EXPECT_TRUE(h.at(1000, T));
  h.add(500, Eigen::Matrix3d::Identity());  // time jumped back: restart
  EXPECT_EQ(h.latest(), 500);
}

TEST(MapLocalization, MapToOdomPutsTheRadarOnTheTruth) {
  const spinradar::sim::Scene scene = spinradar::sim::builtinScene("out_and_back");
  spinradar::sim::PhysicsConfig physics;
  physics.motion_distortion = true;
  physics.doppler = 0.049;

  spinradar::Localizer loc;
  // Map: out on the right lane (heading +x), poses from the truth, velocities from the drive.
  const Trajectory map_tr =
      Trajectory::fromProfile({{kMapScans / 4.0 + 1.0, kSpeed, 0.0}}, {200.0, -2.0, 0.0}, 0.0);
  spinradar::sim::Simulator map_sim(scene.world, map_tr, spinradar::sim::SensorConfig{},
                                    physics, 11);
  std::vector<spinradar::LocFrame> map(kMapScans);
  for (int k = 0; k < kMapScans; ++k) loc.prepare(map_sim.renderScan(k), map[k]);
  for (int k = 0; k < kMapScans; ++k) {
    loc.setVelocity(map[k], k > 0 ? &map[k - 1] : nullptr, k + 1 < kMapScans ? &map[k + 1] : nullptr);
    map[k].T_map_sensor = truthPose(map_tr, 1e-9 * static_cast<double>(map[k].stamp_ns));
    loc.addMapFrame(map[k]);
  }

  // Live: back on the left lane. The nodelet's settings: initial pose (1 m, 3 deg off) + gate.
  const double t0 = 1000.0;
  const Trajectory live_tr = Trajectory::fromProfile(
      {{kLiveScans / 4.0 + 1.0, kSpeed, 0.0}}, {200.0 + kSpeed * kMapScans / 4.0 - 15.0, 2.0, M_PI}, t0);
  spinradar::sim::Simulator live_sim(scene.world, live_tr, spinradar::sim::SensorConfig{},
                                     physics, 12);
  spinradar::LocalizerConfig cfg;
  cfg.loc_match_gate = 5.0;
  loc.setConfig(cfg);
  loc.setInitialPose(truthPose(live_tr, t0) * se2::fromXyYaw(Eigen::Vector3d(0.8, -0.6, 0.05)));

  // Odometry of the base: its own odom frame, drifting (1 % scale, 0.5 deg/s yaw), radar
  // mounted 1.2 m ahead turned 0.1 rad; published every 0.1 s.
  const Eigen::Matrix3d T_base_radar = se2::fromXyYaw(Eigen::Vector3d(1.2, 0.3, 0.1));
  const Eigen::Matrix3d T_map_odom0 = se2::fromXyYaw(Eigen::Vector3d(230.0, 5.0, 2.0));
  auto odomBase = [&](double t) -> Eigen::Matrix3d {
    const double s = t - t0;
    const Eigen::Matrix3d drift = se2::fromXyYaw(Eigen::Vector3d(0.01 * kSpeed * s, 0.0, 0.0087 * s));
    return drift * se2::inverse(T_map_odom0) * truthPose(live_tr, t) * se2::inverse(T_base_radar);
  };
  OdomHistory history;
  for (double t = t0; t < t0 + kLiveScans / 4.0 + 0.5; t += 0.1)
    history.add(static_cast<int64_t>(std::llround(t * 1e9)), odomBase(t));

  std::vector<double> errors;
  int failures = 0;
  const Eigen::Vector3d v_radar(kSpeed, 0.0, 0.0);  // the odometry's velocity, radar frame
  for (int k = 0; k < kLiveScans; ++k) {
    const spinradar::LocalizationResult r = loc.process(live_sim.renderScan(k), &v_radar);
    if (!r.ok) {
      ++failures;
      std::printf("scan %d not localized: %s\n", k, r.reason.c_str());
      continue;
    }
    Eigen::Matrix3d T_odom_base;
    ASSERT_TRUE(history.at(r.stamp_ns, T_odom_base));
    const Eigen::Matrix3d T_map_odom = mapToOdom(r.T_map_sensor, T_odom_base, T_base_radar);
    // What a tf user gets until the next scan: map -> odom (this scan) -> base (odometry
    // 0.2 s later) -> radar, against the truth then.
    const double t = 1e-9 * static_cast<double>(r.stamp_ns) + 0.2;
    const Eigen::Matrix3d T_map_radar = T_map_odom * odomBase(t) * T_base_radar;
    const Eigen::Vector3d e = se2::toXyYaw(se2::inverse(truthPose(live_tr, t)) * T_map_radar);
    const Eigen::Vector3d e_loc = se2::toXyYaw(
        se2::inverse(truthPose(live_tr, 1e-9 * static_cast<double>(r.stamp_ns))) * r.T_map_sensor);
    std::printf("scan %d: %d / %d inliers, localization error %.3f m %.4f rad, map -> odom "
                "radar error %.3f m %.4f rad\n",
                k, r.inliers, r.matches, e_loc.head<2>().norm(), e_loc(2), e.head<2>().norm(), e(2));
    errors.push_back(e.head<2>().norm());
    EXPECT_LT(e.head<2>().norm(), 0.5) << "scan " << k;
    EXPECT_LT(std::abs(e(2)), 0.02) << "scan " << k;
  }
  ASSERT_FALSE(errors.empty());
  std::printf("map -> odom: %zu / %d scans localized, median radar error %.3f m\n",
              errors.size(), kLiveScans, median(errors));
  EXPECT_LE(failures, kLiveScans / 5);
  EXPECT_LT(median(errors), 0.3);
}

}  // namespace
}  // namespace spinradar_ros
