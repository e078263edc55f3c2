// rostest, end to end on loopback: `spinradar serve` (simulator as a live Navtech sensor,
// motion distortion and Doppler on, simulator clock) -> driver -> features -> estimator.
// Checks the odometry against the scene's true trajectory, that tf and both clouds come at
// the scan rate, and that undistorted clouds of consecutive scans line up better than raw
// ones. Also records the scans into a bag and the odometry into a CSV for the playback test.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>

#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_msgs/TFMessage.h>

#include <spinradar/RadarScan.h>

#include "cloud_alignment.hpp"
#include "spinradar/evaluation/evaluation.hpp"
#include "spinradar/core/lie.hpp"
#include "spinradar/io/poses_io.hpp"
#include "spinradar/sim/scenes.hpp"

namespace {

using Cloud = std::vector<Eigen::Vector2d>;

struct Recorder {
  std::mutex mutex;
  std::vector<nav_msgs::Odometry> odom;
  std::map<int64_t, Cloud> raw, corrected;
  std::vector<int64_t> tf_stamps;
  int scans = 0;
  std::unique_ptr<rosbag::Bag> bag;
};

Recorder g;

Cloud toPoints(const sensor_msgs::PointCloud2& c) {
  Cloud out;
  out.reserve(c.width * c.height);
  for (sensor_msgs::PointCloud2ConstIterator<float> x(c, "x"); x != x.end(); ++x) out.emplace_back(x[0], x[1]);
  return out;
}

double yawOf(const geometry_msgs::Quaternion& q) {
  return std::atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z));
}

/// Collects `n` odometry messages (and everything else that comes meanwhile).
bool collect(int n, double timeout_s) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout_s);
  while (ros::ok() && ros::WallTime::now() < end) {
    {
      std::lock_guard<std::mutex> lock(g.mutex);
      if (static_cast<int>(g.odom.size()) >= n) return true;
    }
    ros::WallDuration(0.05).sleep();
  }
  return false;
}

class LiveSim : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    ros::NodeHandle pnh("~");
    scans_ = pnh.param("scans", 60);
    timeout_ = pnh.param("timeout", 120.0);
    scene_ = pnh.param<std::string>("scene", "city");
    ASSERT_TRUE(collect(scans_, timeout_)) << "fewer than " << scans_ << " odometry messages in "
                                           << timeout_ << " s";
    ros::WallDuration(1.0).sleep();  // the last clouds and tf
    std::lock_guard<std::mutex> lock(g.mutex);
    if (g.bag) g.bag->close();
    const std::string csv = pnh.param<std::string>("odom_csv", "");
    std::vector<spinradar::PoseRecord> est;
    for (const auto& o : g.odom) {
      spinradar::PoseRecord r;
      r.t = o.header.stamp.toSec();
      r.x = o.pose.pose.position.x;
      r.y = o.pose.pose.position.y;
      r.yaw = yawOf(o.pose.pose.orientation);
      r.vx = o.twist.twist.linear.x;
      r.vy = o.twist.twist.linear.y;
      r.wz = o.twist.twist.angular.z;
      est.push_back(r);
    }
    est_ = est;
    if (!csv.empty()) spinradar::writePoseCsv(csv, est, true);
    const auto scene = spinradar::sim::builtinScene(scene_);
    for (const auto& s : scene.trajectory.samples()) {
      spinradar::PoseRecord r;
      r.t = s.t;
      r.x = s.pose.x;
      r.y = s.pose.y;
      r.yaw = s.pose.yaw;
      truth_.push_back(r);
    }
  }

  static Eigen::Matrix3d truthAt(int64_t stamp_ns) {
    spinradar::PoseRecord p;
    EXPECT_TRUE(spinradar::interpolatePose(truth_, stamp_ns * 1e-9, p));
    return spinradar::poseMatrix(p);
  }

  static int scans_;
  static double timeout_;
  static std::string scene_;
  static std::vector<spinradar::PoseRecord> est_, truth_;
};
int LiveSim::scans_ = 0;
double LiveSim::timeout_ = 0;
std::string LiveSim::scene_;
std::vector<spinradar::PoseRecord> LiveSim::est_, LiveSim::truth_;

