#pragma once
// Read-only tables of the Cartesian projector (cartesian.hpp): built once per geometry and
// shared, immutable, by the projectors of several threads.
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "spinradar/core/polar_scan.hpp"
#include "spinradar/features/huge_page_allocator.hpp"

namespace spinradar {

/// Range and angle of every pixel of one image geometry (row-major), from which the remap
/// tables of any scan geometry are built.
struct CartesianPixelGeometry {
  double resolution = 0;  ///< m per pixel
  int width = 0;          ///< pixels per side
  HugePageVector<float> range;     ///< m, of the pixel centre
  HugePageVector<uint16_t> angle;  ///< clockwise from forward, 1/65536 turns
};

/// Per pixel, where its value comes from for one scan geometry (the azimuth angles, bins,
/// range resolution and offset recorded here) and one image geometry.
struct CartesianRemap {
  int azimuths = 0, bins = 0;
  double range_resolution = 0, offset = 0;
  std::vector<double> angles;        ///< the scan's azimuths the tables were built for
  int box = 1;                       ///< range bins averaged per pixel
  HugePageVector<uint32_t> offsets;  ///< per pixel: index of its (row, bin) in the smoothed rows
  HugePageVector<uint8_t> weights;   ///< per pixel: weight of the next row, /256

  /// Whether `scan` (with range offset `offset`) may use these tables: the same azimuths, bins,
  /// resolution and offset, and every azimuth angle within 10 % of an azimuth step of the one
  /// they were built for (one encoder count of jitter does not count as a new geometry).
  bool fits(const PolarScan& scan, double offset) const;
};

/// The tables of one image geometry, shared by every projector given this object (for example
/// the feature extractors of the odometry's loader threads): the pixel geometry is built on
/// first use and the remap tables once per scan geometry, under a lock, so that threads asking
/// at the same time wait for one build instead of each building its own. Everything handed out
/// is const: safe to read from any thread while others ask for tables.
class CartesianTableCache {
 public:
  CartesianTableCache(double resolution, int width);
  double resolution() const { return resolution_; }
  int width() const { return width_; }

  std::shared_ptr<const CartesianPixelGeometry> pixels();
  /// The newest remap tables when `scan` fits them, else new ones built for it (`built` says
  /// which). Older tables stay valid for whoever still holds them.
  std::shared_ptr<const CartesianRemap> remapFor(const PolarScan& scan, double offset, bool& built);
  int builds() const;  ///< remap tables built so far, by all users
  /// Builds the remap tables with AVX2 when the CPU has it (default); off = portable loop. Both
  /// give identical tables (the switch exists so that tests compare them).
  void setUseSimd(bool use) {
    std::lock_guard<std::mutex> lock(mutex_);
    use_simd_ = use;
  }

 private:
  std::shared_ptr<const CartesianPixelGeometry> pixelsLocked();

  const double resolution_;
  const int width_;
  mutable std::mutex mutex_;
  std::shared_ptr<const CartesianPixelGeometry> pixels_;
  std::shared_ptr<const CartesianRemap> remap_;
  int builds_ = 0;
  bool use_simd_ = true;
};

}  // namespace spinradar
