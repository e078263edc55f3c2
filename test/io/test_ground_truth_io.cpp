// Ground-truth readers for Boreas and MulRan against hand-computed poses, format detection,
// errors naming file and line, and the sensor lever arm against a known drive.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include <Eigen/LU>
#include <gtest/gtest.h>

#include "spinradar/evaluation/evaluation.hpp"
#include "spinradar/io/ground_truth_io.hpp"

using namespace spinradar;
namespace fs = std::filesystem;

namespace {

constexpr double kPi = 3.14159265358979323846;

std::string writeFile(const std::string& name, const std::string& text) {
  const fs::path p = fs::temp_directory_path() / ("spinradar_gt_" + name);
  std::ofstream(p) << text;
  return p.string();
}

std::string expectThrowMessage(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no exception";
  return {};
}

const char* kBoreasHeader =
    "GPSTime,easting,northing,altitude,vel_east,vel_north,vel_up,roll,pitch,heading,angvel_z,"
    "angvel_y,angvel_x\n";

}  // namespace

// Boreas radar frame: x forward, z down (roll ~ pi). Driving 2.5 m along the heading of 0.3
// rad must come out as 2.5 m straight ahead in the sensor frame, and the yaw as the heading.
TEST(GroundTruthIo, BoreasRadarPosesDriveForward) {
  const double h = 0.3, d = 2.5;
  std::ostringstream s;
  s.precision(12);
  s << kBoreasHeader;
  s << "1606417097528152,10,20,0.5,0,0,0," << kPi << ",0," << h << ",0,0,0\n";
  s << "1606417097778152," << 10 + d * std::cos(h) << "," << 20 + d * std::sin(h) << ",0.5,0,0,0,"
    << kPi << ",0," << h << ",0,0,0\n";
  const auto p = readGroundTruth(writeFile("boreas.csv", s.str()));
  ASSERT_EQ(p.size(), 2u);
  EXPECT_NEAR(p[0].t, 1606417097.528152, 1e-6);
  EXPECT_NEAR(p[1].t - p[0].t, 0.25, 1e-6);
  EXPECT_NEAR(p[0].yaw, h, 1e-12);
  const Eigen::Matrix3d rel = poseMatrix(p[0]).inverse() * poseMatrix(p[1]);
  EXPECT_NEAR(rel(0, 2), d, 1e-9);
  EXPECT_NEAR(rel(1, 2), 0.0, 1e-9);
}

// With roll = 0 (z up) pyboreas' passive yaw turns the x axis clockwise: yaw = -heading.
// Seconds in GPSTime (gps_post_process.csv) are taken as seconds.
TEST(GroundTruthIo, BoreasZUpFrameAndSecondsClock) {
  std::ostringstream s;
  s << kBoreasHeader << "1606417097.5,1,2,0,0,0,0,0,0,0.4,0,0,0\n";
  const auto p = readBoreasPoses(writeFile("boreas_s.csv", s.str()));
  ASSERT_EQ(p.size(), 1u);
  EXPECT_NEAR(p[0].t, 1606417097.5, 1e-6);
  EXPECT_NEAR(p[0].yaw, -0.4, 1e-12);
  EXPECT_DOUBLE_EQ(p[0].x, 1.0);
  EXPECT_DOUBLE_EQ(p[0].y, 2.0);
}

TEST(GroundTruthIo, BoreasErrorsNameFileAndLine) {
  const std::string no_heading = writeFile("boreas_bad1.csv", "GPSTime,easting,northing,roll,pitch\n1,2,3,4,5\n");
  EXPECT_NE(expectThrowMessage([&] { readBoreasPoses(no_heading); }).find("boreas_bad1.csv:1: not a Boreas pose header (no 'heading'"),
            std::string::npos);
  std::ostringstream s;
  s << kBoreasHeader << "1606417097528152,0,0,0,0,0,0,3.14,0,0,0,0,0\n"
    << "1606417097528152,1,0,0,0,0,0,3.14,0,0,0,0,0\n";
  const std::string repeated = writeFile("boreas_bad2.csv", s.str());
  EXPECT_NE(expectThrowMessage([&] { readGroundTruth(repeated); }).find("boreas_bad2.csv:3: time is not after"),
            std::string::npos);
  std::ostringstream u;
  u << kBoreasHeader << "1606417097528152,0,0,0,0,0,0,3.14,0,abc,0,0,0\n";
  const std::string garbage = writeFile("boreas_bad3.csv", u.str());
  EXPECT_NE(expectThrowMessage([&] { readGroundTruth(garbage); }).find("boreas_bad3.csv:2: malformed heading 'abc'"),
            std::string::npos);
}

