// rostest: a bag of the live run's scans (written by test_live_sim) played back with
// rosbag play on simulated time through rosbag.launch gives the same odometry as the live run.
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>

#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>

#include "spinradar/core/lie.hpp"
#include "spinradar/io/poses_io.hpp"

namespace {

std::mutex g_mutex;
std::map<int64_t, spinradar::PoseRecord> g_odom;  // by stamp (ns)

double yawOf(const geometry_msgs::Quaternion& q) {
  return std::atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z));
}

TEST(BagPlayback, SameOdometryAsTheLiveRun) {
  ros::NodeHandle pnh("~");
  const std::string live_csv = pnh.param<std::string>("live_csv", "");
  const double timeout = pnh.param("timeout", 90.0);
  ASSERT_FALSE(live_csv.empty());
  const auto live = spinradar::readPoseCsv(live_csv).poses;
  ASSERT_GT(live.size(), 10u);
  std::map<int64_t, spinradar::PoseRecord> live_by_stamp;
  for (const auto& p : live) live_by_stamp[std::llround(p.t * 1e9)] = p;

  // Wait until the playback has produced odometry for every live stamp, or went quiet.
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  size_t last = 0;
  ros::WallTime last_change = ros::WallTime::now();
  while (ros::WallTime::now() < end) {
    size_t n;
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      n = g_odom.size();
    }
    if (n >= live.size()) break;
    if (n != last) last = n, last_change = ros::WallTime::now();
    if (n > 0 && (ros::WallTime::now() - last_change).toSec() > 10) break;
    ros::WallDuration(0.1).sleep();
  }

  std::lock_guard<std::mutex> lock(g_mutex);
  // Compare frame-to-frame motions between consecutive stamps both runs have (the live run
  // may have started a scan earlier or later than the recording).
  std::vector<int64_t> common;
  for (const auto& [stamp, p] : g_odom)
    if (live_by_stamp.count(stamp)) common.push_back(stamp);
  ASSERT_GE(common.size(), live.size() * 8 / 10)
      << "playback odometry for only " << common.size() << " of " << live.size() << " live scans";
  double max_dt = 0, max_dr = 0;
  for (size_t k = 2; k < common.size(); ++k) {
    auto rel = [](const spinradar::PoseRecord& a, const spinradar::PoseRecord& b) -> Eigen::Matrix3d {
      return spinradar::se2::inverse(spinradar::poseMatrix(a)) * spinradar::poseMatrix(b);
    };
    const Eigen::Matrix3d e = spinradar::se2::inverse(rel(live_by_stamp[common[k - 1]], live_by_stamp[common[k]])) *
                              rel(g_odom[common[k - 1]], g_odom[common[k]]);
    max_dt = std::max(max_dt, e.topRightCorner<2, 1>().norm());
    max_dr = std::max(max_dr, std::abs(std::atan2(e(1, 0), e(0, 0))));
  }
  std::printf("[bag playback] %zu of %zu live scans replayed; largest frame-to-frame difference to "
              "the live run: %.2e m, %.2e rad\n",
              common.size(), live.size(), max_dt, max_dr);
  EXPECT_LT(max_dt, 1e-6);
  EXPECT_LT(max_dr, 1e-8);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_bag_playback");
  ros::NodeHandle nh;
  auto sub = nh.subscribe<nav_msgs::Odometry>("odom", 1000, boost::function<void(const nav_msgs::OdometryConstPtr&)>([](const nav_msgs::OdometryConstPtr& m) {
    spinradar::PoseRecord r;
    r.t = m->header.stamp.toSec();
    r.x = m->pose.pose.position.x;
    r.y = m->pose.pose.position.y;
    r.yaw = yawOf(m->pose.pose.orientation);
    std::lock_guard<std::mutex> lock(g_mutex);
    g_odom[static_cast<int64_t>(m->header.stamp.toNSec())] = r;
  }));
  ros::AsyncSpinner spinner(1);
  spinner.start();
  const int rc = RUN_ALL_TESTS();
  spinner.stop();
  return rc;
}
