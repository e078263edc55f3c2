// Nearest-point search over a keyframe's map points (KeyframeTracker): the points bucketed in
// bands of y, each band sorted by x, so a query looks only at the few bands and the x range
// within its gate. The x-sorted strip it replaces spanned the whole scan in y: with the
// Oxford model's clutter it held hundreds of points per query, and at keyframe switches
// (keyframe_graph) the search was the largest single cost (issue 19, thirteenth round).
// The answer is the strip's, to the bit: the nearest point strictly within the gate, ties to
// the smaller (x, index). Each band's start of an x range is found through a directory of
// x cells (no binary search: at keyframe_graph switches that search was a third of the
// proximity association, issue 19, session 17).
#pragma once

#include <vector>

#include <Eigen/Core>

namespace spinradar {

class NearestPointGrid {
 public:
  /// Buckets the points (finite; others are never found). Reuses its buffers: no heap
  /// allocation once they have held as many points.
  void build(const std::vector<Eigen::Vector2d>& pts);
  void clear();
  bool empty() const { return entries_.empty(); }
  /// The index of the nearest point with squared distance under gate^2 from q; -1 if none.
  int nearest(const Eigen::Vector2d& q, double gate) const;
  /// nearest(q, gate), to the bit, and from the same pass over the points within radius
  /// (>= gate): the nearest point there (`wide`, -1 if none) and the squared distance of the
  /// second-nearest (`second2`, radius^2 if none; -1 when nothing was searched: an empty
  /// gate or a non-finite q). Every point but `wide` lies at least
  /// sqrt(second2) from q (up to rounding), which bounds later queries near q
  /// (proximity_bound.hpp). Keeps the second-nearest distance for that bound.
  int nearest(const Eigen::Vector2d& q, double gate, double radius, int& wide,
              double& second2) const;

  static constexpr double kBand = 1.0;  ///< m, band height (gates are 0.3-1.5 m)
  static constexpr double kCell = 1.0;  ///< m, x cell width of the directory (at least)

 private:
  struct Entry {
    double x, y;
    int index;
  };
  int bandOf(double y) const;
  int cellOf(double x) const;  ///< monotone in x, clamped to [0, cells_ - 1]
  const Entry* firstAtOrAfter(int band, double x) const;  ///< first entry of band with x >= x
  std::vector<Entry> entries_;   ///< band by band, each band sorted by (x, index)
  std::vector<int> band_start_;  ///< entries_ of band b: [band_start_[b], band_start_[b + 1])
  std::vector<int> band_of_;     ///< build scratch: each point's band
  /// Band b's first entry with cellOf(x) >= c: cell_start_[b * cells_ + c]. Every entry before
  /// it has x below any x of cell c (cellOf is monotone), so a search starts there.
  std::vector<int> cell_start_;
  double y0_ = 0.0, inv_band_ = 1.0 / kBand;
  double x0_ = 0.0, inv_cell_ = 1.0 / kCell;
  int bands_ = 0, cells_ = 0;
};

}  // namespace spinradar
