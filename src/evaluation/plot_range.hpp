// Private to the evaluation part: the value range that plot.cpp (histograms) and
// plot_render.cpp (axes) both widen to something drawable.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

namespace spinradar::plot::detail {

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  bool valid() const { return lo <= hi; }
};

/// Widens a range that is empty or a single value so that the axes stay drawable.
inline void ensureSpan(Range& r) {
  if (!r.valid()) {
    r.lo = 0;
    r.hi = 1;
  } else if (r.hi - r.lo < 1e-12 * std::max(1.0, std::fabs(r.lo))) {
    const double d = std::max(std::fabs(r.lo) * 0.1, 0.5);
    r.lo -= d;
    r.hi += d;
  }
}

}  // namespace spinradar::plot::detail
