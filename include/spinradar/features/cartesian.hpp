#pragma once
// Polar scan -> square Cartesian image (sensor at the centre, x forward = up, y left = left).
#include <cstdint>
#include <memory>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "spinradar/core/polar_scan.hpp"
#include "spinradar/features/cartesian_tables.hpp"
#include "spinradar/features/huge_page_allocator.hpp"

namespace spinradar {

/// Renders polar scans into a Cartesian image through a precomputed per-pixel table. Each pixel
/// is the average of the range bins it covers (a centred moving average over
/// round(cart_resolution / range_resolution) bins, so that narrow returns between pixel centres
/// are not lost), interpolated linearly between the two neighbouring azimuths. The tables
/// depend only on the scan geometry (azimuth angles, bins, range resolution and offset) and the
/// image geometry; they are cached and rebuilt only when one of these changes materially
/// (an azimuth angle by more than 10 % of an azimuth step, i.e. < 0.8 px at 125 m for 400
/// azimuths: one encoder count of jitter does not trigger it). A rebuild for new angles costs a
/// few ms (per-pixel range and angle are kept per image geometry; angle -> row goes through a
/// 65536-entry table). Pixels beyond the last bin are 0. The tables live in a
/// CartesianTableCache (cartesian_tables.hpp), read only, which projectors on several threads
/// may share: they are then built once for all of them.
///
/// Pixel convention (as the Oxford SDK): pixel centres at integer (col, row), the sensor at
/// ((W-1)/2, (W-1)/2); a point (x, y) of the REP 103 sensor frame is at
/// col = c - y / res, row = c - x / res.
class CartesianProjector {
 public:
  explicit CartesianProjector(double resolution = 0.2592, int width = 964);
  /// Renders with the tables of `tables` (its image geometry), shared with other projectors.
  explicit CartesianProjector(std::shared_ptr<CartesianTableCache> tables);
  /// A new geometry gets tables of its own (no longer shared).
  void setImageGeometry(double resolution, int width);
  const std::shared_ptr<CartesianTableCache>& tables() const { return cache_; }

  /// Renders `scan` into `image` (CV_8UC1, width x width, bilinear). `extra_range_offset` is
  /// added to scan.range_offset (the detector's range_offset, so image and keypoints agree).
  /// Invalid rows take the data of the nearest valid row before them. No allocation once the
  /// tables for this geometry exist and `image` has the right size.
  void render(const PolarScan& scan, cv::Mat& image, double extra_range_offset = 0.0);

  /// Fractional pixel (col, row) of a point (x, y) in the sensor frame (m).
  cv::Point2f toPixel(double x, double y) const {
    return {static_cast<float>(centre_ - y / resolution_), static_cast<float>(centre_ - x / resolution_)};
  }
  /// Sensor-frame point (x, y) of a fractional pixel (col, row).
  cv::Point2d toMetric(const cv::Point2f& px) const {
    return {(centre_ - px.y) * resolution_, (centre_ - px.x) * resolution_};
  }

  /// Lets the remap use AVX-512 or AVX2 gathers when the CPU has them (default). Off = portable
  /// loop; all give identical images (the switch exists so tests cover every path).
  void setUseSimd(bool use) { simd_ = use ? 2 : 0; }
  /// 2 = AVX-512 when the CPU has it, else AVX2 (default); 1 = AVX2 at most; 0 = portable.
  void setSimdLevel(int level) { simd_ = level; }

  double resolution() const { return resolution_; }
  int width() const { return width_; }
  /// How many times this projector built remap tables (not counting those it got built by
  /// another projector sharing its tables).
  int tableBuilds() const { return builds_; }
  /// The remap tables of the last render (null before the first).
  const std::shared_ptr<const CartesianRemap>& remap() const { return remap_; }
  /// Per pixel (row-major): range (m) of its centre and clockwise angle from forward in
  /// 1/65536 turns, from which the tables are built (built on first use).
  template <class T>
  using Table = HugePageVector<T>;
  const Table<float>& pixelRanges() const { return cache_->pixels()->range; }
  const Table<uint16_t>& pixelAngles() const { return cache_->pixels()->angle; }

 private:
  void remapRows(uint8_t* image, size_t image_step) const;

  double resolution_ = 0.2592;
  int width_ = 964;
  double centre_ = 481.5;
  int builds_ = 0;
  int simd_ = 2;
  std::shared_ptr<CartesianTableCache> cache_;
  std::shared_ptr<const CartesianRemap> remap_;  ///< tables of the current scan geometry
  Table<uint8_t> polar_;  ///< (azimuths + 3) x bins: smoothed rows, row 0 again (wrap), 2 zero rows
};

}  // namespace spinradar
