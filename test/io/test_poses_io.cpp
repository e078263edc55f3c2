// Pose CSV round trip and error messages naming file and line.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "spinradar/io/poses_io.hpp"

using namespace spinradar;
namespace fs = std::filesystem;

namespace {

std::string errorOf(const std::string& text, const std::string& name = "poses.csv") {
  std::istringstream in(text);
  try {
    readPoseCsv(in, name);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(PosesIo, RoundTripKeepsFullPrecision) {
  std::vector<PoseRecord> poses = {{1547131046.353776123, 0, 0, 0, 0, 0, 0},
                                   {1547131046.606586, 2.402550001, -0.0227, 0.0115, 9.5, 0.1, 0.04}};
  const std::string path = (fs::temp_directory_path() / "spinradar_test_poses.csv").string();
  writePoseCsv(path, poses);
  const PoseFile f = readPoseCsv(path);
  ASSERT_TRUE(f.has_velocity);
  ASSERT_EQ(f.poses.size(), 2u);
  EXPECT_NEAR(f.poses[0].t, poses[0].t, 1e-9);
  EXPECT_DOUBLE_EQ(f.poses[1].x, poses[1].x);
  EXPECT_DOUBLE_EQ(f.poses[1].yaw, poses[1].yaw);
  EXPECT_DOUBLE_EQ(f.poses[1].wz, poses[1].wz);
  std::ifstream in(path);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "t,x,y,yaw,vx,vy,wz");
  fs::remove(path);
}

TEST(PosesIo, IncrementalWriter) {
  const std::string path = (fs::temp_directory_path() / "spinradar_test_poses_w.csv").string();
  fs::remove(path);
  {
    PoseCsvWriter w(path, false);
    w.write({1.0, 1, 2, 3});
    // Not closed (a failed run): nothing appears, no temporary file stays behind.
  }
  EXPECT_FALSE(fs::exists(path));
  for (const auto& e : fs::directory_iterator(fs::temp_directory_path()))
    EXPECT_EQ(e.path().filename().string().find(".spinradar_test_poses_w.partial"), std::string::npos);
  {
    PoseCsvWriter w(path, false);
    w.write({1.0, 1, 2, 3});
    w.write({2.0, 4, 5, 6});
    w.close();
  }
  const PoseFile f = readPoseCsv(path);
  EXPECT_FALSE(f.has_velocity);
  ASSERT_EQ(f.poses.size(), 2u);
  EXPECT_EQ(f.poses[1].y, 5.0);
  fs::remove(path);
}

TEST(PosesIo, ColumnsInAnyOrderExtraIgnored) {
  std::istringstream in("# comment\nyaw,t,note,x,y\n0.5,1.0,abc,2,3\n\n0.6,2.0,def,4,5\n");
  const PoseFile f = readPoseCsv(in, "x.csv");
  ASSERT_EQ(f.poses.size(), 2u);
  EXPECT_EQ(f.poses[1].x, 4.0);
  EXPECT_EQ(f.poses[1].yaw, 0.6);
}

TEST(PosesIo, ErrorsNameFileAndLine) {
  EXPECT_NE(errorOf("t,x,y\n1,2,3\n").find("poses.csv:1: header"), std::string::npos);
  EXPECT_NE(errorOf("t,x,y,yaw\n1,2,3,4\n2,2,oops,4\n").find("poses.csv:3: column 'y': 'oops' is not a number"),
            std::string::npos)
      << errorOf("t,x,y,yaw\n1,2,3,4\n2,2,oops,4\n");
  EXPECT_NE(errorOf("t,x,y,yaw\n1,2,3,4\n2,2,3\n").find("poses.csv:3: expected 4 columns"),
            std::string::npos);
  EXPECT_NE(errorOf("t,x,y,yaw\n1,2,3,4\n1,2,3,4\n").find("poses.csv:3: time"), std::string::npos);
  EXPECT_NE(errorOf("t,x,y,yaw\n1,2,nan,4\n").find("poses.csv:2:"), std::string::npos);
  EXPECT_NE(errorOf("").find("empty"), std::string::npos);
  try {
    readPoseCsv("/nonexistent/poses.csv");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/poses.csv"), std::string::npos);
  }
}

// TUM line by hand: yaw 90 degrees is the quaternion (0, 0, sin 45, cos 45).
TEST(PosesIo, TumRowByHand) {
  PoseRecord p;
  p.t = 1547131046.353776;
  p.x = 2.5;
  p.y = -1.25;
  p.yaw = 1.5707963267948966;
  std::ostringstream out;
  writeTumRow(out, p);
  std::istringstream in(out.str());
  double t, x, y, z, qx, qy, qz, qw;
  ASSERT_TRUE(in >> t >> x >> y >> z >> qx >> qy >> qz >> qw);
  EXPECT_NEAR(t, 1547131046.353776, 1e-6);
  EXPECT_EQ(x, 2.5);
  EXPECT_EQ(y, -1.25);
  EXPECT_EQ(z, 0.0);
  EXPECT_EQ(qx, 0.0);
  EXPECT_EQ(qy, 0.0);
  EXPECT_NEAR(qz, std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(qw, std::sqrt(0.5), 1e-15);
  EXPECT_EQ(out.str().back(), '\n');
}
