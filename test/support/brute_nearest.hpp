// The reference for NearestPointGrid and the proximity anchors: the x-sorted strip's answer,
// i.e. the smallest squared distance under gate^2, ties to the smaller (x, index).
#pragma once

#include <vector>

#include <Eigen/Core>

namespace spinradar::testing {

inline int bruteNearest(const std::vector<Eigen::Vector2d>& pts, const Eigen::Vector2d& q,
                        double gate) {
  double best = gate * gate;
  int best_j = -1;
  for (size_t i = 0; i < pts.size(); ++i) {
    const double dx = pts[i].x() - q.x(), dy = pts[i].y() - q.y(), d2 = dx * dx + dy * dy;
    const bool tie_wins = best_j >= 0 && d2 == best &&
                          (pts[i].x() < pts[best_j].x() ||
                           (pts[i].x() == pts[best_j].x() && static_cast<int>(i) < best_j));
    if (d2 < best || tie_wins) {
      best = d2;
      best_j = static_cast<int>(i);
    }
  }
  return best_j;
}

}  // namespace spinradar::testing
