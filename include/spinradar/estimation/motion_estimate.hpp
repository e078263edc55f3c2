#pragma once
// Result types shared by every motion estimator and the odometry front door, kept apart so
// an estimator never includes odometry.hpp (the front door that includes the estimators).
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "spinradar/core/stage_times.hpp"

namespace spinradar {

/// Result of estimating the motion between two feature frames.
struct MotionEstimate {
  bool ok = false;
  /// Sensor body velocity [vx, vy, wz] (m/s, m/s, rad/s) in the sensor frame, constant
  /// between the two scans.
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Matrix3d velocity_cov = Eigen::Matrix3d::Identity();
  /// Pose of scan 2's reference frame (at its stamp_ns) expressed in scan 1's reference frame.
  Eigen::Matrix3d T_12 = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d T_12_cov = Eigen::Matrix3d::Identity();  ///< over [x, y, yaw]
  int matches = 0;
  std::vector<int> inliers;  ///< indices into the match list
};

/// One scan's odometry output.
struct OdometryResult {
  bool ok = false;          ///< false on the first scan or when estimation failed
  int64_t stamp_ns = 0;     ///< reference time of the scan (FeatureFrame::stamp_ns)
  Eigen::Matrix3d T_world_sensor = Eigen::Matrix3d::Identity();  ///< world = first scan
  Eigen::Matrix3d pose_cov = Eigen::Matrix3d::Zero();            ///< accumulated, [x, y, yaw]
  MotionEstimate motion;    ///< last frame-to-frame estimate
  /// Keyframe estimator only (else keyframe_stamp_ns = 0): the pose relative to the keyframe
  /// the scan was registered to (the scan at keyframe_stamp_ns) and its covariance.
  int64_t keyframe_stamp_ns = 0;
  Eigen::Matrix3d T_keyframe_sensor = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d keyframe_cov = Eigen::Matrix3d::Zero();
  /// Set when this scan starts a new segment because of its stamp: Backwards (not after the
  /// previous scan's: a clock step or a restarted source; the state is cleared) or Gap (more
  /// than Odometry::kGapPeriods scan periods since the previous scan: nothing is extrapolated
  /// across it). Either way the pose is kept (continuous), its covariance inflated, and the
  /// velocity is estimated again from the next pair.
  enum class TimeEvent { None, Backwards, Gap };
  TimeEvent time_event = TimeEvent::None;
  double time_step_s = 0;  ///< this stamp minus the previous scan's (set with time_event)
  StageTimes times;
};

}  // namespace spinradar
