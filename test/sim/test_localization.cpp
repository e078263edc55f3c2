// Localization against a map drive in the opposite direction, on the simulator's out-and-back
// road at 15 m/s with motion distortion and Doppler (beta 0.049): the paper's Table II trend,
// median error none > motion > motion + Doppler, by clear margins.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "spinradar/core/lie.hpp"
#include "spinradar/localization/localizer.hpp"
#include "spinradar/sim/scenes.hpp"
#include "spinradar/sim/simulator.hpp"

namespace spinradar {
namespace {

using sim::Trajectory;

constexpr double kSpeed = 15.0;
constexpr int kMapScans = 36;   // 135 m of road
constexpr int kLiveScans = 24;  // 90 m back through the middle of it

Eigen::Matrix3d truthPose(const Trajectory& tr, int64_t stamp_ns) {
  const sim::Pose2 p = tr.at(1e-9 * static_cast<double>(stamp_ns));
  return se2::fromXyYaw(Eigen::Vector3d(p.x, p.y, p.yaw));
}

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

std::vector<double> rsd_ms, keypoints;  // per prepared scan

struct Drive {
  Trajectory trajectory;
  std::vector<LocFrame> frames;
  std::vector<PolarScan> scans;
};

/// Renders and prepares a straight drive at kSpeed from `start` (scan k starts at t0 + k/4 s).
Drive drive(Localizer& loc, const sim::World& world, const sim::Pose2& start, double t0, int n,
            uint64_t seed) {
  Drive d;
  d.trajectory = Trajectory::fromProfile({{n / 4.0 + 1.0, kSpeed, 0.0}}, start, t0);
  sim::PhysicsConfig physics;
  physics.motion_distortion = true;
  physics.doppler = 0.049;
  sim::Simulator simulator(world, d.trajectory, sim::SensorConfig{}, physics, seed);
  d.frames.resize(n);
  for (int k = 0; k < n; ++k) {
    double ms = 0.0;
    d.scans.push_back(simulator.renderScan(k));
    loc.prepare(d.scans.back(), d.frames[k], &ms);
    rsd_ms.push_back(ms);
    keypoints.push_back(static_cast<double>(d.frames[k].keypoints.size()));
  }
  for (int k = 0; k < n; ++k)
    loc.setVelocity(d.frames[k], k > 0 ? &d.frames[k - 1] : nullptr,
                    k + 1 < n ? &d.frames[k + 1] : nullptr);
  return d;
}

class OppositeDirection : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const sim::Scene scene = sim::builtinScene("out_and_back");
    loc_ = new Localizer();
    // Map: out on the right lane (y = -2, heading +x); live: back on the left lane.
    Drive map = drive(*loc_, scene.world, {200.0, -2.0, 0.0}, 0.0, kMapScans, 11);
    for (LocFrame& f : map.frames) {
      f.T_map_sensor = truthPose(map.trajectory, f.stamp_ns);
      loc_->addMapFrame(f);
    }
    live_ = new Drive(drive(*loc_, scene.world, {200.0 + kSpeed * kMapScans / 4.0 - 20.0, 2.0, M_PI},
                            1000.0, kLiveScans, 12));
  }
  static void TearDownTestSuite() {
    delete loc_;
    delete live_;
  }

  /// Median translation / rotation error over the live scans, nearest map scan by truth.
  static void run(Compensation c, double& med_t, double& med_r, int& failures) {
    std::vector<double> et, er, mm;
    failures = 0;
    for (const LocFrame& f : live_->frames) {
      const Eigen::Matrix3d T_true = truthPose(live_->trajectory, f.stamp_ns);
      const LocalizationResult r = loc_->localize(f, T_true, c);
      mm.push_back(r.match_ms);
      if (!r.ok) {
        ++failures;
        std::printf("  not localised: %s\n", r.reason.c_str());
        continue;
      }
      const Eigen::Vector3d e = se2::toXyYaw(se2::inverse(T_true) * r.T_map_sensor);
      et.push_back(e.head<2>().norm());
      er.push_back(std::abs(e(2)) * 180.0 / M_PI);
    }
    med_t = median(et);
    med_r = median(er);
    std::printf("%-15s median translation %.3f m, rotation %.3f deg, failures %d / %zu, "
                "RSD match %.2f ms CPU\n",
                compensationName(c), med_t, med_r, failures, live_->frames.size(), median(mm));
  }

