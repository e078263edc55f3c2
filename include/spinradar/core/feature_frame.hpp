#pragma once
// Keypoints of one scan with their own acquisition times, and their descriptors.
#include <cstdint>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace spinradar {

struct Keypoint {
  double range = 0.0;    ///< m, after range offset (and Doppler correction when applied)
  double azimuth = 0.0;  ///< rad, clockwise from forward (sensor convention)
  double x = 0.0;        ///< m, REP 103 sensor frame: r cos(phi)
  double y = 0.0;        ///< m, REP 103 sensor frame: -r sin(phi)
  int64_t stamp_ns = 0;  ///< acquisition time of the azimuth the return came from
  float power = 0.f;     ///< detector score / intensity
  int azimuth_index = 0; ///< row in the polar scan
  float bin = 0.f;       ///< fractional range bin
};

/// Features of one scan: keypoints, one descriptor row per keypoint.
struct FeatureFrame {
  int64_t stamp_ns = 0;            ///< reference time of the scan (first valid azimuth)
  /// The sensor's rotation period (ns) from the scan's row stamps (rotationPeriodNs in
  /// polar_scan.hpp); 0 = unknown (frames built without a scan). Not the stamp step to the
  /// previous scan, which is two periods after a dropped scan (scan_period.hpp).
  int64_t period_ns = 0;
  std::vector<Keypoint> keypoints;
  cv::Mat descriptors;             ///< keypoints.size() x D, CV_8U (ORB: D = 32)
};

}  // namespace spinradar
