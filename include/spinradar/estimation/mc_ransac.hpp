#pragma once
// Motion-compensated RANSAC (Burnett et al. 2021, Sec. III-B, after Anderson & Barfoot 2013):
// estimates the constant body velocity between two scans with every keypoint at its own
// acquisition time, by Gauss-Newton on
//   J(varpi) = 1/2 sum_m e_m^T R_cart,m^-1 e_m,  e_m = p_m2 - exp(dt_m varpi^) p_m1,
// inside RANSAC over 2-point subsets, with a final refit on the largest inlier set.
// The inlier gate allows one azimuth row of tangential error (kAzimuthQuantum). Two more
// additions, both measured on synthetic scans (test_mc_ransac): the inliers are re-selected
// with the refit and refitted until stable (removes the pull of the 2-point hypothesis on
// points near the threshold), and the covariance is the sandwich form that accounts for the
// noise of p_m1 too (the paper weights by R_cart of y_m2 only).
//
// Conventions. The paper's T_s(t) maps inertial to sensor coordinates, so its varpi is the
// motion of the world seen from the sensor: exp(dt varpi^) = T_s2,s1. Our output is the
// sensor's own body velocity in REP 103, xi = [vx, vy, wz] with T_s1,s2 = exp(dt xi^), hence
// xi = -varpi. Keypoint positions are REP 103 (x = r cos phi, y = -r sin phi), so the
// paper's math applies to them unchanged; only the Cartesian covariance H R H^T uses the
// clockwise azimuth.
#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "spinradar/core/feature_frame.hpp"
#include "spinradar/features/matcher.hpp"
#include "spinradar/estimation/motion_estimate.hpp"
#include "spinradar/core/params.hpp"

namespace spinradar {

/// Fills velocity-derived fields of a MotionEstimate from xi (body velocity, REP 103) and
/// its covariance: T_12 = exp(dt_ref xi^) and T_12_cov over [x, y, yaw].
void setMotionFromVelocity(const Eigen::Vector3d& xi, const Eigen::Matrix3d& xi_cov,
                           double dt_ref, MotionEstimate& out);

/// Tangential position noise that does not shrink with range (m), used by the pair estimate
/// of refined (and its MC-RANSAC start) and by the pair recovery, and the cap of the floor
/// the keyframe registration measures from its own residuals (see below). mc and mc_doppler
/// keep the paper's R_cart (floor 0). Issue 19: after
/// the fit, real Oxford matches (azimuth peaks, 3 pairs) spread 0.16 m across the beam under
/// 20 m, 3x the 0.054 m that azimuth_sigma gives at 12 m, and 0.13-0.20 m beyond (flat, not
/// ~r): the scattering centre of a near extended object (car, wall, post) moves with the
/// aspect angle, which near objects change fastest. Without a floor the near points'
/// tangential residuals got 10-50x the weight of far ones' and carried the yaw (Oxford pair
/// 1, same inliers and times: -0.133 deg with the paper's weights, +0.024 with unit weights).
/// The keyframe registration does not take this value as it is: on scans without such
/// scatter (the simulator's, the synthetic tests') a fixed floor took the near matches'
/// information, which is what pins a registration's yaw rate (far matches only see the yaw
/// rate relative to the keyframe map's): the registered yaw rate then followed the map's,
/// was passed from keyframe to keyframe (-0.08 rad/s after a turn) and moved every published
/// pose by c dw (0.5-0.7 deg, test_keyframe_tracker YawRateStepInsideAScanStaysOutOfTheChain),
/// and proximity ICP on row arcs slowed until it stopped 0.4 deg short (test_keyframe_row_
/// smears). So it measures the floor (KeyframeTracker::kFloorNearFraction) and caps it here.
constexpr double kTangentialFloor = 0.2;

/// Inverse of the Cartesian covariance R_cart = H R H^T of a point p = h(r, phi) with
/// R = diag(range_sigma^2, azimuth_sigma^2): radial variance range_sigma^2, tangential
/// variance (r azimuth_sigma)^2 + tangential_floor^2 (r clamped to >= 1 m).
Eigen::Matrix2d cartesianInformation(const Eigen::Vector2d& p, double range_sigma,
                                     double azimuth_sigma, double tangential_floor = 0.0);

/// R_cart = H R H^T itself (same conventions).
Eigen::Matrix2d cartesianCovariance(const Eigen::Vector2d& p, double range_sigma,
                                    double azimuth_sigma, double tangential_floor = 0.0);

/// McRansac's inlier test for the residual e of a match whose measured point is p (sensor
/// frame): radial half-width inlier_threshold, tangential half-width
/// sqrt(inlier_threshold^2 + 12 (azimuth_sigma |p|)^2) (see McRansac::kAzimuthQuantum).
bool withinInlierGate(const Eigen::Vector2d& e, const Eigen::Vector2d& p,
                      double inlier_threshold, double azimuth_sigma);

class McRansac {
 public:
  explicit McRansac(const EstimatorConfig& config = EstimatorConfig{});
  void setConfig(const EstimatorConfig& config) { config_ = config; }
  const EstimatorConfig& config() const { return config_; }
  /// Tangential noise floor of the weights and the covariance (m, see kTangentialFloor);
  /// 0 (the paper's R_cart) unless set. The inlier gate is unchanged.
  void setTangentialFloor(double floor_m) { tangential_floor_ = floor_m; }

