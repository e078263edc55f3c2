// KITTI-style drift and per-frame errors against hand-computed values, the Oxford ground-truth
// reader on synthetic and real files.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "spinradar/evaluation/evaluation.hpp"

using namespace spinradar;
namespace fs = std::filesystem;

namespace {

constexpr double kPi = 3.14159265358979323846;

/// Straight drive along x: frames every `step_m` metres (0.25 is exact in binary, so path
/// distances are exact and the devkit's "first frame beyond start + len" is predictable).
std::vector<PoseRecord> straightDrive(int n, double step_m, double dt) {
  std::vector<PoseRecord> p(n);
  for (int k = 0; k < n; ++k) {
    p[k].t = 100.0 + k * dt;
    p[k].x = k * step_m;
  }
  return p;
}

/// Compounds a constant body motion (dx forward, dyaw) per frame.
std::vector<PoseRecord> compound(int n, double dx, double dyaw, double dt) {
  std::vector<PoseRecord> p(n);
  Eigen::Matrix3d T = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d step = poseMatrix(dx, 0.0, dyaw);
  for (int k = 0; k < n; ++k) {
    if (k > 0) T = T * step;
    p[k].t = 100.0 + k * dt;
    p[k].x = T(0, 2);
    p[k].y = T(1, 2);
    p[k].yaw = std::atan2(T(1, 0), T(0, 0));
  }
  return p;
}

std::string tempPath(const std::string& name) {
  return (fs::temp_directory_path() / ("spinradar_test_eval_" + name)).string();
}

void writeFile(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
}

const DriftBin* findBin(const std::vector<DriftBin>& bins, double key) {
  for (const auto& b : bins)
    if (std::fabs(b.key - key) < 1e-9) return &b;
  return nullptr;
}

}  // namespace

TEST(Evaluation, ScaleErrorGivesOnePercentTranslationalDrift) {
  // 1 % too long every frame, straight: each segment's error is 1 % of the segment actually
  // driven. The devkit's segment ends at the first frame *beyond* start + len, i.e. len + 0.25.
  const int n = 4000;  // 1000 m
  const auto gt = straightDrive(n, 0.25, 0.025);
  auto est = straightDrive(n, 0.25 * 1.01, 0.025);
  const auto r = evaluateOdometry(est, gt);
  ASSERT_TRUE(r.drift.valid);
  for (double len : {100.0, 200.0, 400.0, 800.0}) {
    const DriftBin* b = findBin(r.drift.by_length, len);
    ASSERT_NE(b, nullptr) << len;
    EXPECT_NEAR(b->t_err_pct, 1.0 * (len + 0.25) / len, 1e-9) << len;
    EXPECT_NEAR(b->r_err_deg_per_m, 0.0, 1e-12);
  }
  EXPECT_NEAR(r.drift.t_err_pct, 1.0, 0.0026);
  EXPECT_GT(r.drift.t_err_pct, 1.0);
  EXPECT_NEAR(r.drift.r_err_deg_per_m, 0.0, 1e-12);
  // 4000 frames, first frames every 10: a segment of len fits when 0.25 (3999 - first) > len.
  int expected_segments = 0;
  for (int first = 0; first < n; first += 10)
    for (double len = 100; len <= 800; len += 100)
      if (0.25 * (n - 1 - first) > len) ++expected_segments;
  EXPECT_EQ(static_cast<int>(r.drift.segments.size()), expected_segments);
  EXPECT_NEAR(r.final_error_m, 0.01 * 0.25 * (n - 1), 1e-9);
}

TEST(Evaluation, YawRateBiasGivesKnownDegreesPerMetre) {
  // Truth straight; the estimate turns an extra 1e-4 rad per 0.25 m frame (0.4 mrad/m, e.g. a
  // 0.004 rad/s gyro-like bias at 10 m/s). Over a segment of len the last frame is
  // len / 0.25 + 1 frames on, so the rotation error is (4 len + 1) 1e-4 rad.
  const int n = 4000;
  const double dyaw = 1e-4;
  const auto gt = straightDrive(n, 0.25, 0.025);
  const auto est = compound(n, 0.25, dyaw, 0.025);
  const auto r = evaluateOdometry(est, gt);
  ASSERT_TRUE(r.drift.valid);
  for (double len : {100.0, 300.0, 800.0}) {
    const DriftBin* b = findBin(r.drift.by_length, len);
    ASSERT_NE(b, nullptr);
    EXPECT_NEAR(b->r_err_deg_per_m, (4 * len + 1) * dyaw / len * 180.0 / kPi, 1e-9) << len;
  }
  // Mean over segments: within (4 len + 1) / (4 len) of 0.4 mrad/m = 0.0229 deg/m.
  EXPECT_NEAR(r.drift.r_err_deg_per_m, 4e-4 * 180.0 / kPi, 0.0025 * 4e-4 * 180.0 / kPi);
}

