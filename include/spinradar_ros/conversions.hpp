#pragma once
// Core types <-> ROS messages for the feature and estimator nodelets. Frames: REP 103; the
// core's odometry world is the radar frame at the first scan, ROS `odom` is the base frame
// there. All poses SE(2) as 3x3 matrices, T_ab = pose of frame b in frame a.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <geometry_msgs/Transform.h>
#include <geometry_msgs/TransformStamped.h>
#include <geometry_msgs/TwistStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/time.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <spinradar/Features.h>

#include "spinradar/core/feature_frame.hpp"
#include "spinradar/estimation/odometry.hpp"

namespace spinradar_ros {

/// Variance given to z, roll and pitch, which a planar radar does not observe.
constexpr double kUnobservedVariance = 1e6;

ros::Time toRosTime(int64_t stamp_ns);  ///< throws std::runtime_error on negative stamps
int64_t toNs(const ros::Time& t);

/// FeatureFrame -> Features. `scan_end_ns` is the last azimuth's time (latency reference).
void toMsg(const spinradar::FeatureFrame& frame, int64_t scan_end_ns, const std::string& frame_id,
           spinradar::Features& msg);
/// Features -> FeatureFrame, reusing `frame`'s buffers. Throws std::runtime_error when the
/// descriptor block does not match keypoints x descriptor_size.
void fromMsg(const spinradar::Features& msg, spinradar::FeatureFrame& frame);

/// SE(2) part of a 3D transform (x, y, yaw), e.g. the radar mounting T_base_radar from tf.
Eigen::Matrix3d toSE2(const geometry_msgs::Transform& t);
geometry_msgs::Transform toTransformMsg(const Eigen::Matrix3d& T);

/// The odometry frames of one result: T_odom_base = T_base_radar T_world_radar T_base_radar^-1.
struct OdometryFrames {
  std::string odom_frame = "odom";
  std::string base_frame = "base_link";
  Eigen::Matrix3d T_base_radar = Eigen::Matrix3d::Identity();
};

/// Pose (odom -> base) with covariance and the base's body twist with covariance.
void toOdometryMsg(const spinradar::OdometryResult& r, const OdometryFrames& f,
                   nav_msgs::Odometry& msg);
/// The base's body velocity, header.frame_id = base frame.
void toTwistMsg(const spinradar::OdometryResult& r, const OdometryFrames& f,
                geometry_msgs::TwistStamped& msg);
/// tf odom -> base at the scan's reference time.
void toTfMsg(const spinradar::OdometryResult& r, const OdometryFrames& f,
             geometry_msgs::TransformStamped& msg);

/// Points (radar frame, z = 0) as PointCloud2 with fields x, y, z, intensity (keypoint power)
/// and t (keypoint acquisition time minus header.stamp, s). `keypoints` may be empty or must
/// be parallel to `points`.
void toCloudMsg(const std::vector<Eigen::Vector2d>& points,
                const std::vector<spinradar::Keypoint>& keypoints, const std_msgs::Header& header,
                sensor_msgs::PointCloud2& msg);

/// The Cartesian scan (CV_8U, x forward = up) with keypoints drawn, as a bgr8 image.
void toDebugImageMsg(const cv::Mat& cartesian, const spinradar::FeatureFrame& frame,
                     double resolution, const std_msgs::Header& header, sensor_msgs::Image& msg);

}  // namespace spinradar_ros