  /// RANSAC + refit. k1[m.i1] (scan 1) <-> k2[m.i2] (scan 2); ref*_ns are the scans'
  /// reference times (T_12 relates the sensor frames at those times). Returns out.ok;
  /// out.inliers index `matches`. No allocation once buffers have grown.
  bool estimate(const std::vector<Keypoint>& k1, const std::vector<Keypoint>& k2,
                const std::vector<Match>& matches, int64_t ref1_ns, int64_t ref2_ns,
                MotionEstimate& out);

  /// Gauss-Newton refit (config.gn_iterations) on inout.inliers starting from
  /// inout.velocity, then re-selects the inliers with the threshold. Used after the
  /// keypoints have been changed (Doppler correction). Returns inout.ok.
  bool refit(const std::vector<Keypoint>& k1, const std::vector<Keypoint>& k2,
             const std::vector<Match>& matches, int64_t ref1_ns, int64_t ref2_ns,
             MotionEstimate& inout, bool with_covariance = true);

  /// Recomputes inout's covariances on inout.inliers for the matches of the last
  /// estimate/refit call (after refit(..., false)).
  bool updateCovariance(int64_t ref1_ns, int64_t ref2_ns, MotionEstimate& inout) const;

  /// Gauss-Newton steps per 2-point hypothesis (from varpi = 0). A hypothesis only has to
  /// be close enough to count inliers at inlier_threshold; the refit on the inliers then
  /// iterates to convergence (up to gn_iterations).
  static constexpr int kHypothesisSteps = 3;
  /// Rounds of "re-select inliers with the refit, refit again" after the paper's refit.
  static constexpr int kReselectRounds = 3;
  /// Inlier gate: radial half-width inlier_threshold, tangential half-width
  /// sqrt(inlier_threshold^2 + (kAzimuthQuantum * azimuth_sigma * r)^2). A keypoint's
  /// azimuth is its row's (uniform +-half a row, std = step / sqrt(12) = azimuth_sigma), so a
  /// match's tangential error reaches one row, r * step = r * sqrt(12) azimuth_sigma. A
  /// Euclidean gate tighter than that (beyond ~22 m at 0.35 m) keeps only the far matches
  /// whose row rounding agrees with the hypothesis; in a turn every point shares the same
  /// fractional row shift per scan, so RANSAC locked onto whole-row shifts and the yaw rate
  /// was off by up to half a row per scan (turning in place at +-0.625 rad/s: -1.4 % and
  /// +2.3 %, test_mc_ransac QuantizedAzimuthsInASteadyTurn; the city route's steady turns:
  /// about +1 %). withinInlierGate() is the same test for other estimators.
  static constexpr double kAzimuthQuantum = 3.4641016151377544;  // sqrt(12)

 private:
  void load(const std::vector<Keypoint>& k1, const std::vector<Keypoint>& k2,
            const std::vector<Match>& matches);
  /// Gauss-Newton on the listed matches; varpi in/out (paper convention). info receives
  /// sum G^T W G at the final point, chi2 the weighted cost. False when singular.
  bool gaussNewton(const int* idx, int n, int iterations, Eigen::Vector3d& varpi,
                   Eigen::Matrix3d* info, double* chi2) const;
  int selectInliers(const Eigen::Vector3d& varpi, std::vector<int>* inliers) const;
  /// Gauss-Newton refit on `inliers`, writes velocity and T_12 into out.
  bool finish(const Eigen::Vector3d& varpi, const std::vector<int>& inliers, double dt_ref,
              MotionEstimate& out) const;
  /// Honest covariance of out.velocity on `inliers` (sandwich form, see the .cpp).
  bool covariance(const std::vector<int>& inliers, double dt_ref, MotionEstimate& out) const;

  EstimatorConfig config_;
  std::mt19937 rng_;
  // Structure of arrays so the per-hypothesis inlier count vectorises.
  std::vector<double> x1_, y1_, x2_, y2_;
  std::vector<double> dt_;  ///< t_m2 - t_m1 in seconds
  std::vector<double> ux_, uy_;   ///< radial unit vector of p_m2 (inlier gate)
  std::vector<double> inv_tan2_;  ///< 1 / tangential gate half-width^2 of match m
  double max_abs_dt_ = 0.0;
  double tangential_floor_ = 0.0;
  std::vector<int> best_, work_;
};

}  // namespace spinradar
