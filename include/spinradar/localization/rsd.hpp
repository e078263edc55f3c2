#pragma once
// Radial Statistics Descriptor (RSD; Cen & Newman 2018, 2019) as used by Burnett et al. 2021
// for localizing against a drive in the opposite direction, where ORB patches of the
// Cartesian image no longer match.
//
// The keypoints of a scan are rasterised into a binary Cartesian grid (one "occupied" pixel
// however many keypoints fall in it). For each keypoint, the occupied pixels within
// `rsd_radius` are counted in `rsd_rings` equal range rings (the range histogram, L2
// normalised) and in `rsd_slices` azimuth slices; the magnitudes of the DFT of the azimuth
// histogram at frequencies 1..M/2, divided by the DC term (the neighbour count), make that
// part rotation invariant too. Descriptor = [range histogram, w * |DFT(azimuth histogram)|].
//
// Speed: the grid is sparse, so instead of scanning every disc of the grid we visit each
// unordered pair of occupied pixels once (pixels bucketed into cells of half the radius) and
// read its ring and both slices from lookup tables indexed by the integer pixel offset: no
// sqrt or atan2 per pair. Keypoints sharing a pixel share the descriptor. Matching is
// brute-force L2 on float rows with the nearest-neighbour ratio test, optionally gated by a
// prior on where each keypoint should land.
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "spinradar/core/feature_frame.hpp"
#include "spinradar/features/matcher.hpp"
#include "spinradar/core/param_macros.hpp"

// clang-format off
#define SPINRADAR_RSD_PARAMS(X) \
  X(double, rsd_resolution, 0.25, 0.05, 5.0, "m/px", "RSD binary keypoint grid resolution") \
  X(double, rsd_radius, 20.0, 2.0, 200.0, "m", "RSD neighbourhood radius around each keypoint") \
  X(int, rsd_rings, 20, 2, 64, "", "RSD range rings (bins of the range histogram)") \
  X(int, rsd_slices, 16, 0, 64, "", "RSD azimuth slices, even (0 = range histogram only)") \
  X(double, rsd_azimuth_weight, 0.5, 0.0, 10.0, "", "Weight of the azimuth-DFT part against the unit range histogram") \
  X(int, rsd_min_neighbours, 5, 0, 10000, "", "Keypoints with fewer occupied pixels in their disc get no descriptor")
// clang-format on

namespace spinradar {

struct RsdConfig {
  SPINRADAR_DECLARE_PARAMS(SPINRADAR_RSD_PARAMS)
  void validate() const;  ///< throws std::invalid_argument naming the parameter
  /// Floats per descriptor: rings + slices / 2.
  int dimension() const { return rsd_rings + rsd_slices / 2; }
};

/// Computes RSD descriptors; holds its lookup tables and working buffers (no allocation per
/// scan once warmed up, apart from cv::Mat growth).
class RsdExtractor {
 public:
  explicit RsdExtractor(const RsdConfig& config = {});
  void setConfig(const RsdConfig& config);
  const RsdConfig& config() const { return config_; }

  /// One CV_32F row of config().dimension() per point (x, y in metres). Rows of points with
  /// fewer than rsd_min_neighbours occupied pixels around them are all zero: rsdValid()
  /// tells them apart and the matcher skips them.
  void compute(const Eigen::Vector2d* points, int n, cv::Mat& descriptors);
  void compute(const std::vector<Keypoint>& keypoints, cv::Mat& descriptors);

 private:
  void rebuildTables();

  RsdConfig config_;
  int radius_px_ = 0, lut_width_ = 0, cell_px_ = 1;
  std::vector<int8_t> ring_lut_;    ///< ring of offset (dx, dy), -1 outside the disc
  std::vector<uint8_t> slice_lut_;  ///< azimuth slice of offset (dx, dy)
  std::vector<float> dft_cos_, dft_sin_;
  // Working buffers.
  std::vector<int64_t> keys_;       ///< packed (pixel, point index) for the unique sort
  std::vector<int> px_, py_;        ///< unique occupied pixels
  std::vector<int> pixel_of_;       ///< point -> unique pixel
  std::vector<int> cell_start_, cell_items_, cell_of_, fill_;
  std::vector<Eigen::Vector2d> pts_;
  std::vector<int32_t> hist_;       ///< unique pixel x (rings + slices)
  std::vector<float> desc_;         ///< unique pixel x dimension
};

/// True when row r of an RSD matrix holds a descriptor (not the all-zero "none" row).
bool rsdValid(const cv::Mat& descriptors, int r);

/// Brute-force L2 matching of RSD rows with the ratio test (same contract as
/// matchDescriptors): for each valid row of d1, its two nearest valid rows of d2; kept when
/// best < nndr * second. With a gate (p1, p2 non-null, gate_m > 0), only pairs with
/// |p1[i] - p2[j]| < gate_m are candidates (p1, p2: where the keypoints should coincide
/// under a prior). `out` is cleared; its capacity is reused.
class RsdMatcher {
 public:
  void match(const cv::Mat& d1, const cv::Mat& d2, double nndr, std::vector<Match>& out,
             const Eigen::Vector2d* p1 = nullptr, const Eigen::Vector2d* p2 = nullptr,
             double gate_m = 0.0);

 private:
  std::vector<int> valid2_;
  std::vector<float> rows2_;   ///< packed valid rows of d2 (gated path)
  std::vector<float> cols2_;   ///< the same transposed, D x V (brute-force path)
  std::vector<float> norm2_;   ///< |row|^2 of each valid row of d2
  std::vector<float> dots_;    ///< 4 x V dot products of a block of queries
  std::vector<int> cell_start_, cell_items_, fill_;
};

}  // namespace spinradar