TEST_F(LiveSim, OdometryMatchesTrueTrajectory) {
  spinradar::KittiConfig kitti;
  kitti.lengths = {25, 50, 75, 100};  // the run is short: KITTI's 100..800 m do not fit
  kitti.step = 1;
  const auto report = spinradar::evaluateOdometry(est_, truth_, kitti);
  std::printf("[live sim] %zu scans, %.1f m path, drift %.2f %% and %.4f deg/m (KITTI-style over "
              "25-100 m), per-frame translation error mean %.3f m, final position error %.2f m "
              "(%.2f %%)\n",
              report.poses.t.size(), report.path_length, report.drift.t_err_pct,
              report.drift.r_err_deg_per_m, report.frames.t_err_m.mean, report.final_error_m,
              report.final_error_pct);
  RecordProperty("drift_t_pct", std::to_string(report.drift.t_err_pct));
  RecordProperty("drift_r_deg_per_m", std::to_string(report.drift.r_err_deg_per_m));
  EXPECT_EQ(report.poses.dropped, 0);
  ASSERT_TRUE(report.drift.valid) << "path " << report.path_length << " m";
  EXPECT_LT(report.drift.t_err_pct, 5.0);
  EXPECT_LT(report.drift.r_err_deg_per_m, 0.05);
}

TEST_F(LiveSim, TfAndCloudsAtTheScanRate) {
  std::lock_guard<std::mutex> lock(g.mutex);
  const size_t n = g.odom.size();
  ASSERT_FALSE(g.tf_stamps.empty() || g.raw.empty() || g.corrected.empty());
  // The test's subscriptions connect one by one at start-up, and a message published before a
  // subscriber is connected never reaches it: check from the first scan every subscription
  // saw, which must come within the first few scans.
  const int64_t from = std::max({*std::min_element(g.tf_stamps.begin(), g.tf_stamps.end()),
                                 g.raw.begin()->first, g.corrected.begin()->first});
  size_t first = 0;
  while (first < n && static_cast<int64_t>(g.odom[first].header.stamp.toNSec()) < from) ++first;
  ASSERT_LE(first, 4u) << "tf and clouds only from scan " << first;
  const size_t checked = n - first;
  // Every scan gives one odometry message, one tf and two clouds with the same stamp.
  EXPECT_GE(g.tf_stamps.size(), checked);
  EXPECT_GE(g.raw.size(), checked - 1);
  EXPECT_GE(g.corrected.size(), checked - 1);
  for (size_t k = first; k < n; ++k) {
    const int64_t s = g.odom[k].header.stamp.toNSec();
    EXPECT_TRUE(std::find(g.tf_stamps.begin(), g.tf_stamps.end(), s) != g.tf_stamps.end() ||
                k + 1 == n) << "no tf at " << s;
  }
  // Consecutive odometry stamps are one rotation (4 Hz) apart: no scan was dropped.
  int gaps = 0;
  for (size_t k = 1; k < n; ++k) {
    const double dt = (g.odom[k].header.stamp - g.odom[k - 1].header.stamp).toSec();
    EXPECT_NEAR(dt, 0.25, 0.01) << "between scans " << k - 1 << " and " << k;
    gaps += std::abs(dt - 0.25) > 0.01;
  }
  std::printf("[live sim] %zu odometry, %zu tf, %zu raw and %zu corrected clouds (checked from "
              "scan %zu); %d gaps\n", n, g.tf_stamps.size(), g.raw.size(), g.corrected.size(),
              first, gaps);
}

