// File formats: World JSON, trajectory CSV, physics and sensor JSON; round trips and errors
// that name the file, the line and the reason.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "spinradar/sim/physics.hpp"
#include "spinradar/sim/scene.hpp"
#include "spinradar/sim/scenes.hpp"
#include "spinradar/sim/sensor_config.hpp"

using namespace spinradar::sim;
namespace fs = std::filesystem;

namespace {

std::string tmpFile(const std::string& name, const std::string& text) {
  fs::path dir = fs::temp_directory_path() / ("spinradar_sim_formats_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::string p = (dir / name).string();
  std::ofstream(p) << text;
  return p;
}

template <class F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(SimFormats, WorldRoundTrip) {
  World w;
  w.targets.push_back({1.5, -2.25, 12.0, 0, 0});
  w.targets.push_back({10, 3, 5, 1.5, -0.5});
  w.walls.push_back({0, 0, 10, 0.1, 3.5});
  std::string p = tmpFile("world.json", "");
  w.save(p);
  World r = World::load(p);
  ASSERT_EQ(r.targets.size(), 2u);
  ASSERT_EQ(r.walls.size(), 1u);
  EXPECT_EQ(r.targets[0].x, 1.5);
  EXPECT_EQ(r.targets[0].y, -2.25);
  EXPECT_EQ(r.targets[1].vx, 1.5);
  EXPECT_EQ(r.targets[1].vy, -0.5);
  EXPECT_EQ(r.walls[0].y2, 0.1);
  EXPECT_EQ(r.walls[0].rcs_per_m, 3.5);
  EXPECT_EQ(r.toJson(), w.toJson());
}

TEST(SimFormats, WorldIgnoresExtraKeysAndAcceptsMissingLists) {
  World w = World::fromJson(nlohmann::json::parse(
      R"({"targets": [{"x": 1, "y": 2, "rcs": 3, "material": "metal"}], "comment": "hi"})"));
  EXPECT_EQ(w.targets.size(), 1u);
  EXPECT_TRUE(w.walls.empty());
}

TEST(SimFormats, BadWorldNamesFileLineAndReason) {
  std::string p = tmpFile("bad_world.json",
                          "{\n  \"targets\": [\n    {\"x\": 1, \"y\": 2, \"rcs\": 3},\n"
                          "    {\"x\": 1, \"y\": 2}\n  ]\n}\n");
  std::string e = errorOf([&] { World::load(p); });
  EXPECT_NE(e.find(p + ":4:"), std::string::npos) << e;
  EXPECT_NE(e.find("targets[1]"), std::string::npos) << e;
  EXPECT_NE(e.find("missing key 'rcs'"), std::string::npos) << e;

  std::string p2 = tmpFile("bad_world2.json", "{\n \"walls\": [\n  {\"x1\": 0, \"y1\": 0, \"x2\": \"a\", \"y2\": 1, \"rcs_per_m\": 0}]}\n");
  e = errorOf([&] { World::load(p2); });
  EXPECT_NE(e.find(p2 + ":3:"), std::string::npos) << e;
  EXPECT_NE(e.find("walls[0].x2: must be a number"), std::string::npos) << e;

  std::string p3 = tmpFile("bad_world3.json", "{\n \"targets\": [\n  {\"x\": 1,, }\n]}\n");
  e = errorOf([&] { World::load(p3); });
  EXPECT_NE(e.find(p3 + ":3:"), std::string::npos) << e;
  EXPECT_NE(e.find("invalid JSON"), std::string::npos) << e;

  e = errorOf([&] { World::load("/nonexistent/world.json"); });
  EXPECT_NE(e.find("/nonexistent/world.json: cannot open"), std::string::npos) << e;
}

TEST(SimFormats, TrajectoryRoundTripAndInterpolation) {
  Trajectory t({{0.0, {0, 0, 3.0}}, {1.0, {10, 2, -3.0}}, {2.0, {20, 2, -3.0}}});
  std::string p = tmpFile("traj.csv", "");
  t.saveCsv(p);
  Trajectory r = Trajectory::loadCsv(p);
  ASSERT_EQ(r.samples().size(), 3u);
  EXPECT_EQ(r.samples()[1].pose.x, 10);
  EXPECT_EQ(r.samples()[1].pose.yaw, -3.0);
  Pose2 m = r.at(0.5);
  EXPECT_DOUBLE_EQ(m.x, 5);
  EXPECT_DOUBLE_EQ(m.y, 1);
  // Shortest arc through +-pi: 3.0 -> -3.0 is +0.283 rad, midpoint at pi (or -pi).
  EXPECT_NEAR(std::abs(m.yaw), M_PI, 1e-9);
  EXPECT_EQ(r.at(-5).x, 0);  // clamped
  EXPECT_EQ(r.at(9).x, 20);
  Eigen::Vector3d v = r.bodyVelocity(1.5);
  EXPECT_NEAR(std::hypot(v.x(), v.y()), 10, 1e-9);
}

TEST(SimFormats, TrajectoryCsvColumnsInAnyOrderAndComments) {
  std::string p = tmpFile("traj2.csv", "# made by hand\nyaw,t,x,y\n0,0,0,0\n0.1,1,1,0\n");
  Trajectory r = Trajectory::loadCsv(p);
  EXPECT_EQ(r.samples()[1].pose.yaw, 0.1);
  EXPECT_EQ(r.endTime(), 1);
}

TEST(SimFormats, BadTrajectoryNamesFileLineAndReason) {
  std::string p = tmpFile("bad1.csv", "t,x,y,yaw\n0,0,0,0\n1,abc,0,0\n");
  std::string e = errorOf([&] { Trajectory::loadCsv(p); });
  EXPECT_NE(e.find(p + ":3:"), std::string::npos) << e;
  EXPECT_NE(e.find("column 'x'"), std::string::npos) << e;

  p = tmpFile("bad2.csv", "t,x,y\n0,0,0\n");
  e = errorOf([&] { Trajectory::loadCsv(p); });
  EXPECT_NE(e.find(p + ":1:"), std::string::npos) << e;
  EXPECT_NE(e.find("missing 'yaw'"), std::string::npos) << e;

  p = tmpFile("bad3.csv", "t,x,y,yaw\n0,0,0,0\n1,0,0,0\n1,0,0,0\n");
  e = errorOf([&] { Trajectory::loadCsv(p); });
  EXPECT_NE(e.find(p + ":4:"), std::string::npos) << e;
  EXPECT_NE(e.find("not strictly increasing"), std::string::npos) << e;

  p = tmpFile("bad4.csv", "t,x,y,yaw\n0,0,0,0\n1,0,0\n");
  e = errorOf([&] { Trajectory::loadCsv(p); });
  EXPECT_NE(e.find(p + ":3:"), std::string::npos) << e;
  EXPECT_NE(e.find("expected 4 fields"), std::string::npos) << e;

  p = tmpFile("bad5.csv", "t,x,y,yaw\n0,0,0,0\n");
  e = errorOf([&] { Trajectory::loadCsv(p); });
  EXPECT_NE(e.find("at least 2 samples"), std::string::npos) << e;
}

TEST(SimFormats, MotionProfileIntegratesArcsExactly) {
  // Quarter circle of radius 10 at 5 m/s, then 2 s straight.
  double w = 0.5;
  Trajectory t = Trajectory::fromProfile({{M_PI / 2 / w, 5, w}, {2, 5, 0}}, {0, 0, 0}, 100.0);
  EXPECT_EQ(t.startTime(), 100.0);
  Pose2 q = t.at(100.0 + M_PI / 2 / w);
  EXPECT_NEAR(q.x, 10, 1e-6);
  EXPECT_NEAR(q.y, 10, 1e-6);
  EXPECT_NEAR(q.yaw, M_PI / 2, 1e-9);
  Pose2 e = t.at(t.endTime());
  EXPECT_NEAR(e.x, 10, 1e-6);
  EXPECT_NEAR(e.y, 20, 1e-6);
  Eigen::Vector3d v = t.bodyVelocity(100.5);
  EXPECT_NEAR(v.x(), 5, 0.01);
  EXPECT_NEAR(v.y(), 0, 0.05);
  EXPECT_NEAR(v.z(), w, 1e-6);
}

TEST(SimFormats, PhysicsRoundTripKeepsExtrasAndListsActiveEffects) {
  auto j = nlohmann::json::parse(
      R"({"motion_distortion": true, "doppler": 0.049, "timestamp_offset": 0.03,
          "azimuth_offset": 0.0105, "range_offset": -0.3, "moving_objects": false,
          "stamp_bursts": true, "rotation_jitter": 0.01})");
  PhysicsConfig p = PhysicsConfig::fromJson(j);
  EXPECT_TRUE(p.motion_distortion);
  EXPECT_EQ(p.doppler, 0.049);
  EXPECT_EQ(p.timestamp_offset, 0.03);
  EXPECT_EQ(p.azimuth_offset, 0.0105);
  EXPECT_EQ(p.range_offset, -0.3);
  EXPECT_FALSE(p.moving_objects);
  std::vector<std::string> want{"motion_distortion", "doppler",      "timestamp_offset",
                                "azimuth_offset",    "range_offset", "rotation_jitter",
                                "stamp_bursts"};
  EXPECT_EQ(p.activeEffects(), want);
  std::string f = tmpFile("physics.json", "");
  p.save(f);
  PhysicsConfig r = PhysicsConfig::load(f);
  EXPECT_EQ(r.toJson(), p.toJson());
  EXPECT_FALSE(r.toJson().contains("moving_objects"));  // off = absent
  EXPECT_TRUE(PhysicsConfig::fromJson(nlohmann::json::object()).activeEffects().empty());
}

TEST(SimFormats, BadPhysicsNamesFileLineAndReason) {
  std::string p = tmpFile("bad_physics.json", "{\n \"doppler\": 0.049,\n \"range_offset\": \"x\"\n}\n");
  std::string e = errorOf([&] { PhysicsConfig::load(p); });
  EXPECT_NE(e.find(p + ":3:"), std::string::npos) << e;
  EXPECT_NE(e.find("range_offset: must be a number"), std::string::npos) << e;
  p = tmpFile("bad_physics2.json", "{\n \"rotation_jitter\": 5\n}\n");
  e = errorOf([&] { PhysicsConfig::load(p); });
  EXPECT_NE(e.find(p + ":2:"), std::string::npos) << e;
  EXPECT_NE(e.find("rotation_jitter"), std::string::npos) << e;
  // A misspelt effect is an error, not an effect silently left out.
  p = tmpFile("bad_physics3.json", "{\n \"dopler\": 0.049\n}\n");
  e = errorOf([&] { PhysicsConfig::load(p); });
  EXPECT_NE(e.find(p + ":2:"), std::string::npos) << e;
  EXPECT_NE(e.find("dopler: unknown effect"), std::string::npos) << e;
}

TEST(SimFormats, SensorJsonRoundTripAndErrors) {
  SensorConfig s;
  s.bins = 3360;
  s.range_resolution = 0.0596;
  std::string p = tmpFile("sensor.json", "");
  s.save(p);
  SensorConfig r = SensorConfig::load(p);
  EXPECT_EQ(r.bins, 3360);
  EXPECT_EQ(r.range_resolution, 0.0596);
  EXPECT_EQ(r.toJson(), s.toJson());
  p = tmpFile("bad_sensor.json", "{\n \"bins\": 3360,\n \"beam_width\": 2\n}\n");
  std::string e = errorOf([&] { SensorConfig::load(p); });
  EXPECT_NE(e.find(p + ":3:"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown sensor parameter"), std::string::npos) << e;
  p = tmpFile("bad_sensor2.json", "{\n \"rotation_hz\": 100\n}\n");
  e = errorOf([&] { SensorConfig::load(p); });
  EXPECT_NE(e.find(p + ":2:"), std::string::npos) << e;
}

TEST(SimFormats, BuiltinScenesExistAndUnknownNamesAreRejected) {
  for (const auto& n : builtinSceneNames()) {
    Scene s = builtinScene(n);
    EXPECT_FALSE(s.world.targets.empty()) << n;
    EXPECT_FALSE(s.world.walls.empty()) << n;
    EXPECT_GT(s.trajectory.endTime() - s.trajectory.startTime(), 60.0) << n;
  }
  EXPECT_THROW(builtinScene("moon"), std::invalid_argument);
}

// No vehicle steps its yaw rate: the built-in routes ramp it, and the city route's eased
// turns still leave the car on a street's centre line (streets every 64 m) on every straight.
TEST(SimScenes, YawRateRampsAndCityStraightsStayMidStreet) {
  for (const auto& n : builtinSceneNames()) {
    const Trajectory tr = builtinScene(n).trajectory;
    // Rates 50 ms apart: the ramps are steps of 10 ms, a stepped turn changes within 10 ms.
    const double dt = 0.05;
    double worst_accel = 0, max_rate = 0, off_centre = 0;
    double prev = tr.bodyVelocity(tr.startTime() + 0.005)[2];
    for (double t = tr.startTime() + 0.005 + dt; t < tr.endTime() - 0.01; t += dt) {
      const Eigen::Vector3d v = tr.bodyVelocity(t);
      worst_accel = std::max(worst_accel, std::abs(v[2] - prev) / dt);
      max_rate = std::max(max_rate, std::abs(v[2]));
      prev = v[2];
      if (n == "city" && std::abs(v[2]) < 1e-9 && v[0] > 1.0) {
        const Pose2 p = tr.at(t);
        auto toLine = [](double u) { return std::abs(u - 64.0 * std::round(u / 64.0)); };
        off_centre = std::max(off_centre, std::min(toLine(p.x), toLine(p.y)));
      }
    }
    EXPECT_GT(max_rate, 0.5) << n;                            // it does turn
    EXPECT_LT(worst_accel, 1.25 * kSceneYawAccel) << n;        // a step would be ~60 rad/s^2
    EXPECT_LT(off_centre, 0.05) << n;                         // (0 for the other scenes)
  }
}
