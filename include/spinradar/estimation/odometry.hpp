#pragma once
// Frame-to-frame radar odometry: features of each scan are matched to the previous scan,
// a motion estimator (rigid, mc, mc_doppler, refined, keyframe) gives the body velocity, and the
// results are compounded into a pose. The keyframe estimator instead registers each scan to
// a keyframe with the refined step as prior (keyframe_tracker.hpp) and sets the pose; the
// surface estimator registers each scan's oriented surface points to a submap with the
// keyframe estimator's step as prior (surface_tracker.hpp). Pose convention: SE(2) 3x3 matrices, T_ab = pose of
// frame b expressed in frame a; REP 103 (x forward, y left, yaw CCW).
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "spinradar/core/feature_frame.hpp"
#include "spinradar/core/params.hpp"
#include "spinradar/core/polar_scan.hpp"
#include "spinradar/core/stage_times.hpp"
#include "spinradar/estimation/motion_estimate.hpp"

namespace spinradar {

class FeatureExtractor;

class Odometry {
 public:
  /// A scan more than this many scan periods (the shortest interval seen) after the previous
  /// one starts a new segment (OdometryResult::time_event).
  static constexpr double kGapPeriods = 4.0;

  explicit Odometry(const PipelineConfig& config);  ///< validates config (throws)
  ~Odometry();
  Odometry(Odometry&&) noexcept;
  Odometry& operator=(Odometry&&) noexcept;

  /// Full chain on a polar scan.
  OdometryResult process(const PolarScan& scan);
  /// Estimation only, for features computed elsewhere (the feature nodelet, or extractFeatures()
  /// on a loader thread); `times` (detect, Cartesian, describe) is passed through to the result.
  OdometryResult process(const FeatureFrame& frame, const StageTimes& times = {});
  /// The same two, writing into `out` (overwritten whole) and reusing its buffers (the
  /// inliers): a caller that keeps `out` across scans makes no allocation per scan once warm.
  void process(const PolarScan& scan, OdometryResult& out);
  void process(const FeatureFrame& frame, const StageTimes& times, OdometryResult& out);
  /// The per-scan part of process(scan): features and keypoint times from the scan and
  /// `config` alone (no estimator state), so another thread may run it ahead with its own
  /// extractor (made from config.detector, config.features); process(frame) on the result
  /// then gives what process(scan) gives.
  static void extractFeatures(const PipelineConfig& config, FeatureExtractor& extractor,
                              const PolarScan& scan, FeatureFrame& out, StageTimes* times);

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
