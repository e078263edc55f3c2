#pragma once
// `--render-seeds N`, the one definition shared by `realism` and `diagnose`: every realism
// figure of a simulated render is the mean over N noise seeds (first, first + 1, ...), written
// with its range (sim/realism_seeds.hpp; docs/diagnose_render_seeds.md).
#include <CLI/CLI.hpp>

#include "cli_checks.hpp"

namespace spinradar::cli {

/// Largest N: the appearance fit's own seeds sit kFitSeedStride apart
/// (diagnose::kFitSeedStride), so N up to this never reaches them.
constexpr int kMaxRenderSeeds = 999;

inline CLI::Option* addRenderSeedsOption(CLI::App& app, int& n, const std::string& first_seed) {
  return app
      .add_option("--render-seeds", n,
                  "Noise seeds per simulated render (" + first_seed +
                      " and the next N-1): each realism figure is the mean over them, with its "
                      "range [lo-hi]; 1 = one render")
      ->check(inRange(1, kMaxRenderSeeds))
      ->capture_default_str();
}

}  // namespace spinradar::cli
