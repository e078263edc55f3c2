// The f-quantile of sorted values, nearest rank (the index f (n - 1) rounded): one definition
// for the CLI's timing figures (`bench`'s p10 / p90, `odometry`'s p95 per stage).
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace spinradar::cli {

inline double quantileOfSorted(const std::vector<double>& sorted, double f) {
  if (sorted.empty()) return 0.0;
  const size_t n = sorted.size();
  return sorted[std::min(n - 1, static_cast<size_t>(f * static_cast<double>(n - 1) + 0.5))];
}

}  // namespace spinradar::cli
