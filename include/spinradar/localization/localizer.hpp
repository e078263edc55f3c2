#pragma once
// Metric localization of live scans against the scans of an earlier "map" drive, possibly
// driven in the opposite direction (Burnett et al. 2021, Sec. IV-B): RSD keypoint
// descriptors (rsd.hpp), ratio-test matching against the map scan nearest to a pose prior,
// then rigid RANSAC on keypoints compensated with each scan's *own* velocity:
//   none           raw keypoints (both scans treated as taken at one instant)
//   motion         each scan undistorted to its reference time with its MC-RANSAC velocity
//   motion_doppler each scan Doppler-corrected (r += beta u) and undistorted with its
//                  MC-RANSAC + Doppler velocity
// MC-RANSAC itself cannot relate the two scans (its constant-velocity model spans the time
// between them, here minutes), so, as the authors' localization code does, each scan's
// velocity comes from odometry within its own drive: MC-RANSAC between the scan and its
// neighbour (mc_ransac.hpp, doppler.hpp). Driving the other way flips the sign of the
// Doppler shift relative to the map, so the shifts no longer cancel as they do in odometry.
//
// Poses: T_map_sensor = pose of the sensor at a scan's reference time (first valid azimuth)
// in the map frame; REP 103.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "spinradar/features/detector.hpp"
#include "spinradar/core/feature_frame.hpp"
#include "spinradar/estimation/mc_ransac.hpp"
#include "spinradar/core/params.hpp"
#include "spinradar/io/poses_io.hpp"
#include "spinradar/estimation/rigid_ransac.hpp"
#include "spinradar/localization/rsd.hpp"

// clang-format off
#define SPINRADAR_LOCALIZER_PARAMS(X) \
  X(std::string, compensation, "motion_doppler", 0, 0, "", "Localization compensation: none, motion or motion_doppler") \
  X(double, loc_nndr, 0.95, 0.1, 1.0, "", "RSD nearest-neighbour distance ratio against the map scan") \
  X(int, loc_ransac_iterations, 1000, 1, 100000, "", "Rigid RANSAC iterations against the map scan") \
  X(double, loc_inlier_threshold, 0.35, 0.01, 5.0, "m", "Rigid RANSAC inlier threshold against the map scan") \
  X(int, loc_min_inliers, 8, 2, 100000, "", "Fewer RANSAC inliers than this: the scan is not localised") \
  X(double, loc_match_gate, 0.0, 0.0, 1000.0, "m", "Only match keypoints the prior puts this close (0 = off, descriptors only as the paper)") \
  X(double, loc_max_map_distance, 30.0, 0.1, 100000.0, "m", "No map scan this close to the prior: the scan is not localised") \
  X(double, loc_max_velocity_gap, 1.0, 0.05, 100.0, "s", "A scan's velocity is estimated only with a neighbour this close in time") \
  X(double, loc_track_max_offset, 8.0, 0.1, 10000.0, "m", "Tracking: an estimate farther than this from the prediction is rejected") \
  X(double, loc_track_max_yaw, 0.2, 0.001, 3.2, "rad", "Tracking: an estimate turned more than this from the prediction is rejected")
// clang-format on

namespace spinradar {

struct LocalizerConfig {
  SPINRADAR_DECLARE_PARAMS(SPINRADAR_LOCALIZER_PARAMS)
  void validate() const;  ///< throws std::invalid_argument naming the parameter
};

enum class Compensation { None, Motion, MotionDoppler };
/// "none", "motion", "motion_doppler"; throws std::invalid_argument otherwise.
Compensation parseCompensation(const std::string& name);
const char* compensationName(Compensation c);

/// One scan prepared for localization: keypoints, RSD descriptors, own velocity.
struct LocFrame {
  int64_t stamp_ns = 0;  ///< reference time: stamp of the first valid azimuth
  std::vector<Keypoint> keypoints;
  cv::Mat rsd;           ///< one CV_32F row per keypoint (rsd.hpp)
  bool has_velocity = false;
  Eigen::Vector3d velocity_mc = Eigen::Vector3d::Zero();       ///< body [vx, vy, wz], MC-RANSAC
  Eigen::Vector3d velocity_doppler = Eigen::Vector3d::Zero();  ///< MC-RANSAC + Doppler
  Eigen::Matrix3d T_map_sensor = Eigen::Matrix3d::Identity();  ///< map frames: known pose
};

struct LocalizationResult {
  bool ok = false;
  int64_t stamp_ns = 0;
  std::string reason;  ///< why not ok
  int map_index = -1;  ///< map frame matched against
  Eigen::Matrix3d T_map_sensor = Eigen::Matrix3d::Identity();    ///< the estimate (prior if !ok)
  Eigen::Matrix3d T_mapscan_sensor = Eigen::Matrix3d::Identity(); ///< relative to the map scan
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity();  ///< over [x, y, yaw] of T_mapscan_sensor
  Eigen::Matrix3d T_map_prior = Eigen::Matrix3d::Identity();
  bool velocity_known = false;  ///< false: compensation could not be applied
  int matches = 0;
  int inliers = 0;
  double match_ms = 0.0, ransac_ms = 0.0;  ///< thread CPU time
};

/// CPU time of the calling thread in ms (timings on a shared machine).
double threadCpuMs();

class Localizer {
 public:
  /// `pipeline` supplies the detector and the odometry estimator parameters used for each
  /// scan's own velocity (ransac_iterations, inlier_threshold, beta, ...). Validates (throws).
  Localizer(const LocalizerConfig& config = {}, const RsdConfig& rsd = {},
            const PipelineConfig& pipeline = {});

