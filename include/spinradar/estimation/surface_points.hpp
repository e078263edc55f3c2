#pragma once
// Oriented surface points (CFEAR, Adolfsson et al. 2022): the returns of a scan grouped on a
// grid, each occupied cell's neighbourhood summarised by its mean and the normal of its
// spread (the eigenvector of the smaller eigenvalue). A facade seen over many azimuth rows
// becomes a few points with a well-defined normal, so a point-to-line cost no longer feels
// the row quantisation of single keypoints along the facade. And a sorted-cell index for
// nearest-neighbour lookups that reuses its buffers (no allocation per scan after warm-up).
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace spinradar {

struct SurfacePoint {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  Eigen::Vector2d normal = Eigen::Vector2d::UnitX();  ///< unit
  /// Planarity 1 - lambda_min / lambda_max in [0, 1]: 0 for a round blob, 1 for a line.
  double planarity = 0.0;
  int count = 0;  ///< returns in the neighbourhood
};

/// Points hashed into square cells of one size; lookups visit the 3x3 cells around a point.
class CellIndex {
 public:
  void build(const Eigen::Vector2d* pts, int n, double cell);
  /// Index of the nearest point within `radius` (<= cell) of q, or -1.
  int nearest(const Eigen::Vector2d& q, double radius) const;
  /// (cell key, point index) sorted by cell: the points of one cell are consecutive.
  const std::vector<std::pair<int64_t, int>>& entries() const { return entries_; }
  /// Calls f(i) for every point in the 3x3 cells around q.
  template <class F>
  void forNeighbourCells(const Eigen::Vector2d& q, F&& f) const {
    const int64_t cx = cellOf(q.x()), cy = cellOf(q.y());
    for (int64_t dx = -1; dx <= 1; ++dx)
      for (int64_t dy = -1; dy <= 1; ++dy) {
        auto it = lowerBound(key(cx + dx, cy + dy));
        for (; it != entries_.end() && it->first == key(cx + dx, cy + dy); ++it) f(it->second);
      }
  }

 private:
  int64_t cellOf(double v) const { return static_cast<int64_t>(std::floor(v * inv_cell_)); }
  static int64_t key(int64_t cx, int64_t cy) { return (cx << 32) ^ (cy & 0xffffffffLL); }
  std::vector<std::pair<int64_t, int>>::const_iterator lowerBound(int64_t k) const;
  std::vector<std::pair<int64_t, int>> entries_;  ///< (cell key, point index), sorted
  const Eigen::Vector2d* pts_ = nullptr;
  double inv_cell_ = 1.0;
};

/// Surface points of a point set: one per occupied cell of size `radius`, from the points
/// within `radius` of that cell's centroid; cells with fewer than min_points neighbours are
/// skipped. `out` is resized (capacity reused).
class SurfaceExtractor {
 public:
  void extract(const std::vector<Eigen::Vector2d>& pts, double radius, int min_points,
               std::vector<SurfacePoint>& out);

 private:
  CellIndex index_;
};

}  // namespace spinradar
