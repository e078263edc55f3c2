#pragma once
// Keypoint times from a fitted firing-time model instead of the recorded row stamps.
// Oxford and MulRan stamp rows with packet arrival times (16 rows ~135-205 us apart, then a
// 7-8 ms gap: `spinradar diagnose --timing-only`), which is up to 8 ms of false timing per
// row; the radar fires at a uniform rate. A least-squares line through (row, stamp) over the
// scan's valid rows recovers the firing times up to one constant offset per scan.
#include <vector>

#include "spinradar/core/feature_frame.hpp"
#include "spinradar/core/polar_scan.hpp"

namespace spinradar {

/// Replaces each keypoint's row stamp by the fitted line at its row, keeping any sub-row
/// offset the detector added (azimuth_peaks). No-op for fewer than 2 valid rows.
void uniformKeypointTimes(const PolarScan& scan, std::vector<Keypoint>& keypoints);

}  // namespace spinradar
