#pragma once
// The rotation period a scan's mid-scan reference is placed with (keyframe and surface
// trackers). The stamp step to the previous scan is the period only while no scan is missing:
// after a dropped scan (or on a recording read every other scan) it is two periods, and a
// reference at half of it falls at the scan's end, not its middle (issue 19: RADIATE read every
// other scan, 0.5 s steps of 0.25 s scans).

#include <algorithm>
#include <cstdint>

#include "spinradar/core/feature_frame.hpp"

namespace spinradar {

/// Tracks the rotation period over a run. `step` is the stamp step to the previous scan (s).
class ScanPeriod {
 public:
  /// A step longer than this many times the scan's own azimuth span is a gap.
  static constexpr double kGapRatio = 1.5;

  /// The period to place `f`'s mid-scan reference with: the step, unless the step is a gap;
  /// then the last step that was not one, or (none yet) the span of the scan's own keypoint
  /// stamps, which is the period to within the rows after its last keypoint.
  double update(const FeatureFrame& f, double step) {
    int64_t last = f.stamp_ns;
    for (const Keypoint& k : f.keypoints) last = std::max(last, k.stamp_ns);
    const double span = 1e-9 * static_cast<double>(last - f.stamp_ns);
    if (span <= 0.0 || step <= kGapRatio * span) {
      period_ = step;
      return step;
    }
    return period_ > 0.0 ? period_ : span;
  }

 private:
  double period_ = 0.0;  ///< the last step that was not a gap (s), 0 before the first
};

}  // namespace spinradar
