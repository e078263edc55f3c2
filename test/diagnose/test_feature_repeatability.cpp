// Front-end strength against the simulator's truth (issue 19, tenth round): true matches are
// told by the truth (a wrong truth finds none), and the calibrated clutter field of the Oxford
// sensor model is what leaves few true descriptor matches between scans a few apart.
#include <gtest/gtest.h>

#include <cstdio>
#include <stdexcept>

#include "spinradar/diagnose/feature_repeatability.hpp"
#include "spinradar/sim/scenes.hpp"
#include "spinradar/sim/simulator.hpp"

using namespace spinradar;

namespace {

diagnose::Repeatability measure(const sim::SensorConfig& sensor, double truth_scale = 1.0, int scans = 8) {
  sim::Scene sc = sim::builtinScene("city", 1);
  const sim::Simulator simulator(sc.world, sc.trajectory, sensor, {}, 1);
  std::vector<sim::Trajectory::Sample> samples = sc.trajectory.samples();
  for (auto& s : samples) s.pose.x *= truth_scale, s.pose.y *= truth_scale;
  PipelineConfig cfg;
  diagnose::RepeatabilityOptions o;
  o.max_gap = 3;
  diagnose::RepeatabilityMeter meter(cfg, sim::Trajectory(samples), o);
  for (int k = 40; k < 40 + scans; ++k) {
    PolarScan scan = simulator.renderScan(k);
    meter.add(scan);
  }
  return meter.result();
}

}  // namespace

TEST(FeatureRepeatability, TrueMatchesAreWhatTheTruthConfirms) {
  const diagnose::Repeatability r = measure(sim::SensorConfig{});
  ASSERT_EQ(r.gaps.size(), 3u);
  const diagnose::GapFigures& g1 = r.gaps[0];
  std::printf("gap 1: %.0f repeatable, %.0f matches, %.0f true; gap 3: %.0f / %.0f true\n", g1.repeatable, g1.matches,
              g1.true_matches, r.gaps[2].repeatable, r.gaps[2].true_matches);
  EXPECT_EQ(g1.pairs, 7);
  EXPECT_GT(g1.true_matches, 50.0);
  EXPECT_LE(g1.true_matches, g1.matches);
  // Nearly every match of a clean sensor one scan apart is a true one.
  EXPECT_GT(g1.true_matches, 0.85 * g1.matches);
  // Fewer found again the farther apart.
  EXPECT_GT(r.gaps[0].repeatable, r.gaps[2].repeatable);
  EXPECT_GT(r.gaps[0].true_matches, r.gaps[2].true_matches);
  // A truth that puts the poses 1.5x as far apart confirms none of the same matches.
  const diagnose::Repeatability wrong = measure(sim::SensorConfig{}, 1.5);
  EXPECT_DOUBLE_EQ(wrong.gaps[0].matches, g1.matches);
  std::printf("scaled truth: %.1f true of %.0f matches\n", wrong.gaps[0].true_matches, wrong.gaps[0].matches);
  EXPECT_LT(wrong.gaps[0].true_matches, 0.1 * g1.true_matches);
}

TEST(FeatureRepeatability, OxfordClutterFieldLeavesFewTrueMatches) {
  // The calibrated Oxford model (a static clutter field up to 4 scatterers per m^2 beyond
  // 35 m) against the same sensor without it: the clutter, not the 0.96 deg beam or the 4.38 cm
  // bins, takes the true matches of scans 3 apart (recordings: 24 against 100 per pair).
  sim::SensorConfig oxford = sim::SensorConfig::loadNamed("oxford");
  sim::SensorConfig clean = oxford;
  clean.clutter_density = 0.0;
  const diagnose::Repeatability with = measure(oxford), without = measure(clean);
  std::printf("gap 3 true matches: %.1f with the clutter, %.1f without; weak %.0f %% / %.0f %%\n",
              with.gaps[2].true_matches, without.gaps[2].true_matches, 100 * with.gaps[2].weak_share,
              100 * without.gaps[2].weak_share);
  EXPECT_LT(with.gaps[2].true_matches, 0.5 * without.gaps[2].true_matches);
  EXPECT_GT(with.gaps[2].weak_share, without.gaps[2].weak_share);
  // Beyond 35 m hardly anything is found again under the clutter.
  const size_t far = with.band_keypoints.size() - 2;
  EXPECT_LT(with.gaps[2].band_true[far] + with.gaps[2].band_true[far + 1],
            0.25 * (without.gaps[2].band_true[far] + without.gaps[2].band_true[far + 1]));
}

TEST(FeatureRepeatability, RejectsBadOptions) {
  diagnose::RepeatabilityOptions o;
  o.max_gap = 0;
  EXPECT_THROW(o.validate(), std::invalid_argument);
  o = {};
  o.band_edges = {10.0, 5.0};
  EXPECT_THROW(o.validate(), std::invalid_argument);
}

// The far-structure realism figure (docs/city_scene_far_structure.md), on the real Oxford
// sample's true matches one scan apart per band (< 2.5, 2.5-10, 10-25, 25-50, 50-100, > 100 m):
// 42.5 of 63.5 lie beyond 25 m, 18.5 beyond 50 m.
TEST(FeatureRepeatability, TrueShareBeyondABandEdge) {
  diagnose::GapFigures g;
  g.band_true = {0.0, 2.0, 19.0, 24.0, 18.5, 0.0};
  EXPECT_DOUBLE_EQ(diagnose::trueShareBeyond(g, 0), 1.0);
  EXPECT_DOUBLE_EQ(diagnose::trueShareBeyond(g, 2), 42.5 / 63.5);
  EXPECT_DOUBLE_EQ(diagnose::trueShareBeyond(g, 3), 18.5 / 63.5);
  EXPECT_DOUBLE_EQ(diagnose::trueShareBeyond(g, 4), 0.0);
  EXPECT_THROW(diagnose::trueShareBeyond(g, 5), std::out_of_range);
  g.band_true.assign(6, 0.0);
  EXPECT_DOUBLE_EQ(diagnose::trueShareBeyond(g, 2), 0.0);  // no true match: no share
}
