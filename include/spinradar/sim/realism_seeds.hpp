#pragma once
// Realism figures over several noise seeds of the same render. A 4-scan render's worst per-band
// gap moves by up to 15 points with the noise seed alone (docs/diagnose_render_seeds.md), so a
// figure of one render is one noise draw: these average every figure over N seeds and keep its
// range. The one definition of `--render-seeds` (spinradar realism, spinradar diagnose).
#include <cstdint>
#include <functional>
#include <vector>

#include "spinradar/sim/realism.hpp"

namespace spinradar::sim {

/// The noise seeds of an N-seed render: first, first + stride, ..., first + (n - 1) stride.
/// n = 1 is the single render of `first` (today's figure). Throws std::invalid_argument when
/// n < 1 or stride is 0.
std::vector<uint64_t> renderSeeds(uint64_t first, int n, uint64_t stride = 1);

/// Mean and range of one figure over the seeds.
struct SeedSpread {
  double mean = 0, lo = 0, hi = 0;
  int n = 0;
};
/// Throws std::invalid_argument on an empty list or a non-finite value.
SeedSpread spreadOf(const std::vector<double>& values);

/// Realism figures of several renders that differ only in their noise seed.
struct RealismOverSeeds {
  RealismStats mean;  ///< every figure averaged over the seeds (name and scans of the first)
  RealismStats lo, hi;  ///< every figure's smallest and largest value over the seeds
  std::vector<RealismStats> per_seed;
};
/// Throws std::invalid_argument on an empty list.
RealismOverSeeds realismOverSeeds(std::vector<RealismStats> per_seed);

/// The scans of one render with noise seed `seed` (the caller's scene, sensor and scan choice).
using SeedRender = std::function<std::vector<PolarScan>(uint64_t seed)>;
/// `render` for every seed of `seeds`, each measured with computeRealism under `options`.
RealismOverSeeds realismOverSeeds(const SeedRender& render, const std::vector<uint64_t>& seeds,
                                  const std::string& name, const RealismOptions& options = {});

/// The worst of `gaps(sim, real)` for each seed's figures, as a spread over the seeds: the
/// worst-gap figure the 15 % is checked against, averaged over noise draws.
SeedSpread worstGapOverSeeds(
    const RealismOverSeeds& sim, const RealismStats& real,
    const std::function<std::vector<double>(const RealismStats&, const RealismStats&)>& gaps);

/// A Markdown realism table (formatRealismTable) whose simulated columns are means over seeds:
/// a figure that differs between seeds is written "mean [lo-hi]". `spreads[i]` belongs to
/// `cols[i]`; null for a column of one render (real data).
std::string formatRealismTable(const std::vector<RealismStats>& cols,
                               const std::vector<const RealismOverSeeds*>& spreads);

}  // namespace spinradar::sim
