#pragma once
// When a proximity association's answer is already known (issue 19, fifteenth round). The
// proximity ICP (keyframe_tracker.cpp, keyframe_fusion.cpp) pairs every keypoint with its
// nearest keyframe point again after each solve, and the pose moves by millimetres between
// those solves: the grid search, a third of the association at keyframe switches, then finds
// what it found before. A wide search (NearestPointGrid::nearest with a radius) leaves an
// anchor: the query, the nearest point there and the distance of the second-nearest, which
// every other point keeps by the triangle inequality. A later query within reach of it gets
// the grid's own answer from the anchor when that answer is provable (the nearest stays the
// nearest with room to spare, and is clearly inside or outside the gate); otherwise it is
// searched again. Exact: the same pairs, so the same poses.
#include <cmath>
#include <vector>

#include <Eigen/Core>

namespace spinradar {

/// One keypoint's last wide search in the keyframe map: the query (ax, ay), the nearest
/// point within the radius (wide, -1 if none) and sep: every other point lies at least sep
/// from the query (the second-nearest's distance, the radius if none).
struct ProximityAnchor {
  double ax = 0.0, ay = 0.0, sep = -1.0;  ///< sep < 0: no anchor
  int wide = -1;
};

/// m: the room left for rounding (distances of points within 200 m are exact to ~1e-13 m).
constexpr double kProximityBoundMargin = 1e-9;
/// boundedNearest(): the anchor does not decide, search the grid.
constexpr int kUndecided = -2;

/// NearestPointGrid::nearest(q_true, gate) on the points pts the grid was built from, when the
/// anchor proves it; kUndecided otherwise. q is q_true or within `slack` (m) of it (a query
/// computed with approx_se2_exp.hpp): every margin widens by twice the slack, since each
/// distance from q is then within slack of the true one.
inline int boundedNearest(const ProximityAnchor& a, const Eigen::Vector2d& q, double gate,
                          const std::vector<Eigen::Vector2d>& pts, double slack = 0.0) {
  if (!(a.sep >= 0.0)) return kUndecided;
  const double margin = kProximityBoundMargin + 2.0 * slack;
  const double mx = q.x() - a.ax, my = q.y() - a.ay;
  // Every point but a.wide is at least this far from q (NaN for a non-finite q: undecided).
  const double lower = a.sep - std::sqrt(mx * mx + my * my) - margin;
  const bool none_else = lower > gate + margin;  // no other point in the gate
  if (a.wide < 0) return none_else ? -1 : kUndecided;
  const Eigen::Vector2d& p = pts[static_cast<size_t>(a.wide)];
  const double dx = p.x() - q.x(), dy = p.y() - q.y(), d = std::sqrt(dx * dx + dy * dy);
  if (d + margin < gate && d + margin < lower) return a.wide;
  if (d > gate + margin && none_else) return -1;
  return kUndecided;
}

}  // namespace spinradar
