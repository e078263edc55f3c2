#pragma once
// Cauchy (Lorentzian) IRLS weights for the refit of `refined`, the pair estimate of keyframe and
// surface (EstimatorConfig::robust_loss). Why: real scans have heavy-tailed match residuals.
// On the Oxford sample, matches within 1 m of the ground truth have a tangential spread of
// 0.14-0.34 rows (median absolute deviation) but a standard deviation of 0.5-0.9 rows, so a
// plain least squares over the RANSAC inliers follows whichever near-threshold matches the
// gate lets in: the per-pair yaw moved by up to 0.4 deg with inlier_threshold 0.15-0.8 m.
// The scale comes from the residuals themselves (their median), so the kernel adapts to each
// sensor's noise instead of trusting range_sigma / azimuth_sigma.
// Not in mc / mc_doppler (the paper's estimators, kept as published): with row keypoints in a
// steady turn the rounding of the far matches is correlated, and the Cauchy weights favoured
// the matches rounded towards whole-row shifts: yaw rate 2 % low / 3 % high turning in place
// (test_mc_ransac QuantizedAzimuthsInASteadyTurn, plain: < 0.3 %). Not in the keyframe
// registration: there a scan holding a yaw-rate step (30 % into the scan) was fitted to its
// larger part and the error stayed in the keyframe chain (1.4 deg against 0.1 deg plain,
// test_keyframe_tracker YawRateStepInsideAScanStaysOutOfTheChain), even with the weights
// starting after the gate had settled.
#include <algorithm>
#include <vector>

namespace spinradar {

/// Cauchy constant for 95 % asymptotic efficiency under Gaussian noise (Holland & Welsch 1977).
constexpr double kCauchyConstant = 2.3849;
/// Fewer residuals than this: no robust scale (plain least squares).
constexpr size_t kCauchyMinResiduals = 8;

/// 1 / (c^2 s^2) for squared normalised 2-d residuals r2 (e^T S^-1 e), with s^2 estimated from
/// their median (the median of a chi^2 with 2 degrees of freedom is 1.386). Reorders r2.
/// Returns 0 (all weights 1) for fewer than kCauchyMinResiduals residuals.
inline double cauchyInverseScale(std::vector<double>& r2) {
  if (r2.size() < kCauchyMinResiduals) return 0.0;
  const auto mid = r2.begin() + static_cast<std::ptrdiff_t>(r2.size() / 2);
  std::nth_element(r2.begin(), mid, r2.end());
  const double s2 = std::max(*mid / 1.386, 1e-12);
  return 1.0 / (kCauchyConstant * kCauchyConstant * s2);
}

/// IRLS weight of a squared normalised residual (1 when inv_scale is 0).
inline double cauchyWeight(double r2, double inv_scale) { return 1.0 / (1.0 + r2 * inv_scale); }

}  // namespace spinradar
