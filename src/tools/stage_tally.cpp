#include "stage_tally.hpp"

#include <algorithm>
#include <cstdio>

#include "sorted_quantile.hpp"

namespace spinradar::cli {

namespace {

struct Tail {
  double p95 = 0.0, max = 0.0;
};

Tail tailOf(std::vector<double> v) {
  Tail t;
  if (v.empty()) return t;
  std::sort(v.begin(), v.end());
  t.p95 = quantileOfSorted(v, 0.95);
  t.max = v.back();
  return t;
}

}  // namespace

StageTally::StageTally(size_t scans) {
  estimate_ms_.reserve(scans);
  total_ms_.reserve(scans);
}

void StageTally::add(const StageTimes& t) {
  totals_ += t;
  estimate_ms_.push_back(t.estimate_ms);
  total_ms_.push_back(t.total());
}

void StageTally::print(double load_ms, double wait_ms, bool prefetch, size_t scans,
                       double wall_s) const {
  const double n = scans > 0 ? static_cast<double>(scans) : 1.0;
  std::fprintf(stderr, "stage timing over %zu scans (total s, mean ms/scan; p95 / max ms of one scan):\n",
               scans);
  auto row = [&](const char* name, double ms, const std::vector<double>* per_scan) {
    std::fprintf(stderr, "  %-18s %9.3f s  %8.2f ms", name, ms / 1000.0, ms / n);
    if (per_scan) {
      const Tail t = tailOf(*per_scan);
      std::fprintf(stderr, "  (p95 %.2f, max %.2f)", t.p95, t.max);
    }
    std::fprintf(stderr, "\n");
  };
  row(prefetch ? "load (background)" : "load", load_ms, nullptr);
  if (prefetch) row("waiting for loads", wait_ms, nullptr);
  row(prefetch ? "detect (bg)" : "detect", totals_.detect_ms, nullptr);
  row(prefetch ? "cartesian (bg)" : "cartesian", totals_.cartesian_ms, nullptr);
  row(prefetch ? "describe (bg)" : "describe", totals_.describe_ms, nullptr);
  row("match", totals_.match_ms, nullptr);
  row("estimate", totals_.estimate_ms, &estimate_ms_);
  row("pipeline total", totals_.total(), &total_ms_);
  std::fprintf(stderr, "  %-18s %9.3f s  %8.2f ms  (%.1f scans/s)\n", "wall clock", wall_s,
               1000.0 * wall_s / n, scans / std::max(wall_s, 1e-9));
}

}  // namespace spinradar::cli