  static Localizer* loc_;
  static Drive* live_;
};

Localizer* OppositeDirection::loc_ = nullptr;
Drive* OppositeDirection::live_ = nullptr;

TEST_F(OppositeDirection, VelocitiesAreEstimatedWithinEachDrive) {
  // Per-scan velocities come from RSD matches within one drive: judged by their median (the
  // estimate) and their worst case (no wild scan), since single scans carry matching noise.
  std::vector<double> lateral, err_doppler, err_mc, err_yaw;
  for (const LocFrame& f : live_->frames) {
    ASSERT_TRUE(f.has_velocity);
    // Body frame: the live car drives forward too (its heading is pi in the world).
    err_doppler.push_back(std::abs(f.velocity_doppler(0) - kSpeed));
    err_mc.push_back(std::abs(f.velocity_mc(0) - kSpeed));
    err_yaw.push_back(std::abs(f.velocity_doppler(2)));
    lateral.push_back(std::abs(f.velocity_doppler(1)));
  }
  EXPECT_LT(median(err_doppler), 0.15);
  EXPECT_LT(median(err_mc), 0.3);
  EXPECT_LT(median(err_yaw), 0.01);
  EXPECT_LT(*std::max_element(err_doppler.begin(), err_doppler.end()), 1.0);
  EXPECT_LT(*std::max_element(err_mc.begin(), err_mc.end()), 1.5);
  EXPECT_LT(*std::max_element(err_yaw.begin(), err_yaw.end()), 0.05);
  // Lateral velocity is the weakest component (few matches along a straight road).
  EXPECT_LT(median(lateral), 0.3);
  std::printf("RSD over %zu scans: median %.0f keypoints, median %.2f ms CPU per scan\n",
              rsd_ms.size(), median(keypoints), median(rsd_ms));
}

TEST_F(OppositeDirection, ErrorFallsWithEachCompensation) {
  double t_none, r_none, t_mot, r_mot, t_dop, r_dop;
  int f_none, f_mot, f_dop;
  run(Compensation::None, t_none, r_none, f_none);
  run(Compensation::Motion, t_mot, r_mot, f_mot);
  run(Compensation::MotionDoppler, t_dop, r_dop, f_dop);
  const int n = kLiveScans;
  EXPECT_LE(f_dop, n / 6);
  EXPECT_LE(f_mot, n / 6);
  // Clear margins: each compensation removes a sizeable part of the error.
  EXPECT_LT(t_mot, 0.75 * t_none);
  EXPECT_LT(t_dop, 0.6 * t_mot);
  EXPECT_LT(t_dop, 0.5);
}

TEST_F(OppositeDirection, OnlineTrackingWithoutTruth) {
  // The nodelet's path: one process() call per live scan, velocity from the previous scan,
  // prior = last estimate moved by it, matches gated around the prior. Starts 1.5 m off.
  LocalizerConfig cfg;
  cfg.loc_match_gate = 5.0;
  Localizer tracker(cfg);
  for (size_t i = 0; i < loc_->mapSize(); ++i) tracker.addMapFrame(loc_->mapFrame(i));
  const Eigen::Matrix3d T0 = truthPose(live_->trajectory, live_->frames[0].stamp_ns);
  tracker.setInitialPose(T0 * se2::fromXyYaw({1.5, -0.5, 0.02}));
  std::vector<double> et;
  int failures = 0;
  for (size_t k = 0; k < live_->scans.size(); ++k) {
    const LocalizationResult r = tracker.process(live_->scans[k]);
    if (k == 0) continue;  // no velocity yet: uncompensated
    if (!r.ok) {
      ++failures;
      continue;
    }
    EXPECT_TRUE(r.velocity_known);
    const Eigen::Matrix3d T_true = truthPose(live_->trajectory, r.stamp_ns);
    et.push_back(se2::toXyYaw(se2::inverse(T_true) * r.T_map_sensor).head<2>().norm());
  }
  std::printf("tracking (motion_doppler, gate 5 m): median %.3f m, failures %d / %zu\n",
              median(et), failures, live_->scans.size() - 1);
  EXPECT_LE(failures, 2);
  EXPECT_LT(median(et), 0.3);
}

}  // namespace
}  // namespace spinradar
