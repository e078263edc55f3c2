#pragma once
// Scan timing, one definition for every estimator (issue 19). A scan's rotation period is the
// sensor's: its row stamps tell it (FeatureFrame::period_ns, rotationPeriodNs). The stamp step
// to the previous scan is the period only while no scan is missing: after a dropped scan (a
// network loss), or on a recording read every other scan, it is two periods. Used for
//  - the mid-scan reference of the keyframe and surface trackers (half a period after the
//    scan's start; half of a two-period step falls at the scan's end), and
//  - the centre of a pair velocity (refined_estimator.cpp): a constant velocity fitted to two
//    scans t1, t2 stands for [t1, t2 + period], centred half a PERIOD after the middle of the
//    step, so interpolating between two pairs to the step's middle weighs the earlier pair
//    period / (step1 + step2): 1/2 only when both steps are one period.

#include <algorithm>
#include <cstdint>

#include "spinradar/core/feature_frame.hpp"

namespace spinradar {

/// Tracks the rotation period over a run. `step` is the stamp step to the previous scan (s).
class ScanPeriod {
 public:
  /// A step longer than this many times the rotation period is a gap (a dropped scan).
  static constexpr double kGapRatio = 1.5;

  /// The rotation period of `f` (s): its row stamps' (period_ns) or, for a frame built without
  /// a scan, the span of its keypoint stamps (the period to within the rows after its last
  /// keypoint); 0 when neither is known.
  static double rotation(const FeatureFrame& f) {
    if (f.period_ns > 0) return 1e-9 * static_cast<double>(f.period_ns);
    int64_t last = f.stamp_ns;
    for (const Keypoint& k : f.keypoints) last = std::max(last, k.stamp_ns);
    return 1e-9 * static_cast<double>(last - f.stamp_ns);
  }

  /// Is a stamp step `step` (s) a gap for a sensor of rotation period `rotation` (s)?
  static bool isGap(double step, double rotation) {
    return rotation > 0.0 && step > kGapRatio * rotation;
  }

  /// The weight of the earlier of two consecutive pair velocities (steps step1, then step2, s)
  /// in the velocity over step2 (see the top of this file): 1/2 while neither step is a gap
  /// (the period is then the mean step), rotation / (step1 + step2) otherwise.
  static double earlierPairWeight(double step1, double step2, double rotation) {
    if (!(step1 > 0.0 && step2 > 0.0)) return 0.5;
    if (!isGap(step1, rotation) && !isGap(step2, rotation)) return 0.5;
    return std::clamp(rotation / (step1 + step2), 0.0, 0.5);
  }

  /// The period to place `f`'s mid-scan reference with: the step, unless the step is a gap;
  /// then the scan's rotation period (its row stamps), or for a frame without one the last
  /// step that was not a gap, or (none yet) the span of the scan's own keypoint stamps.
  double update(const FeatureFrame& f, double step) {
    const double rot = rotation(f);
    if (!(rot > 0.0) || !isGap(step, rot)) {
      period_ = step;
      return step;
    }
    if (f.period_ns > 0) return rot;
    return period_ > 0.0 ? period_ : rot;
  }

 private:
  double period_ = 0.0;  ///< the last step that was not a gap (s), 0 before the first
};

}  // namespace spinradar
