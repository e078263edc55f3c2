// Realism figures over several noise seeds (sim/realism_seeds.hpp, CLI --render-seeds). Known
// truth: one seed is today's single render bit for bit; the mean over N seeds is the mean of the
// N single-seed figures and its range their smallest and largest; a bad N is an error.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "spinradar/sim/realism_seeds.hpp"
#include "spinradar/sim/scenes.hpp"
#include "spinradar/sim/simulator.hpp"

namespace spinradar::sim {
namespace {

// Two scans of the built-in city, 100 m of range: every band, a few seconds per render.
std::vector<PolarScan> cityRender(uint64_t seed) {
  Scene sc = builtinScene("city");
  SensorConfig s;
  s.bins = 2300;
  s.clutter_density = 0.1;
  Simulator sim(std::move(sc.world), std::move(sc.trajectory), s, PhysicsConfig{}, seed);
  const int total = sim.scanCount();
  return {sim.renderScan(total / 4), sim.renderScan(3 * total / 4)};
}

// The per-band figures the realism gap is taken on, and the floor.
std::vector<double> bandFigures(const RealismStats& r) {
  std::vector<double> v;
  for (int k = 0; k < 4; ++k)
    for (double x : {r.band_mean[k], r.band_q90[k], r.band_cacfar[k], r.band_cen[k], r.band_floor[k]})
      v.push_back(x);
  v.push_back(r.mean);
  v.push_back(r.detections_cen);
  return v;
}

TEST(RealismSeeds, SeedList) {
  EXPECT_EQ(renderSeeds(12, 1), std::vector<uint64_t>({12}));
  EXPECT_EQ(renderSeeds(12, 3), std::vector<uint64_t>({12, 13, 14}));
  EXPECT_EQ(renderSeeds(11, 3, 1000), std::vector<uint64_t>({11, 1011, 2011}));
  EXPECT_THROW(renderSeeds(12, 0), std::invalid_argument);
  EXPECT_THROW(renderSeeds(12, -2), std::invalid_argument);
  EXPECT_THROW(renderSeeds(12, 2, 0), std::invalid_argument);
  EXPECT_THROW(realismOverSeeds(std::vector<RealismStats>{}), std::invalid_argument);
  EXPECT_THROW(spreadOf({1.0, NAN}), std::invalid_argument);
}

TEST(RealismSeeds, OneSeedIsTheSingleRender) {
  const RealismStats single = computeRealism(cityRender(12), "sim");
  const RealismOverSeeds over = realismOverSeeds(cityRender, renderSeeds(12, 1), "sim");
  const auto a = bandFigures(single), m = bandFigures(over.mean), lo = bandFigures(over.lo),
             hi = bandFigures(over.hi);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(m[i], a[i]) << i;  // bit-identical: today's figure
    EXPECT_EQ(lo[i], a[i]) << i;
    EXPECT_EQ(hi[i], a[i]) << i;
  }
  // The table of one seed is today's table.
  EXPECT_EQ(formatRealismTable({over.mean}, {&over}), formatRealismTable({single}));
}

TEST(RealismSeeds, MeanOverSeedsIsTheMeanOfSingleSeedFigures) {
  const std::vector<uint64_t> seeds = renderSeeds(12, 3);
  std::vector<std::vector<double>> single;
  for (uint64_t s : seeds) single.push_back(bandFigures(computeRealism(cityRender(s), "sim")));
  const RealismOverSeeds over = realismOverSeeds(cityRender, seeds, "sim");
  ASSERT_EQ(over.per_seed.size(), 3u);
  const auto m = bandFigures(over.mean), lo = bandFigures(over.lo), hi = bandFigures(over.hi);
  int differ = 0;
  for (size_t i = 0; i < m.size(); ++i) {
    const double mean = (single[0][i] + single[1][i] + single[2][i]) / 3;
    EXPECT_NEAR(m[i], mean, 1e-9 * std::max(1.0, std::abs(mean))) << i;
    EXPECT_EQ(lo[i], std::min({single[0][i], single[1][i], single[2][i]})) << i;
    EXPECT_EQ(hi[i], std::max({single[0][i], single[1][i], single[2][i]})) << i;
    differ += lo[i] != hi[i];
  }
  // The seeds are different noise draws (otherwise the mean would prove nothing).
  EXPECT_GT(differ, 5);
  // The worst gap over seeds: the mean of each seed's worst gap, its range theirs.
  const RealismStats real = over.per_seed[0];
  auto gaps = [](const RealismStats& s, const RealismStats& r) { return bandGaps(s, r); };
  std::vector<double> worst;
  for (const auto& s : over.per_seed) {
    const auto g = bandGaps(s, real);
    worst.push_back(*std::max_element(g.begin(), g.end()));
  }
  const SeedSpread w = worstGapOverSeeds(over, real, gaps);
  EXPECT_EQ(w.n, 3);
  EXPECT_NEAR(w.mean, (worst[0] + worst[1] + worst[2]) / 3, 1e-12);
  EXPECT_EQ(w.lo, 0.0);  // seed 12 against itself
  EXPECT_EQ(w.hi, std::max({worst[0], worst[1], worst[2]}));
  EXPECT_GT(w.hi, 0.0);
  // A figure that differs between seeds is written with its range.
  const std::string table = formatRealismTable({over.mean}, {&over});
  EXPECT_NE(table.find(" ["), std::string::npos);
  EXPECT_THROW(formatRealismTable({over.mean}, {}), std::invalid_argument);
}

}  // namespace
}  // namespace spinradar::sim