TEST(Evaluation, SpeedBandsFollowTheDevkit) {
  // 0.25 m per 25 ms = 10 m/s. A 100 m segment spans 401 frames = 10.025 s: 9.975 m/s, inside
  // the 8 and 10 m/s bands (|v - c| < 2) but not the 12 m/s one.
  const auto gt = straightDrive(4000, 0.25, 0.025);
  const auto est = straightDrive(4000, 0.25 * 1.02, 0.025);
  const auto r = evaluateOdometry(est, gt);
  ASSERT_NE(findBin(r.drift.by_speed, 10.0), nullptr);
  ASSERT_NE(findBin(r.drift.by_speed, 8.0), nullptr);
  EXPECT_EQ(findBin(r.drift.by_speed, 12.0), nullptr);
  EXPECT_EQ(findBin(r.drift.by_speed, 10.0)->count, static_cast<int>(r.drift.segments.size()));
  for (const auto& s : r.drift.segments) EXPECT_NEAR(s.speed, s.length / (0.025 * (s.last_frame - s.first_frame)), 1e-9);
}

TEST(Evaluation, ShortSequenceHasNoDriftButFrameErrors) {
  const auto gt = straightDrive(10, 1.0, 0.25);
  const auto est = straightDrive(10, 1.02, 0.25);
  const auto r = evaluateOdometry(est, gt);
  EXPECT_FALSE(r.drift.valid);
  ASSERT_EQ(r.frames.frames.size(), 9u);
  for (const auto& f : r.frames.frames) {
    EXPECT_NEAR(f.t_err, 0.02, 1e-12);
    EXPECT_NEAR(f.t_err_pct, 2.0, 1e-9);
    EXPECT_NEAR(f.speed, 4.0, 1e-9);
  }
  EXPECT_NEAR(r.frames.t_err_m.median, 0.02, 1e-12);
  EXPECT_NE(formatReport(r).find("not available"), std::string::npos);
}

TEST(Evaluation, RotationErrorPerFrame) {
  const auto gt = compound(5, 2.0, 0.01, 0.25);
  const auto est = compound(5, 2.0, 0.012, 0.25);
  const auto r = evaluateOdometry(est, gt);
  ASSERT_EQ(r.frames.frames.size(), 4u);
  for (const auto& f : r.frames.frames) {
    EXPECT_NEAR(f.r_err, 0.002, 1e-12);
    EXPECT_NEAR(f.gt_dyaw, 0.01, 1e-12);
    EXPECT_NEAR(f.est_step, 2.0, 1e-12);
  }
}

TEST(Evaluation, AssociationInterpolatesAndDropsOutside) {
  std::vector<PoseRecord> gt(3);
  gt[0] = {0.0, 0.0, 0.0, 3.0, 0, 0, 0};
  gt[1] = {1.0, 10.0, 0.0, -3.0, 0, 0, 0};  // yaw crosses +-pi: shortest arc
  gt[2] = {2.0, 20.0, 4.0, -3.0, 0, 0, 0};
  PoseRecord p;
  ASSERT_TRUE(interpolatePose(gt, 0.5, p));
  EXPECT_NEAR(p.x, 5.0, 1e-12);
  EXPECT_NEAR(std::fabs(p.yaw), kPi, 1e-12);
  ASSERT_TRUE(interpolatePose(gt, 1.25, p));
  EXPECT_NEAR(p.y, 1.0, 1e-12);
  EXPECT_FALSE(interpolatePose(gt, 2.1, p));
  EXPECT_TRUE(interpolatePose(gt, 2.00005, p));  // within the tolerance
  std::vector<PoseRecord> est = {{-1.0}, {0.25}, {0.75}, {3.0}};
  const auto a = associatePoses(est, gt);
  EXPECT_EQ(a.dropped, 2);
  ASSERT_EQ(a.t.size(), 2u);
  EXPECT_NEAR(a.gt[1](0, 2), 7.5, 1e-12);
}

