#pragma once
// Keypoint detectors on polar scans: Cen2018 (the real-time variant of Burnett et al. 2021) and
// CA-CFAR. Both work per azimuth and keep one keypoint (the peak) per run of detections.
#include <cstdint>
#include <vector>

#include "spinradar/core/feature_frame.hpp"
#include "spinradar/core/params.hpp"
#include "spinradar/core/polar_scan.hpp"

namespace spinradar {

/// Reusable detector: holds its working buffers, so repeated calls do not allocate once the
/// output vector has grown to its working size.
///
/// Ranges are `scan.rangeOfBin(bin) + config.range_offset`: loaders already put a dataset's own
/// offset (Boreas -0.31 m) into PolarScan::range_offset; the config offset is for sources whose
/// scans carry none. Rows with valid = 0 are skipped. Keypoints come out ordered by azimuth row,
/// then range.
class Detector {
 public:
  explicit Detector(const DetectorConfig& config = {});
  void setConfig(const DetectorConfig& config);
  const DetectorConfig& config() const { return config_; }

  /// DetectorConfig::azimuth_peaks. Off (default, the paper's Cen2018): one keypoint per row per
  /// run, at the row's angle and time. On (both detectors): of the rows that see the same return
  /// (same range +-2 bins), only the row with the highest power is kept, moved to a sub-row
  /// azimuth (parabola through the neighbouring rows) and the matching time. Row keypoints are
  /// not fixed world points: when a turn moves every target by a fractional number of rows,
  /// descriptor matching pairs rows with the nearest whole-row shift, which biased the yaw rate
  /// by up to ~1 % on simulated turns; azimuth peaks remove that (test/sim/test_keypoint_truth.cpp).
  /// Off by default: on the simulated city route (full physics) peaks cut mc_doppler drift
  /// 2.67 -> 2.22 % and keyframe 0.77 -> 0.58 %, but on the real Oxford sample they keep a third
  /// of the keypoints (1718 -> 590, MC-RANSAC inliers 132 -> 63) and the yaw error of one of its
  /// two pairs grew 0.007 -> 0.12 deg (mc_doppler). Detector cost +0.1 ms per scan.
  void setAzimuthPeaks(bool on) { config_.azimuth_peaks = on; }
  /// Cen2018: score every bin instead of only the candidates that can pass (detector.cpp). Same
  /// keypoints, slower; the switch exists so that tests compare the two.
  void setScoreEveryBin(bool on) { score_every_bin_ = on; }
  bool azimuthPeaks() const { return config_.azimuth_peaks; }

  /// Clears `out` and fills it with the keypoints of `scan` (config.detector selects the method).
  void detect(const PolarScan& scan, std::vector<Keypoint>& out);

  /// Cen2018, real-time variant. Per azimuth: q = power - mean(power); p = Gaussian(q) with sigma
  /// `sigma_gauss` bins (kernel 2*floor(1.5 sigma)+1 taps as the authors' code, reflected
  /// borders); noise sigma = sqrt(2 mean(q^2 | q < 0)); score
  /// y = q (1 - N(q - p)) + p (N(q - p) - N(p)), N(u) = exp(-u^2 / 2 sigma^2);
  /// bins with y > zq * sigma form runs; each run gives its highest-y bin (refined to a
  /// fractional bin by a parabola through its neighbours). Keypoint::power = y at the peak.
  void detectCen2018(const PolarScan& scan, std::vector<Keypoint>& out);

  /// CA-CFAR: a bin is detected when power > cfar_threshold * mean of the `cfar_window` training
  /// cells on each side beyond `cfar_guard` guard cells (one-sided near the ends). One keypoint
  /// per run, at its strongest bin. Keypoint::power = power - cell average.
  void detectCfar(const PolarScan& scan, std::vector<Keypoint>& out);

 private:
  /// Throws std::invalid_argument when the scan's arrays disagree with its size.
  static void requireConsistent(const PolarScan& scan);
  void emit(const PolarScan& scan, int a, double bin, float score, std::vector<Keypoint>& out) const;
  void rangeWindow(const PolarScan& scan, int& b0, int& b1) const;
  /// Azimuthal peaks only (DetectorConfig::azimuth_peaks).
  void keepAzimuthPeaks(const PolarScan& scan, std::vector<Keypoint>& out) const;
  void rebuildKernel();

  DetectorConfig config_;
  int radius_ = 0;               ///< Gaussian half width in bins
  double cand_factor_ = 0;       ///< Cen2018 candidates: q > cand_factor_ sigma (detector.cpp)
  bool score_every_bin_ = false;
  std::vector<int16_t> kernel_;  ///< fixed-point Gaussian taps (sum 2^15), zero-padded to 8k
  std::vector<uint8_t> padded_;  ///< one row with reflected borders
  std::vector<int> cand_;        ///< candidate bins of one row
  std::vector<float> p_, q_, y_; ///< smoothed, raw (minus mean) and score at the candidates
  std::vector<int32_t> prefix_;  ///< CFAR prefix sums
  std::vector<uint8_t> hit_;     ///< CFAR detections of one row
  std::vector<float> mean_;      ///< CFAR cell averages of one row
  std::vector<double> cos_, sin_;
};

}  // namespace spinradar
