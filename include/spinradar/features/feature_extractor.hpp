#pragma once
// Polar scan -> keypoints (Cen2018 or CA-CFAR) -> Cartesian image -> ORB descriptors.
#include <memory>

#include <opencv2/core/mat.hpp>

#include "spinradar/core/feature_frame.hpp"
#include "spinradar/core/params.hpp"
#include "spinradar/core/polar_scan.hpp"
#include "spinradar/core/stage_times.hpp"

namespace spinradar {

class CartesianTableCache;

class FeatureExtractor {
 public:
  FeatureExtractor(const DetectorConfig& detector, const FeatureConfig& features);
  /// Shares the read-only Cartesian tables of `tables` (see cartesianTables()) when they have
  /// this config's image geometry, so that extractors on several threads build them once;
  /// otherwise (or when null) builds its own. Each extractor keeps its own working buffers.
  FeatureExtractor(const DetectorConfig& detector, const FeatureConfig& features,
                   std::shared_ptr<CartesianTableCache> tables);
  ~FeatureExtractor();
  FeatureExtractor(FeatureExtractor&&) noexcept;
  FeatureExtractor& operator=(FeatureExtractor&&) noexcept;

  /// Detects keypoints and computes one descriptor per kept keypoint (keypoints whose ORB
  /// patch falls off the image are dropped, so keypoints and descriptor rows stay aligned).
  /// Reuses internal buffers: no allocation per scan once warmed up.
  void extract(const PolarScan& scan, FeatureFrame& out, StageTimes* times = nullptr);

  /// The Cartesian image of the last extracted scan (CV_8U, cart_pixel_width square,
  /// sensor at the centre, x forward = up, y left = left). For debug display.
  const cv::Mat& cartesianImage() const;

  /// The Cartesian projector's tables (thread-safe, read only once built), to share.
  const std::shared_ptr<CartesianTableCache>& cartesianTables() const;

  /// Overrides DetectorConfig::azimuth_peaks (keypoints at azimuthal peaks, sub-row azimuths).
  void setAzimuthPeaks(bool on);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace spinradar
