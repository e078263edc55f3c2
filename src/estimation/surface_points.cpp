#include "spinradar/estimation/surface_points.hpp"

#include <algorithm>

namespace spinradar {

void CellIndex::build(const Eigen::Vector2d* pts, int n, double cell) {
  pts_ = pts;
  inv_cell_ = 1.0 / cell;
  if (entries_.capacity() < static_cast<size_t>(n)) entries_.reserve(static_cast<size_t>(n) * 2);
  entries_.resize(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) entries_[i] = {key(cellOf(pts[i].x()), cellOf(pts[i].y())), i};
  std::sort(entries_.begin(), entries_.end());
}

std::vector<std::pair<int64_t, int>>::const_iterator CellIndex::lowerBound(int64_t k) const {
  return std::lower_bound(entries_.begin(), entries_.end(), std::pair<int64_t, int>(k, -1));
}

int CellIndex::nearest(const Eigen::Vector2d& q, double radius) const {
  double best = radius * radius;
  int best_i = -1;
  forNeighbourCells(q, [&](int i) {
    const double d2 = (pts_[i] - q).squaredNorm();
    if (d2 < best) {
      best = d2;
      best_i = i;
    }
  });
  return best_i;
}

void SurfaceExtractor::extract(const std::vector<Eigen::Vector2d>& pts, double radius,
                               int min_points, std::vector<SurfacePoint>& out) {
  out.clear();
  const int n = static_cast<int>(pts.size());
  if (n == 0) return;
  index_.build(pts.data(), n, radius);
  const auto& e = index_.entries();
  const double r2 = radius * radius;
  for (size_t a = 0; a < e.size();) {
    size_t b = a;
    Eigen::Vector2d c = Eigen::Vector2d::Zero();
    for (; b < e.size() && e[b].first == e[a].first; ++b) c += pts[e[b].second];
    c /= static_cast<double>(b - a);
    a = b;
    // Mean and spread of the returns within `radius` of the cell's centroid.
    Eigen::Vector2d s = Eigen::Vector2d::Zero();
    Eigen::Matrix2d ss = Eigen::Matrix2d::Zero();
    int cnt = 0;
    index_.forNeighbourCells(c, [&](int i) {
      const Eigen::Vector2d d = pts[i] - c;
      if (d.squaredNorm() > r2) return;
      s += d;
      ss += d * d.transpose();
      ++cnt;
    });
    if (cnt < min_points) continue;
    const Eigen::Vector2d m = s / cnt;
    const Eigen::Matrix2d cov = ss / cnt - m * m.transpose();
    // Closed-form eigen decomposition of the symmetric 2x2 spread.
    const double tr = cov.trace(), det = cov(0, 0) * cov(1, 1) - cov(0, 1) * cov(1, 0);
    const double disc = std::sqrt(std::max(0.0, 0.25 * tr * tr - det));
    const double l_max = 0.5 * tr + disc, l_min = std::max(0.0, 0.5 * tr - disc);
    if (!(l_max > 1e-12)) continue;
    // Eigenvector of l_max is the line direction; the normal is perpendicular to it.
    Eigen::Vector2d dir(cov(0, 1), l_max - cov(0, 0));
    if (dir.squaredNorm() < 1e-18) dir = Eigen::Vector2d(l_max - cov(1, 1), cov(0, 1));
    if (dir.squaredNorm() < 1e-18) dir = Eigen::Vector2d::UnitX();
    dir.normalize();
    SurfacePoint sp;
    sp.mean = c + m;
    sp.normal = Eigen::Vector2d(-dir.y(), dir.x());
    sp.planarity = 1.0 - l_min / l_max;
    sp.count = cnt;
    out.push_back(sp);
  }
}

}  // namespace spinradar
