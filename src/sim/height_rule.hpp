#pragma once
// The height rule of the renderer (worlds with "height" keys; render_scan.cpp). The plain depth
// map keeps the first wall along each occlusion angle bin and hides everything behind it, as if
// every wall were infinitely tall. With heights, a scatterer of height h at range r is hidden by
// a wall crossing its line of sight at distance d < r with top H iff, seen from the antenna at
// height h_s, the wall's top is not below the line to the scatterer:
//     (h - h_s) / r  <=  (H - h_s) / d          (visible iff (h - h_s) d > (H - h_s) r)
// So per bin only the running maximum of (H - h_s) / d over distance matters: the "skyline".
// A wall lower than the antenna (a parked car) has a negative slope and hides only what lies
// below the line over it; an infinitely tall wall (no height) has slope +inf and hides
// everything, itself included for the walls behind it. With no finite height anywhere the
// skyline of a bin is its first wall, and the rule is the depth map's (test_height_rule.cpp).
#include <algorithm>
#include <cstdint>
#include <limits>

#include "simulator_impl.hpp"

namespace spinradar::sim::detail {

/// (H - h_s) / d: the elevation slope of a top at height H seen at distance d (H = inf: inf).
inline double topSlope(double height, double mount_height, double d) {
  return (height - mount_height) / d;
}

/// From w.hits (every wall hit of every bin, any order) builds the skylines w.sky / w.sky_start
/// of the J bins, and marks in wall_seen every wall that raises the skyline of some bin (its
/// top shows over every wall in front: only those walls' scatterers are bucketed; with no
/// finite height, the first wall of a bin, as the depth map). No allocation once the work
/// vectors have grown.
inline void buildSkylines(ScanWork& w, int J, std::vector<uint8_t>& wall_seen) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  w.hit_start.assign(size_t(J) + 1, 0);
  for (const auto& h : w.hits) ++w.hit_start[h.j + 1];
  for (int j = 0; j < J; ++j) w.hit_start[j + 1] += w.hit_start[j];
  w.hits_sorted.resize(w.hits.size());
  w.sky_start.assign(w.hit_start.begin(), w.hit_start.end() - 1);  // fill cursor for now
  for (const auto& h : w.hits) w.hits_sorted[w.sky_start[h.j]++] = h;
  w.sky.clear();
  w.sky_start.assign(size_t(J) + 1, 0);
  // Ties in distance go to the lower wall index: the depth map's strict "<" over walls in order.
  auto nearer = [](const ScanWork::Hit& a, const ScanWork::Hit& b) {
    return a.t < b.t || (a.t == b.t && a.wall < b.wall);
  };
  for (int j = 0; j < J; ++j) {
    auto* b = w.hits_sorted.data() + w.hit_start[j];
    auto* e = w.hits_sorted.data() + w.hit_start[j + 1];
    std::sort(b, e, nearer);
    double top = -kInf;  // largest slope of the walls so far
    for (auto* it = b; it != e && top < kInf; ++it)
      if (it->slope > top) {  // an infinitely tall wall ends the bin: nothing behind shows
        w.sky.push_back({it->t, it->slope, top, it->wall});
        wall_seen[it->wall] = 1;
        top = it->slope;
      }
    w.sky_start[j + 1] = uint32_t(w.sky.size());
  }
}

/// Whether a scatterer at range r with elevation slope `slope` = (h - h_s) / r clears the walls
/// of bin j that stand more than `tol` in front of it. Its own wall (`own`, -1 = none) does not
/// hide it when that wall sets the skyline there (as the depth map's own-wall exemption).
inline bool clearsWalls(const ScanWork& w, int j, double r, double slope, int32_t own, double tol) {
  const double x = r - tol;
  uint32_t k = w.sky_start[j], last = UINT32_MAX;
  for (const uint32_t e = w.sky_start[j + 1]; k < e && w.sky[k].t < x; ++k) last = k;
  if (last == UINT32_MAX) return true;
  const ScanWork::Step& s = w.sky[last];
  return slope > (s.wall == own ? s.below : s.top);
}

}  // namespace spinradar::sim::detail
