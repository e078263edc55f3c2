#include "spinradar_ros/conversions.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include <opencv2/imgproc.hpp>
#include <sensor_msgs/point_cloud2_iterator.h>

#include "spinradar/core/lie.hpp"

namespace spinradar_ros {
namespace {

using spinradar::se2::adjoint;

double yawOf(const Eigen::Matrix3d& T) { return std::atan2(T(1, 0), T(0, 0)); }

/// A 3x3 covariance over [x, y, yaw] into a 6x6 one over [x, y, z, roll, pitch, yaw].
void toCovariance6(const Eigen::Matrix3d& c, boost::array<double, 36>& out) {
  out.fill(0.0);
  const int idx[3] = {0, 1, 5};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out[idx[i] * 6 + idx[j]] = c(i, j);
  for (int k : {2, 3, 4}) out[k * 6 + k] = kUnobservedVariance;
}

void setYaw(double yaw, geometry_msgs::Quaternion& q) {
  q.x = q.y = 0.0;
  q.z = std::sin(yaw / 2);
  q.w = std::cos(yaw / 2);
}

Eigen::Matrix3d odomBase(const spinradar::OdometryResult& r, const OdometryFrames& f) {
  return f.T_base_radar * r.T_world_sensor * spinradar::se2::inverse(f.T_base_radar);
}

}  // namespace

ros::Time toRosTime(int64_t stamp_ns) {
  if (stamp_ns < 0)
    throw std::runtime_error("negative time stamp " + std::to_string(stamp_ns) +
                             " ns cannot become a ros::Time");
  ros::Time t;
  t.fromNSec(static_cast<uint64_t>(stamp_ns));
  return t;
}

int64_t toNs(const ros::Time& t) { return static_cast<int64_t>(t.toNSec()); }

void toMsg(const spinradar::FeatureFrame& frame, int64_t scan_end_ns, const std::string& frame_id,
           spinradar::Features& msg) {
  msg.header.stamp = toRosTime(frame.stamp_ns);
  msg.header.frame_id = frame_id;
  msg.scan_end = toRosTime(scan_end_ns);
  msg.rotation_period.fromNSec(frame.period_ns > 0 ? frame.period_ns : 0);
  const size_t n = frame.keypoints.size();
  msg.keypoints.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const auto& k = frame.keypoints[i];
    auto& m = msg.keypoints[i];
    m.range = k.range;
    m.azimuth = k.azimuth;
    m.x = k.x;
    m.y = k.y;
    m.stamp_ns = k.stamp_ns;
    m.power = k.power;
    m.azimuth_index = k.azimuth_index;
    m.bin = k.bin;
  }
  const cv::Mat& d = frame.descriptors;
  if (d.empty() || n == 0) {
    msg.descriptor_size = 0;
    msg.descriptors.clear();
    return;
  }
  if (d.type() != CV_8U || static_cast<size_t>(d.rows) != n)
    throw std::runtime_error("FeatureFrame: descriptors are " + std::to_string(d.rows) +
                             " rows of type " + std::to_string(d.type()) + " for " +
                             std::to_string(n) + " keypoints (need one CV_8U row each)");
  msg.descriptor_size = static_cast<uint32_t>(d.cols);
  msg.descriptors.resize(n * d.cols);
  for (int r = 0; r < d.rows; ++r)
    std::memcpy(msg.descriptors.data() + static_cast<size_t>(r) * d.cols, d.ptr(r), d.cols);
}

void fromMsg(const spinradar::Features& msg, spinradar::FeatureFrame& frame) {
  const size_t n = msg.keypoints.size();
  const size_t size = msg.descriptor_size;
  if (msg.descriptors.size() != n * size)
    throw std::runtime_error("spinradar/Features: " + std::to_string(msg.descriptors.size()) +
                             " descriptor bytes for " + std::to_string(n) + " keypoints x " +
                             std::to_string(size) + " bytes");
  frame.stamp_ns = toNs(msg.header.stamp);
  frame.period_ns = std::max<int64_t>(0, static_cast<int64_t>(msg.rotation_period.toNSec()));
  frame.keypoints.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const auto& m = msg.keypoints[i];
    auto& k = frame.keypoints[i];
    k.range = m.range;
    k.azimuth = m.azimuth;
    k.x = m.x;
    k.y = m.y;
    k.stamp_ns = m.stamp_ns;
    k.power = m.power;
    k.azimuth_index = m.azimuth_index;
    k.bin = m.bin;
  }
  if (n == 0 || size == 0) {
    frame.descriptors.release();
    return;
  }
  frame.descriptors.create(static_cast<int>(n), static_cast<int>(size), CV_8U);  // reuses
  std::memcpy(frame.descriptors.data, msg.descriptors.data(), n * size);
}

Eigen::Matrix3d toSE2(const geometry_msgs::Transform& t) {
  const auto& q = t.rotation;
  const double yaw = std::atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z));
  return spinradar::se2::fromXyYaw(Eigen::Vector3d(t.translation.x, t.translation.y, yaw));
}

