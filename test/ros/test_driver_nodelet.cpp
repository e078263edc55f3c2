// rostest node for test/ros/driver.test: checks what the DriverNodelet publishes.
#include <gtest/gtest.h>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <spinradar/RadarScan.h>

namespace {
std::vector<spinradar::RadarScan::ConstPtr> g_scans;
int g_images = 0;
bool g_diag = false;
void onScan(const spinradar::RadarScan::ConstPtr& m) { g_scans.push_back(m); }
void onImage(const sensor_msgs::Image::ConstPtr&) { ++g_images; }
void onDiagnostics(const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
  for (const auto& st : m->status)
    if (st.name.find("Navtech driver") != std::string::npos) g_diag = true;
}
}  // namespace

TEST(DriverNodelet, PublishesScansImagesAndDiagnostics) {
  ros::NodeHandle nh;
  auto s1 = nh.subscribe("scan", 10, onScan);
  auto s2 = nh.subscribe("polar_image", 10, onImage);
  auto s3 = nh.subscribe("/diagnostics", 10, onDiagnostics);
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(60);
  while (ros::ok() && ros::WallTime::now() < end && (g_scans.size() < 5 || g_images < 2 || !g_diag)) {
    ros::spinOnce();
    ros::WallDuration(0.02).sleep();
  }
  ASSERT_GE(g_scans.size(), 5u);
  EXPECT_GE(g_images, 2);
  EXPECT_TRUE(g_diag);
  for (size_t i = 0; i < g_scans.size(); ++i) {
    const auto& m = *g_scans[i];
    EXPECT_EQ(m.header.frame_id, "radar_test");
    EXPECT_EQ(m.azimuths, 400u);
    EXPECT_EQ(m.bins, 3768u);
    EXPECT_EQ(m.bit_depth, 8);
    EXPECT_EQ(m.data8.size(), size_t(m.azimuths) * m.bins);
    EXPECT_EQ(m.valid.size(), m.azimuths);
    EXPECT_EQ(m.missing_azimuths, 0u);
    for (size_t a = 1; a < m.stamp_ns.size(); ++a) EXPECT_GT(m.stamp_ns[a], m.stamp_ns[a - 1]);
    if (i > 0) {  // one rotation apart (4 Hz), stamps from the sensor's (wall) clock
      const double dt = (m.header.stamp - g_scans[i - 1]->header.stamp).toSec();
      EXPECT_NEAR(dt, 0.25 * double(m.sequence - g_scans[i - 1]->sequence), 1e-3);
    }
  }
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_driver_nodelet");
  ros::NodeHandle nh;  // keeps the node alive for the test
  return RUN_ALL_TESTS();
}
