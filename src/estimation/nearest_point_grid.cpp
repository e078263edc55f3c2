#include "spinradar/estimation/nearest_point_grid.hpp"

#include <algorithm>
#include <cmath>

namespace spinradar {

namespace {
constexpr int kMaxBands = 1 << 16;  // a wider spread of y widens the bands instead
constexpr size_t kMaxDirectory = 1 << 18;  // bands x cells; a wider map widens the cells

// Grows with headroom, so that the next, slightly larger map does not reallocate.
template <typename T>
void fitSize(std::vector<T>& v, size_t n) {
  if (v.capacity() < n) v.reserve(n + n / 2);
  v.resize(n);
}
}  // namespace

void NearestPointGrid::clear() {
  entries_.clear();
  band_start_.clear();
  cell_start_.clear();
  bands_ = cells_ = 0;
}

// Monotone in y (all a query needs: the bands of [y - gate, y + gate] hold every point there).
int NearestPointGrid::bandOf(double y) const {
  const double b = (y - y0_) * inv_band_;
  return !(b >= 0.0) ? 0 : b >= bands_ ? bands_ - 1 : static_cast<int>(b);
}

void NearestPointGrid::build(const std::vector<Eigen::Vector2d>& pts) {
  clear();
  double lo = 0.0, hi = 0.0, xlo = 0.0, xhi = 0.0;
  bool any = false;
  for (const Eigen::Vector2d& p : pts) {
    if (!std::isfinite(p.x()) || !std::isfinite(p.y())) continue;
    lo = any ? std::min(lo, p.y()) : p.y();
    hi = any ? std::max(hi, p.y()) : p.y();
    xlo = any ? std::min(xlo, p.x()) : p.x();
    xhi = any ? std::max(xhi, p.x()) : p.x();
    any = true;
  }
  if (!any) return;
  y0_ = lo;
  const double band = std::max(kBand, (hi - lo) / (kMaxBands - 1));
  inv_band_ = 1.0 / band;
  bands_ = static_cast<int>(std::floor((hi - lo) * inv_band_)) + 1;
  // Counting sort by band, then each band by (x, index).
  fitSize(band_start_, static_cast<size_t>(bands_) + 1);
  std::fill(band_start_.begin(), band_start_.end(), 0);
  fitSize(band_of_, pts.size());
  for (size_t i = 0; i < pts.size(); ++i) {
    const bool finite = std::isfinite(pts[i].x()) && std::isfinite(pts[i].y());
    band_of_[i] = finite ? bandOf(pts[i].y()) : -1;
    if (finite) ++band_start_[static_cast<size_t>(band_of_[i]) + 1];
  }
  for (int b = 0; b < bands_; ++b) band_start_[b + 1] += band_start_[b];
  fitSize(entries_, static_cast<size_t>(band_start_[bands_]));
  for (size_t i = 0; i < pts.size(); ++i) {
    if (band_of_[i] < 0) continue;
    // band_start_[b] walks forward while filling; restored below.
    entries_[static_cast<size_t>(band_start_[band_of_[i]]++)] = {pts[i].x(), pts[i].y(),
                                                                  static_cast<int>(i)};
  }
  for (int b = bands_; b > 0; --b) band_start_[b] = band_start_[b - 1];
  band_start_[0] = 0;
  for (int b = 0; b < bands_; ++b)
    std::sort(entries_.begin() + band_start_[b], entries_.begin() + band_start_[b + 1],
              [](const Entry& a, const Entry& c) {
                return a.x < c.x || (a.x == c.x && a.index < c.index);
              });
  // The x-cell directory: per band, where each cell's entries start.
  x0_ = xlo;
  const double max_cells = std::max(1.0, static_cast<double>(kMaxDirectory / bands_));
  const double cell = std::max(kCell, (xhi - xlo) / std::max(1.0, max_cells - 1.0));
  inv_cell_ = 1.0 / cell;
  cells_ = std::min(static_cast<int>(std::floor((xhi - xlo) * inv_cell_)) + 1,
                    static_cast<int>(max_cells));
  fitSize(cell_start_, static_cast<size_t>(bands_) * static_cast<size_t>(cells_));
  for (int b = 0; b < bands_; ++b) {
    int e = band_start_[b];
    const int end = band_start_[b + 1];
    int* row = cell_start_.data() + static_cast<size_t>(b) * static_cast<size_t>(cells_);
    for (int c = 0; c < cells_; ++c) {
      while (e < end && cellOf(entries_[static_cast<size_t>(e)].x) < c) ++e;
      row[c] = e;
    }
  }
}

int NearestPointGrid::cellOf(double x) const {
  const double c = (x - x0_) * inv_cell_;
  return !(c >= 0.0) ? 0 : c >= cells_ ? cells_ - 1 : static_cast<int>(c);
}

// From the directory's start of x's cell, on while below x: the same entry a binary search
// over the band finds (entries before the start have a smaller cell, so a smaller x).
const NearestPointGrid::Entry* NearestPointGrid::firstAtOrAfter(int b, double x) const {
  const Entry* it = entries_.data() +
                    cell_start_[static_cast<size_t>(b) * static_cast<size_t>(cells_) +
                                static_cast<size_t>(cellOf(x))];
  const Entry* const last = entries_.data() + band_start_[b + 1];
  while (it != last && it->x < x) ++it;
  return it;
}

int NearestPointGrid::nearest(const Eigen::Vector2d& q, double gate) const {
  if (bands_ == 0 || !(gate > 0.0) || !std::isfinite(q.x()) || !std::isfinite(q.y())) return -1;
  double best = gate * gate, best_x = 0.0;
  int best_j = -1;
  const int b_hi = bandOf(q.y() + gate);
  for (int b = bandOf(q.y() - gate); b <= b_hi; ++b) {
    const Entry* it = firstAtOrAfter(b, q.x() - gate);
    const Entry* const last = entries_.data() + band_start_[b + 1];
    for (; it != last && it->x <= q.x() + gate; ++it) {
      const double dx = it->x - q.x(), dy = it->y - q.y(), d2 = dx * dx + dy * dy;
      // Ties (equal squared distance) to the smaller (x, index), the x-strip's order.
      if (d2 < best || (best_j >= 0 && d2 == best &&
                        (it->x < best_x || (it->x == best_x && it->index < best_j)))) {
        best = d2;
        best_x = it->x;
        best_j = it->index;
      }
    }
  }
  return best_j;
}

// The same visit as nearest(q, radius), with the gate's answer kept apart: a point is a
// candidate for it only where nearest(q, gate) would visit it (its bands and x range), so the
// answer is that search's even at the edges of its region.
int NearestPointGrid::nearest(const Eigen::Vector2d& q, double gate, double radius, int& wide,
                              double& second2) const {
  wide = -1;
  second2 = radius * radius;
  if (bands_ == 0 || !(gate > 0.0) || !(radius >= gate) || !std::isfinite(q.x()) ||
      !std::isfinite(q.y())) {
    second2 = -1.0;  // no search: no bound
    return nearest(q, gate);
  }
  double best = gate * gate, best_x = 0.0, wbest = radius * radius, wbest_x = 0.0;
  int best_j = -1;
  const double gx_lo = q.x() - gate, gx_hi = q.x() + gate;
  const int g_lo = bandOf(q.y() - gate), g_hi = bandOf(q.y() + gate);
  const int b_hi = bandOf(q.y() + radius);
  for (int b = bandOf(q.y() - radius); b <= b_hi; ++b) {
    const bool gate_band = b >= g_lo && b <= g_hi;
    const Entry* it = firstAtOrAfter(b, q.x() - radius);
    const Entry* const last = entries_.data() + band_start_[b + 1];
    for (; it != last && it->x <= q.x() + radius; ++it) {
      const double dx = it->x - q.x(), dy = it->y - q.y(), d2 = dx * dx + dy * dy;
      if (gate_band && it->x >= gx_lo && it->x <= gx_hi &&
          (d2 < best || (best_j >= 0 && d2 == best &&
                         (it->x < best_x || (it->x == best_x && it->index < best_j))))) {
        best = d2;
        best_x = it->x;
        best_j = it->index;
      }
      if (d2 < wbest || (wide >= 0 && d2 == wbest &&
                         (it->x < wbest_x || (it->x == wbest_x && it->index < wide)))) {
        if (wide >= 0) second2 = wbest;  // the one it displaces is now second
        wbest = d2;
        wbest_x = it->x;
        wide = it->index;
      } else if (d2 < second2) {
        second2 = d2;
      }
    }
  }
  return best_j;
}

}  // namespace spinradar
