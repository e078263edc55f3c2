#pragma once
// Frame-to-frame motion without descriptors, for the scan pairs where descriptor matching
// fails (issue 19). The refined chain (refined, keyframe, surface) used to predict with the
// last velocity there, which loses the whole turn when the reason for the failure is the
// turn itself: the ORB descriptors are upright (orb_descriptors.hpp), so beyond about
// 15 deg between scans (a U-turn at 1.5 rad/s turns 21 deg per 0.25 s scan) they stop
// matching. Measured on the simulator's out_and_back route (a layout other than the
// held-out one): the two pairs at the U-turn entry failed, the prediction kept 0 deg for
// 2 x 21 deg and every row-keypoint estimator came out of the turn 40 deg off.
//
// Here: the two scans' keypoints are registered as point sets under the constant-velocity
// model of MC-RANSAC (one velocity xi over the pair, T_12 = exp(dt xi), every point moved
// to its scan's start by its own time with xi and Doppler-corrected with xi). First a
// search over the yaw rate (the one direction a failed pair can be far off in: the speed
// changes little within 0.25 s) that counts points near a point of the other scan, then
// Gauss-Newton on [vx, vy, wz] with nearest-neighbour association, the gate shrinking to
// inlier_threshold. Covariance: the inverse information
// of the point-to-point terms (both endpoints' polar noise), scaled by chi2/dof when above 1.
#include <vector>

#include <Eigen/Core>

#include "spinradar/core/feature_frame.hpp"
#include "spinradar/core/params.hpp"
#include "spinradar/estimation/motion_estimate.hpp"

namespace spinradar {

/// Points binned on a dense grid over their bounding box (counting sort, buffers reused):
/// the recovery rebuilds its map for every search candidate and looks up every point, where
/// a sorted-key index (CellIndex) spent most of the time in binary searches.
class DenseGrid {
 public:
  void build(const std::vector<Eigen::Vector2d>& pts, double cell);
  /// Index of the nearest point within radius (<= cell) of q, or -1.
  int nearest(const Eigen::Vector2d& q, double radius) const;

 private:
  const std::vector<Eigen::Vector2d>* pts_ = nullptr;
  double x0_ = 0.0, y0_ = 0.0, inv_cell_ = 1.0;
  int nx_ = 0, ny_ = 0;
  std::vector<int> start_;  ///< per cell (row-major), then one past the end
  std::vector<int> order_;  ///< point indices sorted by cell
};

class PairRecovery {
 public:
  explicit PairRecovery(const EstimatorConfig& config = EstimatorConfig{}) : config_(config) {}
  void setConfig(const EstimatorConfig& config) { config_ = config; }

  /// f1, f2: consecutive scans. xi_guess: the search's centre (the last estimate). out
  /// receives the velocity, its covariance and T_12 (setMotionFromVelocity); out.matches =
  /// inliers. Returns out.ok.
  bool estimate(const FeatureFrame& f1, const FeatureFrame& f2, const Eigen::Vector3d& xi_guess,
                MotionEstimate& out);

  int lastInliers() const { return inliers_; }

  /// A keypoint as used here: position, beam unit vector (REP 103), seconds after its
  /// scan's start.
  struct Point {
    double x, y, ux, uy, t;
  };

  static constexpr double kYawStep = 0.035;    ///< rad per scan pair, coarse search step (2 deg)
  static constexpr double kMaxYaw = 0.5;       ///< rad per scan pair searched either side
  static constexpr double kSearchGate = 2.0;   ///< m, counts a point as explained
  static constexpr int kSearchPoints = 400;    ///< scan points scored per candidate (strided)
  static constexpr int kIterations = 12;
  static constexpr int kMinInliers = 30;
  /// A descriptor pair with fewer MC-RANSAC inliers than this is tried here too (odometry.cpp).
  static constexpr int kMinPairInliers = 5;
  /// The search's best candidate must explain this fraction of the scored points: a scene
  /// the map does not share (or noise) never gets a recovered step.
  static constexpr double kMinFraction = 0.2;

 private:
  /// The map: every stride-th point of scan 1 with velocity xi at its start (map_, index_).
  void buildMap(const Eigen::Vector3d& xi, int stride);
  /// Every stride-th point of scan 2 (moved with xi2, then by the step exp(dt xi1)) within
  /// kSearchGate of the map.
  int score(const Eigen::Vector3d& xi1, const Eigen::Vector3d& xi2, double dt, int stride) const;

  EstimatorConfig config_;
  int inliers_ = 0;
  std::vector<Point> p1_, p2_;        ///< the two scans' keypoints
  std::vector<Eigen::Vector2d> map_;  ///< f1's points at its start, its frame
  std::vector<int> map_idx_;          ///< their keypoint indices in f1
  DenseGrid index_;
};

}  // namespace spinradar
