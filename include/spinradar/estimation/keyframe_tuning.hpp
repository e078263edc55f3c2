#pragma once
// The keyframe estimator's fixed tuning (KeyframeTracker inherits them, so they read
// KeyframeTracker::kName everywhere): gates, inlier counts, prior inflations and the solve's
// iteration counts, each with why it has its value. Tunable ones are EstimatorConfig fields
// (core/params.hpp); these are not, as the README's tuning records explain.
#include "spinradar/estimation/mc_ransac.hpp"  // kTangentialFloor

namespace spinradar {

struct KeyframeTuning {
  static constexpr int kMinInliers = 30;
  /// A scan whose descriptors found kMinWeakInliers..kMinInliers-1 inliers where the
  /// proximity fallback does not run is registered with them and becomes the keyframe
  /// (keyframe_tracker.cpp).
  static constexpr int kMinWeakInliers = 12;
  /// m: when descriptor matches cannot register a scan (few and mostly wrong against a
  /// keyframe turned by 15-30 deg at turn entry or exit), keypoints are paired with the
  /// nearest keyframe point within this distance of the predicted position instead.
  static constexpr double kProximityGate = 1.5;
  /// After a proximity registration: pair again under the solved pose within this gate (m)
  /// and solve, at most this many times, until the pose settles (keyframe_tracker.cpp; the
  /// registrations to past keyframes: EstimatorConfig::graph_proximity_rounds).
  static constexpr double kProximityRegate = 0.6;
  static constexpr int kProximityIterations = 30;
  /// m, nearest-point re-association after a descriptor registration (keyframe_tracker.cpp)
  static constexpr double kReassociateGate = 0.3;
  static constexpr double kProximityMinAngle = 0.15;  ///< rad, keyframe-to-scan yaw for it
  /// Where the descriptors fail even with kMinWeakInliers and the proximity fallback did not
  /// run, the proximity ICP is tried last and kept when its pose's squared Mahalanobis
  /// distance from the prediction (over [x, y, yaw], the prior's covariance) is under this:
  /// chi-square, 3 degrees of freedom, 99 % (keyframe_tracker.cpp).
  static constexpr double kLastResortChi2 = 11.34;
  /// The registration's own velocity moves the scan's frame and map when its yaw rate is
  /// this far (rad/s) from the pair velocity's, or the pair velocity's yaw rate changed by
  /// over kRampYawAccel (rad/s^2) in the last scan; the pair velocity otherwise. After a
  /// keyframe taken in such a ramp, and across a dropped scan (a step of two rotation
  /// periods, ScanPeriod::isGap), the gap also counts relative to the keyframe's own; and it
  /// must also be EstimatorConfig::yaw_rate_sigmas standard deviations (keyframe_tracker.cpp).
  static constexpr double kRegisteredYawRateGap = 0.05;
  static constexpr double kRampYawAccel = 0.1;
  static constexpr double kPredictionGate = 2.0;  ///< m, first gate around the prediction
  // Prior inflation, chosen on the city route (README): velocity prior by acceleration over
  // kPriorLag scan periods; pose prior (pair step) by white-noise acceleration over a step.
  static constexpr double kAccelSigma = 3.0;         ///< m/s^2
  static constexpr double kAngAccelSigma = 1.0;      ///< rad/s^2
  static constexpr double kPriorLag = 0.1;           ///< scan periods
  static constexpr double kStepAccelSigma = 0.5;     ///< m/s^2
  static constexpr double kStepAngAccelSigma = 0.2;  ///< rad/s^2
  static constexpr int kIterations = 8;
  /// Each scan's registration is solved for its frame at this fraction of the scan period
  /// after its first azimuth (mid-scan), not at the scan start (see the top of this file).
  static constexpr double kMidScan = 0.5;
  /// Scan periods: the lag the pair velocity really has (its centre is half a scan before
  /// this scan's), for the published covariance only (kPriorLag steers the estimate).
  static constexpr double kHonestLag = 0.5;
  /// Floor of the residual scales (variance factors on the configured noise) of the
  /// accumulated pose's covariance, radial and tangential (see direction_scales.hpp): a
  /// tangential sigma at least 0.22 of azimuth_sigma (peaks, city_wide: median k_t 0.06).
  static constexpr double kMinResidualScale = 0.05;
  /// Tangential noise floor of the registration's weights (issue 19), measured in each solve
  /// of descriptor matches with at least kMinInliers inliers: the spread across the beam of
  /// the near matches' residuals (|q| azimuth_sigma under kFloorNearFraction of the cap,
  /// where a floor would dominate), beyond what azimuth_sigma explains, at most the cap
  /// (setTangentialFloor, default kTangentialFloor); needs kFloorMinMatches near matches,
  /// else the last solve's floor is kept. Re-weighed while it moves by more than
  /// kFloorTolerance (m), with up to kFloorIterations extra iterations (keyframe_solve.cpp).
  /// Real scans: 0.17 m on the Oxford pair, 0-0.2 m on RADIATE (mostly 0.04-0.17); simulator
  /// with azimuth peaks (layout-0 matrix columns): 0 in 98-100 % of the solves (city_mulran
  /// 83 %, mostly under 0.01 m), at most 0.045-0.093 m: its near returns spread 0.01-0.03 m
  /// across the beam, under azimuth_sigma's 0.045 m at 10 m.
  static constexpr double kFloorNearFraction = 0.5;
  static constexpr int kFloorMinMatches = 10;
  static constexpr double kFloorTolerance = 0.01;
  static constexpr int kFloorIterations = 4;
  /// m: with EstimatorConfig::submap_keyframes > 1, a new keyframe point is averaged with the
  /// nearest point within this gate of each earlier keyframe of the submap (keyframe_map.cpp):
  /// 2.5 sigma of the difference of two returns under the simulator's 0.14 m glint.
  static constexpr double kSubmapGate = 0.5;
  /// A submap keyframe is averaged into the new one unless a rigid fit of its points onto the
  /// new keyframe's (from at least kSubmapMinPairs pairs) moves it further than these (rad, m):
  /// then the chained pose between them is off. Consecutive keyframes' maps agree within
  /// 0.01-0.05 deg on straights and disagree by 0.15-0.45 deg at turn entries, where averaging
  /// handed half of that on (city_narrow layout 2: 1.3 deg in one switch; round 18).
  static constexpr int kSubmapMinPairs = 20;
  static constexpr double kSubmapAgreeYaw = 0.2 * 3.14159265358979323846 / 180.0;
  static constexpr double kSubmapAgreeShift = 0.15;
  /// EstimatorConfig::keyframe_fusion (keyframe_fusion.cpp): the extra registration against
  /// an earlier keyframe is solved with the chained pose as a prior of this many times its
  /// covariance (a weak pull: it only holds directions the registration leaves open; its
  /// covariance leaves the prior out, as every registration's), and refused when its squared
  /// Mahalanobis distance from the chained pose (over the left perturbation, both
  /// covariances) exceeds kFusionChi2 (chi-square, 3 degrees of freedom, 99 %).
  static constexpr double kFusionPriorInflation = 16.0;
  static constexpr double kFusionChi2 = 11.34;
};

}  // namespace spinradar
