#pragma once
// Rigid RANSAC (the paper's baseline): both scans are treated as if taken at one instant.
// 2-point subsets, closed-form Arun/Umeyama fit without scale, fixed seed, refit on the
// largest inlier set.
#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "spinradar/core/feature_frame.hpp"
#include "spinradar/features/matcher.hpp"
#include "spinradar/estimation/motion_estimate.hpp"
#include "spinradar/core/params.hpp"

namespace spinradar {

/// Least-squares rigid transform T (SE(2)) minimising sum w_i |a_i - T b_i|^2 over the
/// listed indices (Arun 1987 / Umeyama 1991 without scale). In 2D the SVD of the 2x2
/// cross-covariance reduces to theta = atan2(sum b x a, sum b . a), which is what we compute
/// (no reflection case to handle). Returns false for fewer than 2 points or all coincident.
bool fitRigid2d(const Eigen::Vector2d* a, const Eigen::Vector2d* b, const int* idx, int n,
                Eigen::Matrix3d& T);

class RigidRansac {
 public:
  explicit RigidRansac(const EstimatorConfig& config = EstimatorConfig{});
  void setConfig(const EstimatorConfig& config) { config_ = config; }

  /// Estimates T_12 from matched keypoints (k1[m.i1] in scan 1, k2[m.i2] in scan 2), i.e.
  /// p1 = T_12 p2, and the constant velocity log(T_12) / (ref2 - ref1). Inliers index the
  /// match list. Returns out.ok. No allocation once the buffers have grown.
  bool estimate(const std::vector<Keypoint>& k1, const std::vector<Keypoint>& k2,
                const std::vector<Match>& matches, int64_t ref1_ns, int64_t ref2_ns,
                MotionEstimate& out);

  /// Same on plain point pairs p1[i] <-> p2[i] (dt_ref in seconds, > 0).
  bool estimate(const std::vector<Eigen::Vector2d>& p1, const std::vector<Eigen::Vector2d>& p2,
                double dt_ref, MotionEstimate& out);

 private:
  int countInliers(const Eigen::Matrix3d& T, std::vector<int>* inliers) const;

  EstimatorConfig config_;
  std::mt19937 rng_;
  std::vector<Eigen::Vector2d> p1_, p2_;
  std::vector<int> best_, scratch_;
};

}  // namespace spinradar