geometry_msgs::Transform toTransformMsg(const Eigen::Matrix3d& T) {
  geometry_msgs::Transform t;
  t.translation.x = T(0, 2);
  t.translation.y = T(1, 2);
  t.translation.z = 0.0;
  setYaw(yawOf(T), t.rotation);
  return t;
}

void toOdometryMsg(const spinradar::OdometryResult& r, const OdometryFrames& f,
                   nav_msgs::Odometry& msg) {
  msg.header.stamp = toRosTime(r.stamp_ns);
  msg.header.frame_id = f.odom_frame;
  msg.child_frame_id = f.base_frame;
  const Eigen::Matrix3d T = odomBase(r, f);
  msg.pose.pose.position.x = T(0, 2);
  msg.pose.pose.position.y = T(1, 2);
  msg.pose.pose.position.z = 0.0;
  setYaw(yawOf(T), msg.pose.pose.orientation);
  const Eigen::Matrix3d A = adjoint(f.T_base_radar);
  toCovariance6(A * r.pose_cov * A.transpose(), msg.pose.covariance);
  const Eigen::Vector3d v = A * r.motion.velocity;
  msg.twist.twist.linear.x = v(0);
  msg.twist.twist.linear.y = v(1);
  msg.twist.twist.linear.z = 0.0;
  msg.twist.twist.angular.x = msg.twist.twist.angular.y = 0.0;
  msg.twist.twist.angular.z = v(2);
  toCovariance6(A * r.motion.velocity_cov * A.transpose(), msg.twist.covariance);
}

void toTwistMsg(const spinradar::OdometryResult& r, const OdometryFrames& f,
                geometry_msgs::TwistStamped& msg) {
  msg.header.stamp = toRosTime(r.stamp_ns);
  msg.header.frame_id = f.base_frame;
  const Eigen::Vector3d v = adjoint(f.T_base_radar) * r.motion.velocity;
  msg.twist.linear.x = v(0);
  msg.twist.linear.y = v(1);
  msg.twist.linear.z = 0.0;
  msg.twist.angular.x = msg.twist.angular.y = 0.0;
  msg.twist.angular.z = v(2);
}

void toTfMsg(const spinradar::OdometryResult& r, const OdometryFrames& f,
             geometry_msgs::TransformStamped& msg) {
  msg.header.stamp = toRosTime(r.stamp_ns);
  msg.header.frame_id = f.odom_frame;
  msg.child_frame_id = f.base_frame;
  msg.transform = toTransformMsg(odomBase(r, f));
}

void toCloudMsg(const std::vector<Eigen::Vector2d>& points,
                const std::vector<spinradar::Keypoint>& keypoints, const std_msgs::Header& header,
                sensor_msgs::PointCloud2& msg) {
  const bool with_kp = keypoints.size() == points.size();
  msg.header = header;
  sensor_msgs::PointCloud2Modifier mod(msg);
  mod.setPointCloud2Fields(5, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1,
                           sensor_msgs::PointField::FLOAT32, "z", 1,
                           sensor_msgs::PointField::FLOAT32, "intensity", 1,
                           sensor_msgs::PointField::FLOAT32, "t", 1,
                           sensor_msgs::PointField::FLOAT32);
  mod.resize(points.size());
  msg.height = 1;
  msg.width = static_cast<uint32_t>(points.size());
  msg.is_dense = true;
  const int64_t t0 = toNs(header.stamp);
  sensor_msgs::PointCloud2Iterator<float> x(msg, "x"), i(msg, "intensity"), t(msg, "t");
  for (size_t k = 0; k < points.size(); ++k, ++x, ++i, ++t) {
    x[0] = static_cast<float>(points[k].x());
    x[1] = static_cast<float>(points[k].y());
    x[2] = 0.f;
    *i = with_kp ? keypoints[k].power : 0.f;
    *t = with_kp ? static_cast<float>((keypoints[k].stamp_ns - t0) * 1e-9) : 0.f;
  }
}

void toDebugImageMsg(const cv::Mat& cartesian, const spinradar::FeatureFrame& frame,
                     double resolution, const std_msgs::Header& header, sensor_msgs::Image& msg) {
  msg.header = header;
  msg.height = cartesian.rows;
  msg.width = cartesian.cols;
  msg.encoding = "bgr8";
  msg.is_bigendian = 0;
  msg.step = cartesian.cols * 3;
  msg.data.resize(static_cast<size_t>(msg.step) * msg.height);
  if (cartesian.empty()) return;
  cv::Mat out(cartesian.rows, cartesian.cols, CV_8UC3, msg.data.data(), msg.step);
  cv::cvtColor(cartesian, out, cv::COLOR_GRAY2BGR);
  // Sensor at the centre, x forward = up, y left = left (FeatureExtractor::cartesianImage).
  const double cu = cartesian.cols / 2.0, cv_ = cartesian.rows / 2.0;
  for (const auto& k : frame.keypoints) {
    const cv::Point p(static_cast<int>(std::lround(cu - k.y / resolution)),
                      static_cast<int>(std::lround(cv_ - k.x / resolution)));
    cv::circle(out, p, 2, cv::Scalar(0, 0, 255), 1, cv::LINE_AA);
  }
}

}  // namespace spinradar_ros
