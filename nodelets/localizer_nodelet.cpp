// Localizer nodelet: metric localization of the live polar scans (spinradar/RadarScan on `scan`)
// against a map drive loaded once (`map_dir` scans, `map_poses` t,x,y,yaw CSV of the radar in
// the map), RSD descriptors and compensated RANSAC (spinradar/localization/localizer.hpp). The
// estimator's `odom` supplies each scan's velocity and the odom pose at the scan time; out:
// tf map -> odom. Results wait for the odometry of their scan (the estimator runs after the
// feature nodelet, so it lags the scan).
#include <cstdlib>
#include <deque>
#include <memory>
#include <mutex>

#include <nav_msgs/Odometry.h>
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include "spinradar/localization/localizer.hpp"
#include "spinradar_ros/conversions.hpp"
#include "spinradar_ros/map_odom.hpp"
#include "spinradar_ros/params.hpp"
#include "spinradar_ros/polar_scan_conversions.hpp"

namespace spinradar_ros {

namespace se2 = spinradar::se2;

class LocalizerNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    spinradar::LocalizerConfig loc;
    spinradar::RsdConfig rsd;
    spinradar::PipelineConfig pipeline;
    loadParams(pnh, loc);
    loadParams(pnh, rsd);
    loadParams(pnh, pipeline);
    const std::string map_dir = pnh.param<std::string>("map_dir", "");
    const std::string map_poses = pnh.param<std::string>("map_poses", "");
    map_frame_ = pnh.param<std::string>("map_frame", "map");
    odom_frame_ = pnh.param<std::string>("odom_frame", "odom");
    base_frame_ = pnh.param<std::string>("base_frame", "base_link");
    radar_frame_ = pnh.param<std::string>("radar_frame", "");  // "" = the scans' frame_id
    tf_timeout_ = pnh.param("tf_timeout", 2.0);
    if (map_dir.empty() || map_poses.empty()) {
      NODELET_WARN("map_dir or map_poses not set: localization off");
      return;
    }
    const bool initial = pnh.param("use_initial_pose", false);
    // With a pose prior, keypoints are matched near where the prior puts them (unless set).
    if (initial && !pnh.hasParam("loc_match_gate")) loc.loc_match_gate = 5.0;
    localizer_ = std::make_unique<spinradar::Localizer>(loc, rsd, pipeline);  // validates
    const int n = localizer_->loadMap(map_dir, map_poses);  // throws naming the file
    if (initial)
      localizer_->setInitialPose(se2::fromXyYaw(Eigen::Vector3d(pnh.param("initial_x", 0.0),
                                                                pnh.param("initial_y", 0.0),
                                                                pnh.param("initial_yaw", 0.0))));
    NODELET_INFO("map of %d scans from %s; publishing %s -> %s", n, map_dir.c_str(),
                 map_frame_.c_str(), odom_frame_.c_str());

    tf_listener_ = std::make_unique<tf2_ros::TransformListener>(tf_buffer_, nh);
    const int queue = pnh.param("queue_size", 20);
    odom_sub_ = nh.subscribe("odom", 50, &LocalizerNodelet::onOdom, this);
    scan_sub_ = nh.subscribe("scan", queue, &LocalizerNodelet::onScan, this);
  }

  void onOdom(const nav_msgs::OdometryConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto& p = msg->pose.pose;
    geometry_msgs::Transform t;
    t.translation.x = p.position.x;
    t.translation.y = p.position.y;
    t.rotation = p.orientation;
    history_.add(toNs(msg->header.stamp), toSE2(t));
    const auto& v = msg->twist.twist;
    velocity_base_ = Eigen::Vector3d(v.linear.x, v.linear.y, v.angular.z);
    velocity_stamp_ns_ = toNs(msg->header.stamp);
    flush();
  }

  void onScan(const spinradar::RadarScanConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!mounting_known_) lookUpMounting(radar_frame_.empty() ? msg->header.frame_id : radar_frame_);
    try {
      fromMsg(*msg, scan_);
    } catch (const std::exception& e) {
      NODELET_ERROR("dropping scan at %.3f: %s", msg->header.stamp.toSec(), e.what());
      return;
    }
    // The odometry's latest velocity, in the radar frame, when recent; else the localizer
    // estimates it from the previous live scan.
    const bool recent = velocity_stamp_ns_ > 0 &&
                        std::llabs(toNs(msg->header.stamp) - velocity_stamp_ns_) < 1000000000LL;
    const Eigen::Vector3d v = se2::adjoint(se2::inverse(T_base_radar_)) * velocity_base_;
    const spinradar::LocalizationResult r = localizer_->process(scan_, recent ? &v : nullptr);
    if (!r.ok) {
      NODELET_WARN_THROTTLE(5.0, "scan at %.3f not localized: %s", msg->header.stamp.toSec(),
                            r.reason.c_str());
      return;
    }
    pending_.push_back(r);
    if (pending_.size() > 20) {
      NODELET_WARN_THROTTLE(5.0, "no odometry for the localized scans: dropping the oldest");
      pending_.pop_front();
    }
    flush();
  }

  /// Publishes map -> odom for the results whose scan time the odometry has reached.
  void flush() {
    while (!pending_.empty() && !history_.empty() && pending_.front().stamp_ns <= history_.latest()) {
      const spinradar::LocalizationResult& r = pending_.front();
      Eigen::Matrix3d T_odom_base;
      if (history_.at(r.stamp_ns, T_odom_base)) {
        geometry_msgs::TransformStamped tf;
        tf.header.stamp = toRosTime(r.stamp_ns);
        tf.header.frame_id = map_frame_;
        tf.child_frame_id = odom_frame_;
        tf.transform = toTransformMsg(mapToOdom(r.T_map_sensor, T_odom_base, T_base_radar_));
        tf_broadcaster_.sendTransform(tf);
        ++published_;
      }  // else older than the odometry kept: nothing to relate it to
      pending_.pop_front();
    }
  }

  /// T_base_radar from tf once (static mounting), as the estimator nodelet does.
  void lookUpMounting(const std::string& radar_frame) {
    mounting_known_ = true;
    if (radar_frame == base_frame_) return;
    try {
      T_base_radar_ = toSE2(tf_buffer_.lookupTransform(base_frame_, radar_frame, ros::Time(0),
                                                       ros::Duration(tf_timeout_))
                                .transform);
    } catch (const tf2::TransformException& e) {
      NODELET_ERROR("no tf %s -> %s within %.1f s (%s): using the radar as the base frame",
                    base_frame_.c_str(), radar_frame.c_str(), tf_timeout_, e.what());
    }
  }

  std::unique_ptr<spinradar::Localizer> localizer_;
  spinradar::PolarScan scan_;
  OdomHistory history_;
  std::deque<spinradar::LocalizationResult> pending_;
  Eigen::Vector3d velocity_base_ = Eigen::Vector3d::Zero();
  int64_t velocity_stamp_ns_ = 0;
  Eigen::Matrix3d T_base_radar_ = Eigen::Matrix3d::Identity();
  std::string map_frame_, odom_frame_, base_frame_, radar_frame_;
  double tf_timeout_ = 2.0;
  bool mounting_known_ = false;
  long published_ = 0;
  std::mutex mutex_;

  tf2_ros::Buffer tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  ros::Subscriber odom_sub_, scan_sub_;
};

}  // namespace spinradar_ros

PLUGINLIB_EXPORT_CLASS(spinradar_ros::LocalizerNodelet, nodelet::Nodelet)
