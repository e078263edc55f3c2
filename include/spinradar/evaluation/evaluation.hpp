#pragma once
// Odometry evaluation against ground truth: KITTI-style drift (exactly as the KITTI odometry
// devkit's evaluate_odometry.cpp computes it, in SE(2)), drift by path length and by speed,
// and per-frame relative errors for sequences too short for 100 m subsequences.
//
// Poses are T_world_sensor, REP 103. Estimate and truth need not share an origin: every metric
// uses relative motions only.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "spinradar/io/ground_truth_io.hpp"
#include "spinradar/io/poses_io.hpp"

namespace spinradar {

/// Pose of a trajectory (sorted by t) at time t: linear in x, y and shortest-arc in yaw between
/// the two samples around t. Returns false when t lies outside [front.t - tol, back.t + tol]
/// (times within tol of an end take that end's pose).
bool interpolatePose(const std::vector<PoseRecord>& trajectory, double t, PoseRecord& out,
                     double tol = 1e-4);

/// Estimate and ground truth at the same instants (the estimate's times).
struct AssociatedPoses {
  std::vector<double> t;
  std::vector<Eigen::Matrix3d> est;
  std::vector<Eigen::Matrix3d> gt;
  int dropped = 0;  ///< estimate poses outside the ground truth's time span
};
AssociatedPoses associatePoses(const std::vector<PoseRecord>& est,
                               const std::vector<PoseRecord>& gt, double tol = 1e-4);

struct KittiConfig {
  std::vector<double> lengths{100, 200, 300, 400, 500, 600, 700, 800};  ///< m
  /// First frames are taken every `step` frames. The devkit uses 10 (one second of KITTI's
  /// 10 Hz); keep 10 to match it, or 4 for "every second" at the radar's 4 Hz.
  int step = 10;
  /// Speed bands for drift-vs-speed, as the devkit's plots: centres 2, 4, ..., 24 m/s, each
  /// taking segments within +-2 m/s (bands overlap); bands with fewer than
  /// min_segments_per_bin segments are left out (devkit: num > 2.5).
  std::vector<double> speed_centres{2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24};
  double speed_half_width = 2.0;
  int min_segments_per_bin = 3;
};

/// One subsequence of the devkit: from first_frame until the ground-truth path has grown by
/// more than `length`.
struct SegmentError {
  int first_frame = 0;
  int last_frame = 0;
  double length = 0;  ///< m (the nominal subsequence length)
  double t_err = 0;   ///< translational error / length (fraction; x100 for %)
  double r_err = 0;   ///< rotational error / length (rad/m)
  /// m/s: length / elapsed time. The devkit writes length / (0.1 * frames) (10 Hz KITTI);
  /// with time stamps available the real speed is used.
  double speed = 0;
};

struct DriftBin {
  double key = 0;              ///< length (m) or speed-band centre (m/s)
  double t_err_pct = 0;        ///< mean translational drift, %
  double r_err_deg_per_m = 0;  ///< mean rotational drift, deg/m
  int count = 0;
};

struct DriftResult {
  bool valid = false;          ///< false when no subsequence of the shortest length fits
  double t_err_pct = 0;        ///< mean over all segments (devkit's "t_err" x 100)
  double r_err_deg_per_m = 0;  ///< mean over all segments, deg/m (devkit's r_err in deg)
  std::vector<DriftBin> by_length;
  std::vector<DriftBin> by_speed;
  std::vector<SegmentError> segments;
};

/// Devkit's calcSequenceErrors (+ the per-length / per-speed averages of saveErrorPlots).
/// `t` (s) is only used for the segment speeds; pass empty to use `frame_dt` per frame.
DriftResult kittiDrift(const std::vector<Eigen::Matrix3d>& gt,
                       const std::vector<Eigen::Matrix3d>& est, const std::vector<double>& t,
                       const KittiConfig& config = {}, double frame_dt = 0.25);

/// Cumulative ground-truth path length at each frame (devkit's trajectoryDistances).
std::vector<double> pathDistances(const std::vector<Eigen::Matrix3d>& poses);

/// Error of each frame-to-frame motion: E = (T_est_{k-1,k})^-1 T_gt_{k-1,k}.
struct FrameError {
  double t = 0;          ///< time of frame k
  double gt_step = 0;    ///< m, ground-truth translation from k-1 to k
  double gt_dyaw = 0;    ///< rad, ground-truth rotation from k-1 to k
  double est_step = 0;   ///< m, estimated translation
  double est_dyaw = 0;   ///< rad
  double t_err = 0;      ///< m, norm of E's translation
  double r_err = 0;      ///< rad, |yaw of E|
  double t_err_pct = 0;  ///< 100 t_err / gt_step (0 when gt_step < 1 cm)
  double speed = 0;      ///< m/s, gt_step / dt
};

struct ErrorStats {
  double mean = 0, median = 0, rmse = 0, max = 0;
};
ErrorStats errorStats(std::vector<double> values);

struct RelativeErrors {
  std::vector<FrameError> frames;
  ErrorStats t_err_m, r_err_deg, t_err_pct;
};
RelativeErrors relativeFrameErrors(const AssociatedPoses& poses);

struct EvaluationReport {
  AssociatedPoses poses;
  DriftResult drift;
  RelativeErrors frames;
  double path_length = 0;     ///< m, ground truth over the associated span
  double duration = 0;        ///< s
  double final_error_m = 0;   ///< position error at the end, first poses aligned
  double final_error_pct = 0; ///< final_error_m / path_length x 100
};
EvaluationReport evaluateOdometry(const std::vector<PoseRecord>& est,
                                  const std::vector<PoseRecord>& gt,
                                  const KittiConfig& config = {});
/// Human-readable summary (drift, bins, per-frame errors for short runs).
std::string formatReport(const EvaluationReport& report, int max_frames_listed = 20);

}  // namespace spinradar
