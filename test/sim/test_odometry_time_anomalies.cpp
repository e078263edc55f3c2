// Odometry across time anomalies on a simulated drive with known truth: time going back (a
// sensor clock step, through the emulator and the driver) resets the state without a jump,
// and a long gap starts a new segment instead of extrapolating across it. No step is larger
// than the truth allows, and the velocity is estimated again from the next pair.
#include <gtest/gtest.h>

#include <chrono>

#include "spinradar/driver/navtech_driver.hpp"
#include "spinradar/driver/navtech_server.hpp"
#include "spinradar/estimation/odometry.hpp"
#include "spinradar/sim/sim_radar_input.hpp"

using namespace spinradar;
using TimeEvent = OdometryResult::TimeEvent;

namespace {

constexpr double kSlack = 0.3;  // m: estimated step vs truth, well above the estimator's error

std::shared_ptr<const sim::Simulator> citySim() {
  static auto sim = sim::makeBuiltinSimulator("city", sim::PhysicsConfig{});
  return sim;
}

/// Distance the sensor truly moved between two true times.
double truthStep(double t1, double t2) {
  const sim::Pose2 a = citySim()->trajectory().at(t1), b = citySim()->trajectory().at(t2);
  return std::hypot(b.x - a.x, b.y - a.y);
}

double stepLength(const OdometryResult& a, const OdometryResult& b) {
  return (b.T_world_sensor.topRightCorner<2, 1>() - a.T_world_sensor.topRightCorner<2, 1>()).norm();
}

}  // namespace

TEST(OdometryTimeAnomalies, LongGapStartsANewSegmentWithoutAJump) {
  auto sim = citySim();
  Odometry odo(PipelineConfig{});
  // Rotations 6..27 (5.5 s) never arrive.
  const std::vector<int> ks = {0, 1, 2, 3, 4, 5, 28, 29, 30, 31};
  std::vector<OdometryResult> res;
  for (int k : ks) res.push_back(odo.process(sim->renderScan(k)));
  for (size_t i = 1; i < ks.size(); ++i) {
    const double truth = truthStep(res[i - 1].stamp_ns * 1e-9, res[i].stamp_ns * 1e-9);
    const double est = stepLength(res[i - 1], res[i]);
    EXPECT_LE(est, truth + kSlack) << "scan " << ks[i];
    if (ks[i] == 28) {
      EXPECT_EQ(res[i].time_event, TimeEvent::Gap);
      EXPECT_NEAR(res[i].time_step_s, 5.75, 1e-3);
      EXPECT_EQ(est, 0.0);  // no extrapolated step across the gap
      // The unknown motion meanwhile is in the covariance: at least (1 m/s * 5.75 s)^2 more.
      EXPECT_GT(res[i].pose_cov(0, 0) - res[i - 1].pose_cov(0, 0), 5.75 * 5.75);
      EXPECT_FALSE(res[i].ok);
      std::cout << "[ info ] gap of " << res[i].time_step_s << " s: step 0 (truth " << truth
                << " m), pose sigma x " << std::sqrt(res[i - 1].pose_cov(0, 0)) << " -> "
                << std::sqrt(res[i].pose_cov(0, 0)) << " m\n";
    } else {
      EXPECT_EQ(res[i].time_event, TimeEvent::None) << "scan " << ks[i];
      EXPECT_TRUE(res[i].ok) << "scan " << ks[i];  // incl. 29: velocity from the new pair
      EXPECT_NEAR(est, truth, kSlack) << "scan " << ks[i];
    }
  }
}

TEST(OdometryTimeAnomalies, SensorClockStepsThroughTheDriver) {
  // The simulator served as a sensor whose clock jumps forward 10 s in rotation 3 and steps
  // back 10 s in rotation 7; the driver drops both straddling rotations, the odometry starts
  // a new segment after the jump ahead and resets when time goes back.
  using K = navtech::ServerFault::Kind;
  navtech::ServerOptions so;
  so.rate = 0;
  so.wall_clock = false;  // the simulator's clock: truth times are the stamps (-10 s between)
  so.log = [](navtech::LogLevel, const std::string&) {};
  so.faults.resize(2);
  so.faults[0].at_azimuth = 3 * 400 + 200;
  so.faults[0].kind = K::ClockStep;
  so.faults[0].value = 10.0;
  so.faults[1].at_azimuth = 7 * 400 + 100;
  so.faults[1].kind = K::ClockStep;
  so.faults[1].value = -10.0;
  navtech::NavtechServer server(so, sim::simScanSource(citySim(), 0));
  server.start();
  DriverConfig c;
  c.port = server.port();
  navtech::NavtechDriver d(c);
  d.setLog([](navtech::LogLevel, const std::string&) {});
  Odometry odo(PipelineConfig{});
  navtech::AssembledScan s;
  std::vector<OdometryResult> res;
  std::vector<double> truth_t;
  std::vector<uint64_t> anomalies;
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (res.size() < 10 && std::chrono::steady_clock::now() < end) {
    if (d.poll(s, std::chrono::milliseconds(200)) != navtech::InputStatus::Ok) continue;
    for (int a = 1; a < s.scan.azimuths; ++a) ASSERT_GT(s.scan.stamp_ns[a], s.scan.stamp_ns[a - 1]);
    res.push_back(odo.process(s.scan));
    anomalies.push_back(d.stats().time_anomalies);
    truth_t.push_back(res.back().stamp_ns * 1e-9 + (anomalies.back() == 1 ? -10.0 : 0.0));
  }
  ASSERT_EQ(res.size(), 10u);  // rotations 0-2, 4-6, 8-11
  int backwards = 0, gaps = 0;
  for (size_t i = 1; i < res.size(); ++i) {
    const double truth = truthStep(truth_t[i - 1], truth_t[i]);
    const double est = stepLength(res[i - 1], res[i]);
    EXPECT_LE(est, truth + kSlack) << "scan " << i;
    if (anomalies[i] != anomalies[i - 1]) {
      // The first scan after each step: a new segment, the pose kept.
      EXPECT_EQ(res[i].time_event, anomalies[i] == 1 ? TimeEvent::Gap : TimeEvent::Backwards);
      EXPECT_EQ(est, 0.0);
      backwards += res[i].time_event == TimeEvent::Backwards;
      gaps += res[i].time_event == TimeEvent::Gap;
    } else {
      EXPECT_EQ(res[i].time_event, TimeEvent::None) << "scan " << i;
      EXPECT_TRUE(res[i].ok) << "scan " << i;
      EXPECT_NEAR(est, truth, kSlack) << "scan " << i;
    }
  }
  EXPECT_EQ(backwards, 1);
  EXPECT_EQ(gaps, 1);
  EXPECT_EQ(d.stats().time_anomalies, 2u);
}
