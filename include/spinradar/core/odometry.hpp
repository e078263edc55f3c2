#pragma once
// Frame-to-frame radar odometry: features of each scan are matched to the previous scan,
// a motion estimator (rigid, mc, mc_doppler, refined, keyframe) gives the body velocity, and the
// results are compounded into a pose. The keyframe estimator instead registers each scan to
// a keyframe with the refined step as prior (keyframe_tracker.hpp) and sets the pose. Pose convention: SE(2) 3x3 matrices, T_ab = pose of
// frame b expressed in frame a; REP 103 (x forward, y left, yaw CCW).
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "spinradar/core/feature_frame.hpp"
#include "spinradar/core/params.hpp"
#include "spinradar/core/polar_scan.hpp"
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
  StageTimes times;
};

class Odometry {
 public:
  explicit Odometry(const PipelineConfig& config);  ///< validates config (throws)
  ~Odometry();
  Odometry(Odometry&&) noexcept;
  Odometry& operator=(Odometry&&) noexcept;

  /// Full chain on a polar scan.
  OdometryResult process(const PolarScan& scan);
  /// Estimation only, for features computed elsewhere (the feature nodelet).
  OdometryResult process(const FeatureFrame& frame);

  /// The last frame's keypoints moved to its reference time with the estimated velocity and,
  /// for mc_doppler/refined, Doppler-corrected: (x, y) in the sensor frame at stamp_ns.
  const std::vector<Eigen::Vector2d>& correctedPoints() const;
  /// The same keypoints as measured (no undistortion, no Doppler correction).
  const std::vector<Eigen::Vector2d>& rawPoints() const;

  void reset();
  const PipelineConfig& config() const;
  /// Applies new parameters (e.g. from dynamic_reconfigure) from the next scan on.
  void setConfig(const PipelineConfig& config);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace spinradar
