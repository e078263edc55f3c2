#pragma once
// The `surface` estimator (issue 19): a CFEAR-style point-to-line stage on top of the
// keyframe estimator. Each scan's keypoints are Doppler-corrected and motion-compensated
// to mid-scan with the refined pair velocity (MC-RANSAC + Doppler, refined), summarised as
// oriented surface points (surface_points.hpp) and registered to a submap of the last few
// surface keyframes (world frame) with a robust (Cauchy) point-to-line cost, the predicted
// step as a prior (degenerate streets). The prediction is the keyframe estimator's step,
// kept as its own chain, so descriptors still carry the scan through turns and the surface
// stage only corrects what descriptor matches of row keypoints cannot see: the sub-row
// azimuth of facades (row quantisation), and the heading walk between descriptor
// keyframes. Registration is in the mid-scan frame (see keyframe_tracker.hpp for why);
// the published scan-start pose is worked back with the velocity.
// Covariance (published): the Gauss-Newton information of the point-to-line terms (without
// the prior, which shares the scan's points), scaled by the robust residual variance, is
// the pose relative to the newest submap keyframe; compounded onto that keyframe's pose.
#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "spinradar/core/feature_frame.hpp"
#include "spinradar/core/params.hpp"
#include "spinradar/estimation/scan_period.hpp"
#include "spinradar/estimation/surface_points.hpp"

namespace spinradar {

class SurfaceTracker {
 public:
  explicit SurfaceTracker(const EstimatorConfig& config = EstimatorConfig{});
  void setConfig(const EstimatorConfig& config) { config_ = config; }
  void reset();

  /// cur: scan k. velocity: its body velocity (compensation and Doppler). T_w_prev, P_prev:
  /// the previous scan's published pose; T_step, C_step: the predicted step to scan k
  /// (scan-start frames) and its [x, y, yaw] covariance. T_w, P receive scan k's pose.
  /// Returns false when the registration failed (T_w is then the prediction).
  bool track(const FeatureFrame& cur, const Eigen::Vector3d& velocity,
             const Eigen::Matrix3d& T_w_prev, const Eigen::Matrix3d& P_prev,
             const Eigen::Matrix3d& T_step, const Eigen::Matrix3d& C_step, Eigen::Matrix3d& T_w,
             Eigen::Matrix3d& P);

  int64_t keyframeStamp() const { return rel_key_stamp_; }
  const Eigen::Matrix3d& relativePose() const { return rel_T_; }
  const Eigen::Matrix3d& relativeCov() const { return rel_C_; }
  int lastAssociations() const { return last_assoc_; }
  int scanSurfacePoints() const { return static_cast<int>(scan_sp_.size()); }

  static constexpr double kRadius = 2.0;          ///< m, surface neighbourhood and cell
  static constexpr int kMinPoints = 4;            ///< returns per surface point
  static constexpr double kMinPlanarity = 0.9;    ///< blobs (poles, cars) do not give lines
  static constexpr double kAssocRadius = 0.5;     ///< m, scan to map surface point
  static constexpr double kCauchy = 0.15;         ///< m, robust scale of the line distance
  static constexpr double kNormalCos = 0.9;       ///< |n_scan . n_map| at least (25 deg)
  static constexpr int kSubmap = 3;               ///< keyframes in the submap
  static constexpr double kKeyDistance = 6.0;     ///< m, new surface keyframe beyond
  static constexpr double kKeyAngle = 0.2;      ///< rad
  static constexpr int kIterations = 10;
  static constexpr int kMinAssociations = 20;
  static constexpr double kMidScan = 0.5;
  static constexpr double kCovInflation = 4.0;  ///< published covariance (see the .cpp)

 private:
  ScanPeriod scan_period_;  ///< the rotation period, for the mid-scan reference (gaps)
  bool solve(const Eigen::Matrix3d& T_pred, const Eigen::Matrix3d& W_prior, Eigen::Matrix3d& T,
             Eigen::Matrix3d& cov);
  void addKeyframe(const Eigen::Matrix3d& T_w_mid, int64_t stamp, const Eigen::Matrix3d& T_w,
                   const Eigen::Matrix3d& P);

  EstimatorConfig config_;
  int64_t last_stamp_ = 0;
  bool has_last_ = false;
  // Submap: the last kSubmap keyframes' surface points in the world frame (ring).
  std::array<std::vector<SurfacePoint>, kSubmap> keys_;
  int n_keys_ = 0, next_key_ = 0;
  std::vector<SurfacePoint> map_;
  std::vector<Eigen::Vector2d> map_means_;
  CellIndex map_index_;
  /// Newest keyframe: mid-scan world pose (for the keyframe test), scan-start pose, stamp.
  Eigen::Matrix3d key_mid_ = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d key_T_ = Eigen::Matrix3d::Identity(), key_P_ = Eigen::Matrix3d::Zero();
  int64_t key_stamp_ = 0, rel_key_stamp_ = 0;
  Eigen::Matrix3d rel_T_ = Eigen::Matrix3d::Identity(), rel_C_ = Eigen::Matrix3d::Zero();
  int last_assoc_ = 0;
  // Per-scan buffers.
  std::vector<Keypoint> corrected_;
  std::vector<Eigen::Vector2d> pts_;
  std::vector<SurfacePoint> scan_sp_;
  SurfaceExtractor extractor_;
};

}  // namespace spinradar