TEST(Evaluation, NoOverlapNamesTheClocks) {
  const auto gt = straightDrive(10, 1.0, 0.25);
  auto est = gt;
  for (auto& p : est) p.t += 1e6;
  try {
    evaluateOdometry(est, gt);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("same clock"), std::string::npos) << e.what();
  }
}

TEST(Evaluation, OxfordReaderComposesAndConvertsFrames) {
  const std::string path = tempPath("oxford.csv");
  writeFile(path,
            "source_timestamp,destination_timestamp,x,y,z,roll,pitch,yaw,source_radar_timestamp,"
            "destination_radar_timestamp\n"
            "1250000,1000000,2.0,0.5,0,0,0,0.1,1250000,1000000\n"
            "1500000,1250000,2.0,0.0,0,0,0,0.0,1500000,1250000\n");
  const auto p = readGroundTruth(path);
  ASSERT_EQ(p.size(), 3u);
  EXPECT_DOUBLE_EQ(p[0].t, 1.0);
  EXPECT_DOUBLE_EQ(p[1].t, 1.25);
  // Dataset y right / yaw clockwise -> REP 103 y left / yaw CCW.
  EXPECT_NEAR(p[1].x, 2.0, 1e-12);
  EXPECT_NEAR(p[1].y, -0.5, 1e-12);
  EXPECT_NEAR(p[1].yaw, -0.1, 1e-12);
  // Second motion is 2 m forward in the frame of scan 1 (yawed -0.1 rad).
  EXPECT_NEAR(p[2].x, 2.0 + 2.0 * std::cos(-0.1), 1e-12);
  EXPECT_NEAR(p[2].y, -0.5 + 2.0 * std::sin(-0.1), 1e-12);
  fs::remove(path);
}

TEST(Evaluation, OxfordReaderRejectsBrokenChainWithLine) {
  const std::string path = tempPath("oxford_broken.csv");
  writeFile(path,
            "source_timestamp,destination_timestamp,x,y,z,roll,pitch,yaw,source_radar_timestamp,"
            "destination_radar_timestamp\n"
            "1250000,1000000,2.0,0.5,0,0,0,0.1,1250000,1000000\n"
            "1600000,1300000,2.0,0.0,0,0,0,0.0,1600000,1300000\n");
  try {
    readOxfordRadarOdometry(path);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path + ":3:"), std::string::npos) << e.what();
  }
  writeFile(path,
            "source_timestamp,destination_timestamp,x,y,z,roll,pitch,yaw,source_radar_timestamp,"
            "destination_radar_timestamp\n"
            "1250000,1000000,2.0,abc,0,0,0,0.1,1250000,1000000\n");
  try {
    readOxfordRadarOdometry(path);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path + ":2:"), std::string::npos) << e.what();
  }
  fs::remove(path);
}

TEST(Evaluation, OxfordRealGroundTruth) {
  const std::string path = std::string(SPINRADAR_SHARED_DIR) +
                           "/realdata/oxford_2019-01-10-14-36-48/gt/radar_odometry.csv";
  if (!fs::exists(path)) GTEST_SKIP() << "real Oxford sample not found at " << path;
  const auto p = readGroundTruth(path);
  ASSERT_EQ(p.size(), 3u);
  EXPECT_NEAR(p[0].t, 1547131046.353776, 1e-6);
  EXPECT_NEAR(p[1].t, 1547131046.606586, 1e-6);
  EXPECT_NEAR(p[2].t, 1547131046.858560, 1e-6);
  // Row 1: x 2.402550, y -0.022744, yaw -0.011546 in the dataset frame (y right).
  EXPECT_NEAR(p[1].x, 2.402550, 1e-9);
  EXPECT_NEAR(p[1].y, 0.022744, 1e-9);
  EXPECT_NEAR(p[1].yaw, 0.011546, 1e-9);
  const double c = std::cos(0.011546), s = std::sin(0.011546);
  EXPECT_NEAR(p[2].x, 2.402550 + c * 2.286416 - s * 0.011055, 1e-9);
  EXPECT_NEAR(p[2].y, 0.022744 + s * 2.286416 + c * 0.011055, 1e-9);
  EXPECT_NEAR(p[2].yaw, 0.011546 + 0.010155, 1e-9);
  // About 9.5 m/s, as the sample README says.
  EXPECT_NEAR(std::hypot(p[1].x, p[1].y) / (p[1].t - p[0].t), 9.5, 0.3);
}