TEST_F(LiveSim, UndistortedCloudsLineUpBetterThanRaw) {
  std::lock_guard<std::mutex> lock(g.mutex);
  // Place each scan's cloud in the world with the true pose at the scan's reference time and
  // measure how far its points lie from the previous scan's (static scene parts).
  auto score = [](const std::map<int64_t, Cloud>& clouds) {
    double sum = 0;
    int pairs = 0;
    Cloud prev;
    for (const auto& [stamp, pts] : clouds) {
      const Eigen::Matrix3d T = truthAt(stamp);
      Cloud world;
      world.reserve(pts.size());
      for (const auto& p : pts) world.push_back(T.topLeftCorner<2, 2>() * p + T.topRightCorner<2, 1>());
      if (!prev.empty()) {
        const auto a = spinradar_test::alignment(prev, world, 1.0);
        if (a.pairs > 50) {
          sum += a.mean;
          ++pairs;
        }
      }
      prev = std::move(world);
    }
    return pairs ? sum / pairs : -1.0;
  };
  const double raw = score(g.raw), corrected = score(g.corrected);
  std::printf("[live sim] scan-to-scan alignment (mean nearest-neighbour distance, true poses): raw "
              "%.3f m, undistorted + Doppler-corrected %.3f m (%.0f %% closer)\n",
              raw, corrected, 100 * (1 - corrected / raw));
  RecordProperty("alignment_raw_m", std::to_string(raw));
  RecordProperty("alignment_corrected_m", std::to_string(corrected));
  ASSERT_GT(raw, 0);
  ASSERT_GT(corrected, 0);
  EXPECT_LT(corrected, 0.9 * raw);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_live_sim");
  ros::NodeHandle nh, pnh("~");
  const std::string bag = pnh.param<std::string>("bag", "");
  if (!bag.empty()) {
    g.bag = std::make_unique<rosbag::Bag>(bag, rosbag::bagmode::Write);
  }
  auto s1 = nh.subscribe<nav_msgs::Odometry>("odom", 1000, boost::function<void(const nav_msgs::OdometryConstPtr&)>([](const nav_msgs::OdometryConstPtr& m) {
    std::lock_guard<std::mutex> lock(g.mutex);
    g.odom.push_back(*m);
  }));
  auto s2 = nh.subscribe<sensor_msgs::PointCloud2>("points_raw", 1000, boost::function<void(const sensor_msgs::PointCloud2ConstPtr&)>([](const sensor_msgs::PointCloud2ConstPtr& m) {
    std::lock_guard<std::mutex> lock(g.mutex);
    g.raw[m->header.stamp.toNSec()] = toPoints(*m);
  }));
  auto s3 = nh.subscribe<sensor_msgs::PointCloud2>("points_corrected", 1000, boost::function<void(const sensor_msgs::PointCloud2ConstPtr&)>([](const sensor_msgs::PointCloud2ConstPtr& m) {
    std::lock_guard<std::mutex> lock(g.mutex);
    g.corrected[m->header.stamp.toNSec()] = toPoints(*m);
  }));
  auto s4 = nh.subscribe<tf2_msgs::TFMessage>("/tf", 1000, boost::function<void(const tf2_msgs::TFMessageConstPtr&)>([](const tf2_msgs::TFMessageConstPtr& m) {
    std::lock_guard<std::mutex> lock(g.mutex);
    for (const auto& t : m->transforms)
      if (t.header.frame_id == "odom" && t.child_frame_id == "base_link") g.tf_stamps.push_back(t.header.stamp.toNSec());
  }));
  auto s5 = nh.subscribe<spinradar::RadarScan>("scan", 1000, boost::function<void(const spinradar::RadarScanConstPtr&)>([](const spinradar::RadarScanConstPtr& m) {
    std::lock_guard<std::mutex> lock(g.mutex);
    // rosbag refuses time 0 (the simulator clock starts there): bag time at least 1 ns.
    if (g.bag && g.bag->isOpen())
      g.bag->write("scan", std::max(m->header.stamp, ros::Time(0, 1)), *m);
  }));
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int rc = RUN_ALL_TESTS();
  spinner.stop();
  return rc;
}
