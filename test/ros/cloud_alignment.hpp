#pragma once
// How well two point clouds of a static scene line up once placed in the world: the mean
// distance from each point of one cloud to its nearest neighbour in the other, counting only
// pairs closer than a gate (points seen in one scan only do not count). Grid hashing keeps
// it linear in the number of points.
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

namespace spinradar_test {

class PointGrid {
 public:
  PointGrid(const std::vector<Eigen::Vector2d>& points, double cell) : points_(points), cell_(cell) {
    for (size_t i = 0; i < points.size(); ++i) cells_[key(cellOf(points[i].x()), cellOf(points[i].y()))].push_back(i);
  }
  /// Distance to the nearest point within `gate` (gate <= cell), or -1 when none.
  double nearest(const Eigen::Vector2d& p, double gate) const {
    const int64_t cx = cellOf(p.x()), cy = cellOf(p.y());
    double best = gate * gate;
    bool found = false;
    for (int64_t dx = -1; dx <= 1; ++dx)
      for (int64_t dy = -1; dy <= 1; ++dy) {
        auto it = cells_.find(key(cx + dx, cy + dy));
        if (it == cells_.end()) continue;
        for (size_t i : it->second) {
          const double d2 = (points_[i] - p).squaredNorm();
          if (d2 <= best) {
            best = d2;
            found = true;
          }
        }
      }
    return found ? std::sqrt(best) : -1.0;
  }

 private:
  int64_t cellOf(double v) const { return static_cast<int64_t>(std::floor(v / cell_)); }
  static int64_t key(int64_t x, int64_t y) { return (x << 32) ^ (y & 0xffffffff); }
  std::vector<Eigen::Vector2d> points_;
  double cell_;
  std::unordered_map<int64_t, std::vector<size_t>> cells_;
};

struct Alignment {
  double mean = 0;   ///< m, mean nearest-neighbour distance of the gated pairs
  size_t pairs = 0;  ///< points of `b` with a neighbour in `a` within the gate
};

/// Mean nearest-neighbour distance from b's points to a's (both in the same frame).
inline Alignment alignment(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b,
                           double gate) {
  PointGrid grid(a, gate);
  Alignment out;
  double sum = 0;
  for (const auto& p : b) {
    const double d = grid.nearest(p, gate);
    if (d < 0) continue;
    sum += d;
    ++out.pairs;
  }
  out.mean = out.pairs ? sum / out.pairs : 0.0;
  return out;
}

}  // namespace spinradar_test