  const LocalizerConfig& config() const { return config_; }
  void setConfig(const LocalizerConfig& config);  ///< validates (throws)
  const PipelineConfig& pipeline() const { return pipeline_; }

  // ---- Preparation (map and live scans alike) -------------------------------------------
  /// Detects keypoints and computes their RSD descriptors. rsd_ms: CPU time of the RSD.
  void prepare(const PolarScan& scan, LocFrame& out, double* rsd_ms = nullptr);
  /// Velocity of the drive between two prepared scans of it, a before b (MC-RANSAC and
  /// MC-RANSAC + Doppler on RSD matches). False when too few matches or a time gap above
  /// loc_max_velocity_gap.
  bool estimateVelocity(const LocFrame& a, const LocFrame& b, Eigen::Vector3d& velocity_mc,
                        Eigen::Vector3d& velocity_doppler);
  /// Sets f.has_velocity and its velocities from the pair (f, next) or else (prev, f)
  /// (either may be null): a scan's own acquisition spans [t_f, t_next].
  bool setVelocity(LocFrame& f, const LocFrame* prev, const LocFrame* next);

  // ---- Map ------------------------------------------------------------------------------
  /// Loads every scan of `scan_dir` (ScanFolder formats), its pose interpolated from the
  /// `t,x,y,yaw` CSV at the scan's reference time, and its velocity from its neighbours.
  /// Scans outside the poses' time span are skipped (counted in the return value's
  /// complement: returns the number of map frames). Errors name the file.
  int loadMap(const std::string& scan_dir, const std::string& poses_csv,
              const std::function<void(size_t, size_t)>& progress = {});
  /// Adds a prepared frame (T_map_sensor set; velocity set or not).
  void addMapFrame(LocFrame frame);
  void clearMap();
  size_t mapSize() const { return map_.size(); }
  const LocFrame& mapFrame(size_t i) const { return map_.at(i); }
  /// Index of the map frame nearest (in position) to p, or -1 when the map is empty.
  int nearestMapFrame(const Eigen::Vector2d& p) const;

  // ---- Localization ---------------------------------------------------------------------
  /// Localizes a prepared live frame against the map frame nearest to the prior. A frame
  /// (live or map) without velocity is used uncompensated; velocity_known is then false.
  LocalizationResult localize(const LocFrame& live, const Eigen::Matrix3d& T_map_prior,
                              Compensation compensation);
  /// Same against a given map frame.
  LocalizationResult localizeAgainst(const LocFrame& live, int map_index,
                                     const Eigen::Matrix3d& T_map_prior,
                                     Compensation compensation);
  /// Tracking check: a result whose pose lies farther than loc_track_max_offset /
  /// loc_track_max_yaw from its prior is turned into a failure (ok = false, pose = prior,
  /// reason set). Returns r.ok.
  bool checkAgainstPrior(LocalizationResult& r) const;
  /// Place recognition without a prior: tries every `stride`-th map frame and keeps the
  /// result with the most inliers.
  LocalizationResult globalLocalize(const LocFrame& live, Compensation compensation,
                                    int stride = 1);

  // ---- Online use (nodelet): one call per live scan -------------------------------------
  /// Tracking: prepare, velocity from `velocity` when given (e.g. the odometry's) or from
  /// the previous live scan, prior = last estimate moved by that velocity (or the initial
  /// pose, or global localization for the first scan), localize with config().compensation.
  LocalizationResult process(const PolarScan& scan, const Eigen::Vector3d* velocity = nullptr);
  void setInitialPose(const Eigen::Matrix3d& T_map_sensor);
  void resetTracking();

 private:
  void compensate(const LocFrame& f, Compensation c, std::vector<Eigen::Vector2d>& out);

  LocalizerConfig config_;
  RsdConfig rsd_config_;
  PipelineConfig pipeline_;
  Detector detector_;
  RsdExtractor rsd_;
  RsdMatcher matcher_;
  McRansac mc_;
  RigidRansac rigid_;
  std::vector<LocFrame> map_;
  // Buffers.
  std::vector<Match> matches_;
  std::vector<Keypoint> kc_a_, kc_b_, kd_;
  std::vector<Eigen::Vector2d> pm_, pl_, gate_m_, gate_l_;
  MotionEstimate est_;
  // Tracking state.
  bool have_last_ = false, have_initial_ = false;
  Eigen::Matrix3d T_last_ = Eigen::Matrix3d::Identity(), T_initial_ = Eigen::Matrix3d::Identity();
  int64_t last_stamp_ = 0;
  LocFrame prev_live_, cur_live_;
};

}  // namespace spinradar