// MulRan global_pose.csv: ns, then [R | t] row-major, no header; UTM-sized coordinates.
TEST(GroundTruthIo, MulranGlobalPose) {
  const double yaw = 0.5, c = std::cos(yaw), s = std::sin(yaw);
  std::ostringstream f;
  f.precision(12);
  f << "1564718976161407002," << c << "," << -s << ",0,353000.5," << s << "," << c << ",0,4026000.25,0,0,1,19.5\n";
  f << "1564718976171407002," << c << "," << -s << ",0,353001.5," << s << "," << c << ",0,4026000.25,0,0,1,19.5\n";
  const auto p = readGroundTruth(writeFile("mulran.csv", f.str()));
  ASSERT_EQ(p.size(), 2u);
  EXPECT_NEAR(p[1].t - p[0].t, 0.01, 1e-6);
  EXPECT_NEAR(p[0].yaw, yaw, 1e-12);
  EXPECT_DOUBLE_EQ(p[0].x, 353000.5);
  EXPECT_DOUBLE_EQ(p[0].y, 4026000.25);
  const std::string short_line = writeFile("mulran_bad.csv", f.str() + "1564718976181407002,1,0,0,0,0,1,0,0,0,0,1\n");
  EXPECT_NE(expectThrowMessage([&] { readMulranGlobalPose(short_line); }).find("mulran_bad.csv:3: expected 13 values"),
            std::string::npos);
}

// A body frame turning in place by 90 degrees: the radar 1.5 m ahead of it swings from
// (1.5, 0) to (0, 1.5).
TEST(GroundTruthIo, SensorPoseAppliesTheLeverArm) {
  std::vector<PoseRecord> body(2);
  body[1].t = 1.0;
  body[1].yaw = kPi / 2;
  const auto s = withSensorPose(body, 1.5, 0.0, 0.0);
  EXPECT_NEAR(s[0].x, 1.5, 1e-12);
  EXPECT_NEAR(s[0].y, 0.0, 1e-12);
  EXPECT_NEAR(s[1].x, 0.0, 1e-12);
  EXPECT_NEAR(s[1].y, 1.5, 1e-12);
  EXPECT_NEAR(s[1].yaw, kPi / 2, 1e-12);
}

// A perfect radar odometry on a winding drive scored against the vehicle's truth shows drift
// that is only the lever arm; with --gt-sensor-pose it vanishes.
TEST(GroundTruthIo, LeverArmDriftVanishesWithTheSensorPose) {
  std::vector<PoseRecord> body;
  Eigen::Matrix3d T = Eigen::Matrix3d::Identity();
  for (int k = 0; k < 1200; ++k) {
    PoseRecord p;
    p.t = 0.25 * k;
    p.x = T(0, 2);
    p.y = T(1, 2);
    p.yaw = std::atan2(T(1, 0), T(0, 0));
    body.push_back(p);
    const double yaw_rate = 0.4 * std::sin(0.05 * k);  // rad/s, winding
    T = T * poseMatrix(2.5, 0.0, 0.25 * yaw_rate);
  }
  const auto radar = withSensorPose(body, 1.7, -0.2, 0.02);
  KittiConfig kc;
  kc.step = 4;
  const auto wrong = evaluateOdometry(radar, body, kc);
  const auto right = evaluateOdometry(radar, withSensorPose(body, 1.7, -0.2, 0.02), kc);
  ASSERT_TRUE(wrong.drift.valid && right.drift.valid);
  EXPECT_GT(wrong.drift.t_err_pct, 0.2);
  EXPECT_LT(right.drift.t_err_pct, 1e-6);
  EXPECT_LT(right.drift.r_err_deg_per_m, 1e-9);
}
