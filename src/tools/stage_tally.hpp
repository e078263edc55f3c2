// Per-stage timing of a run of `spinradar odometry`: totals and means per scan, and for the
// estimate stage and the whole chain also the 95th percentile and the worst scan. A mean hides
// the scans that make a live pipeline late (keyframe switches register against the whole
// keyframe window: issue 19, thirteenth round), so the tail is printed beside it.
#pragma once

#include <cstddef>
#include <vector>

#include "spinradar/core/stage_times.hpp"

namespace spinradar::cli {

class StageTally {
 public:
  explicit StageTally(size_t scans);
  void add(const StageTimes& t);  ///< one processed scan (no allocation within `scans`)
  const StageTimes& totals() const { return totals_; }
  /// Writes the table to stderr; scans: the folder's (means are over it, as before).
  void print(double load_ms, double wait_ms, bool prefetch, size_t scans, double wall_s) const;

 private:
  StageTimes totals_;
  std::vector<double> estimate_ms_, total_ms_;  ///< per processed scan
};

}  // namespace spinradar::cli
