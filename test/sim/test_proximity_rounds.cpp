// EstimatorConfig::proximity_rounds (issue 19, docs/sensor_columns/round17_proximity_rounds.md)
// on the simulator against its truth: the tight_turns scene with full physics, noise seed 1,
// the default pipeline otherwise. The proximity ICP (descriptors failed against a keyframe
// turned away from the scan, and the graph's registrations to past keyframes) pairs by
// proximity and solves again until the pose settles, at most proximity_rounds times per gate.
// Checked: the rounds matter (one round leaves the turns' heading clearly worse), and the
// default's few rounds keep the heading of the former 30 rounds.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <memory>
#include <vector>

#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/odometry.hpp"
#include "spinradar/sim/scenes.hpp"
#include "spinradar/sim/simulator.hpp"
#include "sim_test_util.hpp"

using namespace spinradar;

TEST(ProximityRounds, FewRoundsKeepTheTurnsHeadingAndOneRoundDoesNot) {
  const sim::Scene sc = sim::builtinScene("tight_turns", 0);
  const sim::Simulator s(sc.world, sc.trajectory, sim::SensorConfig{}, sim::testing::fullPhysics(),
                         1);
  const int scans = 240;  // 60 s: the scene's turns one after another
  const int default_rounds = EstimatorConfig{}.proximity_rounds;
  const std::vector<int> rounds = {1, default_rounds, 30};
  std::vector<std::unique_ptr<Odometry>> odo;
  for (const int r : rounds) {
    PipelineConfig cfg;
    cfg.estimator.proximity_rounds = r;
    odo.push_back(std::make_unique<Odometry>(cfg));
  }
  // Heading error against the truth, both relative to the first scan: rms over the scans.
  std::vector<double> sq(rounds.size(), 0.0);
  double truth0 = 0.0;
  std::vector<double> est0(rounds.size(), 0.0);
  for (int k = 0; k < scans; ++k) {
    const PolarScan scan = s.renderScan(k);
    for (size_t i = 0; i < rounds.size(); ++i) {
      const OdometryResult r = odo[i]->process(scan);
      ASSERT_TRUE(r.T_world_sensor.allFinite());
      const double truth = sc.trajectory.at(1e-9 * static_cast<double>(r.stamp_ns)).yaw;
      const double yaw = se2::toXyYaw(r.T_world_sensor)(2);
      if (k == 0) {
        truth0 = truth;
        est0[i] = yaw;
      }
      const double e = se2::wrapAngle((yaw - est0[i]) - (truth - truth0));
      sq[i] += e * e;
    }
  }
  std::vector<double> rms;
  for (const double v : sq) rms.push_back(std::sqrt(v / scans) * 180.0 / M_PI);
  std::cout << "[ info ] tight_turns seed 1, " << scans << " scans, heading error rms deg: "
            << "1 round " << rms[0] << ", " << default_rounds << " rounds (default) " << rms[1]
            << ", 30 rounds " << rms[2] << "\n";
  // Measured: 1 round 1.147 deg, 5 rounds 0.197, 30 rounds 0.194.
  // The default keeps the former 30 rounds' heading (within 10 % or 0.01 deg).
  EXPECT_LE(rms[1], 1.1 * rms[2] + 0.01);
  // One round (a single re-association per gate) is clearly worse: the loop is not idle here.
  EXPECT_GT(rms[0], 1.3 * rms[1]);
}
