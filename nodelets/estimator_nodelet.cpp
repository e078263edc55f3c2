// Estimator nodelet: spinradar/Features in (`features`); frame-to-frame radar odometry out:
// nav_msgs/Odometry `odom`, TwistStamped `velocity`, tf odom -> base, PointCloud2
// `points_corrected` (undistorted to the scan time, Doppler-corrected) and `points_raw`, and a
// nav_msgs/Path `path` for rviz. The radar mounting T_base_radar comes from tf. Time going back
// or a long gap between scans starts a new segment (warning; pose and tf stay continuous).
#include <memory>
#include <mutex>

#include <nav_msgs/Path.h>
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include <spinradar/EstimatorNodeletConfig.h>

#include "spinradar/estimation/odometry.hpp"
#include "spinradar_ros/conversions.hpp"
#include "spinradar_ros/params.hpp"
#include "spinradar_ros/validated_reconfigure.hpp"

namespace spinradar_ros {

class EstimatorNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    loadParams(pnh, config_);
    config_.validate();  // a bad parameter fails the load, naming it
    odometry_ = std::make_unique<spinradar::Odometry>(config_);
    frames_.odom_frame = pnh.param<std::string>("odom_frame", "odom");
    frames_.base_frame = pnh.param<std::string>("base_frame", "base_link");
    radar_frame_ = pnh.param<std::string>("radar_frame", "");  // "" = the features' frame_id
    publish_tf_ = pnh.param("publish_tf", true);
    tf_timeout_ = pnh.param("tf_timeout", 2.0);
    path_length_ = pnh.param("path_length", 10000);

    tf_listener_ = std::make_unique<tf2_ros::TransformListener>(tf_buffer_, nh);
    odom_pub_ = nh.advertise<nav_msgs::Odometry>("odom", 50);
    velocity_pub_ = nh.advertise<geometry_msgs::TwistStamped>("velocity", 50);
    corrected_pub_ = nh.advertise<sensor_msgs::PointCloud2>("points_corrected", 10);
    raw_pub_ = nh.advertise<sensor_msgs::PointCloud2>("points_raw", 10);
    path_pub_ = nh.advertise<nav_msgs::Path>("path", 1);
    reconfigure_ = std::make_unique<Reconfigure>(
        pnh, config_, mutex_, [this] { odometry_->setConfig(config_); });
    sub_ = nh.subscribe("features", pnh.param("queue_size", 20), &EstimatorNodelet::onFeatures,
                        this);
    NODELET_INFO("estimator '%s', publishing %s -> %s", config_.estimator.estimator.c_str(),
                 frames_.odom_frame.c_str(), frames_.base_frame.c_str());
  }

  /// T_base_radar from tf, looked up once (the mounting is static); identity when the radar
  /// is the base frame. Falls back to identity with an error if tf has nothing in time.
  void lookUpMounting(const std::string& radar_frame) {
    mounting_known_ = true;
    if (radar_frame == frames_.base_frame) return;
    try {
      const auto t = tf_buffer_.lookupTransform(frames_.base_frame, radar_frame, ros::Time(0),
                                                ros::Duration(tf_timeout_));
      frames_.T_base_radar = toSE2(t.transform);
    } catch (const tf2::TransformException& e) {
      NODELET_ERROR("no tf %s -> %s within %.1f s (%s): using the radar as the base frame",
                    frames_.base_frame.c_str(), radar_frame.c_str(), tf_timeout_, e.what());
    }
  }

  void onFeatures(const spinradar::FeaturesConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    const std::string radar_frame = radar_frame_.empty() ? msg->header.frame_id : radar_frame_;
    if (!mounting_known_) lookUpMounting(radar_frame);
    try {
      fromMsg(*msg, frame_);
    } catch (const std::exception& e) {
      NODELET_ERROR("dropping features at %.3f: %s", msg->header.stamp.toSec(), e.what());
      return;
    }
    odometry_->process(frame_, {}, result_);  // into the kept result: no allocation per scan
    const spinradar::OdometryResult& result = result_;
    using TimeEvent = spinradar::OdometryResult::TimeEvent;
    if (result.time_event == TimeEvent::Backwards)
      NODELET_WARN("scan at %.3f: time went back by %.3f s: odometry state reset, pose kept "
                   "(covariance inflated); velocity re-estimated from the next scan",
                   msg->header.stamp.toSec(), -result.time_step_s);
    else if (result.time_event == TimeEvent::Gap)
      NODELET_WARN("scan at %.3f: %.3f s since the previous scan: new segment, no step "
                   "extrapolated across the gap (covariance inflated); velocity re-estimated "
                   "from the next scan", msg->header.stamp.toSec(), result.time_step_s);
    else if (!result.ok && scans_ > 0)
      NODELET_WARN("scan at %.3f: motion estimation failed (%d matches); pose extrapolated",
                   msg->header.stamp.toSec(), result.motion.matches);
    ++scans_;

    auto odom = boost::make_shared<nav_msgs::Odometry>();
    toOdometryMsg(result, frames_, *odom);
    odom_pub_.publish(odom);
    auto twist = boost::make_shared<geometry_msgs::TwistStamped>();
    toTwistMsg(result, frames_, *twist);
    velocity_pub_.publish(twist);
    if (publish_tf_) {
      geometry_msgs::TransformStamped tf;
      toTfMsg(result, frames_, tf);
      tf_broadcaster_.sendTransform(tf);
    }
    std_msgs::Header header;
    header.stamp = odom->header.stamp;
    header.frame_id = radar_frame;
    auto corrected = boost::make_shared<sensor_msgs::PointCloud2>();
    toCloudMsg(odometry_->correctedPoints(), frame_.keypoints, header, *corrected);
    corrected_pub_.publish(corrected);
    auto raw = boost::make_shared<sensor_msgs::PointCloud2>();
    toCloudMsg(odometry_->rawPoints(), frame_.keypoints, header, *raw);
    raw_pub_.publish(raw);
    publishPath(*odom);
  }

  void publishPath(const nav_msgs::Odometry& odom) {
    if (path_length_ <= 0) return;
    geometry_msgs::PoseStamped p;
    p.header = odom.header;
    p.pose = odom.pose.pose;
    path_.header = odom.header;
    path_.poses.push_back(p);
    if (static_cast<int>(path_.poses.size()) > path_length_)
      path_.poses.erase(path_.poses.begin(), path_.poses.begin() + path_length_ / 10 + 1);
    if (path_pub_.getNumSubscribers() > 0) path_pub_.publish(path_);
  }

  spinradar::PipelineConfig config_;
  std::unique_ptr<spinradar::Odometry> odometry_;
  spinradar::FeatureFrame frame_;
  spinradar::OdometryResult result_;
  OdometryFrames frames_;
  std::string radar_frame_;
  bool publish_tf_ = true, mounting_known_ = false;
  double tf_timeout_ = 2.0;
  int path_length_ = 10000;
  long scans_ = 0;
  nav_msgs::Path path_;
  std::mutex mutex_;  // callbacks and reconfiguration may run on different threads

  tf2_ros::Buffer tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  ros::Subscriber sub_;
  ros::Publisher odom_pub_, velocity_pub_, corrected_pub_, raw_pub_, path_pub_;
  using Reconfigure = ValidatedReconfigure<spinradar::EstimatorNodeletConfig, spinradar::PipelineConfig>;
  std::unique_ptr<Reconfigure> reconfigure_;
};

}  // namespace spinradar_ros

PLUGINLIB_EXPORT_CLASS(spinradar_ros::EstimatorNodelet, nodelet::Nodelet)
