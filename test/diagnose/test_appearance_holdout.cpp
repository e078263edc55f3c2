// Why a held-out appearance figure is off (issue 20, detail::holdoutSceneCheck): the fitted
// sensor is rendered with the held-out part's own scene. Known truth, the sensor being the one
// the recording was rendered with:
// - fit part and held-out part of two stretches of one road, one sensor: the halves differ by
//   15-28 %, the sensor carries over within 10 %: verdict "scene";
// - the held-out part's receiver noise 6 dB higher: verdict "model" (carry-over over 10 %);
// - null (one stretch, one sensor): everything carries over, nothing over 15 %.
// The recorded sensor is the one rendered with, not a fit: where its own-scene render is over
// 15 % off on the fit part too (the own scene's bias a fit takes up), nothing is asserted.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>

#include "../../src/diagnose/appearance_detail.hpp"
#include "diagnose/appearance_fixtures.hpp"
#include "spinradar/sim/realism.hpp"
#include "spinradar/sim/scenes.hpp"
#include "spinradar/sim/simulator.hpp"

namespace spinradar::diagnose {
namespace {

std::vector<PolarScan> render(const std::string& scene, const sim::SensorConfig& s,
                              const std::vector<int>& scans, uint64_t seed) {
  sim::Scene sc = sim::builtinScene(scene);
  const sim::Simulator sim(std::move(sc.world), std::move(sc.trajectory), s, {}, seed);
  std::vector<PolarScan> out;
  for (const int k : scans) out.push_back(sim.renderScan(k));
  return out;
}

void print(const char* what, const AppearanceReport& rep) {
  std::cout << what << ": worst held-out gap " << rep.worst_holdout_after
            << ", with the held-out part's own scene " << rep.worst_holdout_scene
            << ", fit part's own scene " << rep.worst_fit_scene << "\n";
  for (const auto& f : rep.held_out_figures)
    std::cout << "  " << f.name << ": " << f.real_fit << " / " << f.real_holdout << " / "
              << f.sim << " / " << f.sim_holdout_scene << " carry " << f.carry << ": " << f.verdict
              << "\n";
}

// Another stretch of the same road: the halves differ by 15-28 % (25-50 m mean and q90, 50-100 m
// Cen2018), the sensor is the same: every figure the fit part matches carries over.
TEST(AppearanceHoldout, OtherStretchHeldOutIsTheScene) {
  const sim::SensorConfig s = testing::hundredMetreSensor();
  const auto fit = render("out_and_back", s, {300, 600}, 3);
  const auto holdout = render("out_and_back", s, {450, 750}, 4);
  const AppearanceReport rep = testing::holdoutCheck(fit, holdout, s);
  print("other stretch", rep);
  int scene = 0, halves = 0;
  for (const auto& f : rep.held_out_figures) {
    if (f.gap_fit > 0.15) continue;  // the own scene's bias, which a fit takes up
    EXPECT_LE(std::abs(f.carry), 0.10) << f.name;
    halves += f.halves > 0.15;
    if (f.gap_holdout > 0.15) {
      EXPECT_EQ(f.verdict.rfind("scene", 0), 0u) << f.name << ": " << f.verdict;
      ++scene;
    }
  }
  EXPECT_GE(halves, 3);  // 25-50 m mean and q90, 50-100 m Cen2018
  EXPECT_GE(scene, 1);   // 25-50 m q90 (17 %)
}

// The held-out part's receiver noise 6 dB up, same road: its own scene (returns 10 dB over the
// floor) cannot take that up, the carry-over shows it.
TEST(AppearanceHoldout, NoisierHeldOutReceiverIsTheModel) {
  const sim::SensorConfig s = testing::hundredMetreSensor();
  sim::SensorConfig noisy = s;
  noisy.noise_floor_db += 6.0;
  const auto fit = render("out_and_back", s, {300, 600}, 3);
  const auto holdout = render("out_and_back", noisy, {310, 610}, 4);
  const AppearanceReport rep = testing::holdoutCheck(fit, holdout, s);
  print("noisier held-out receiver", rep);
  int model = 0;
  for (const auto& f : rep.held_out_figures)
    if (f.gap_fit <= 0.15 && f.gap_holdout > 0.15) {
      EXPECT_EQ(f.verdict.rfind("model", 0), 0u) << f.name << ": " << f.verdict;
      EXPECT_GT(std::abs(f.carry), 0.10) << f.name;
      ++model;
    }
  EXPECT_GE(model, 3);
  // A receiver change moves the background of every sector alike.
  for (int k = 1; k < kBands; ++k) {
    const SectorShift sh = rep.floor_shifts[size_t(k)];
    std::cout << "  band " << k << " background shift " << sh.lo << " .. " << sh.hi << " (" << sh.common << ")\n";
    EXPECT_GT(sh.common, 2.0) << k;
    EXPECT_GT(sh.lo, 1.0) << k;
  }
}

TEST(AppearanceHoldout, NullCarriesOver) {
  const sim::SensorConfig s = testing::hundredMetreSensor();
  const auto fit = render("out_and_back", s, {300, 600}, 3);
  const auto holdout = render("out_and_back", s, {310, 610}, 4);
  const AppearanceReport rep = testing::holdoutCheck(fit, holdout, s);
  print("null", rep);
  for (const auto& f : rep.held_out_figures)
    if (f.gap_fit <= 0.15) {
      EXPECT_LE(std::abs(f.carry), 0.10) << f.name;
      EXPECT_LE(f.gap_holdout, 0.15) << f.name;
    }
  for (int k = 1; k < kBands; ++k) EXPECT_LT(std::abs(rep.floor_shifts[size_t(k)].common), 1.0) << k;
}

// One scan split by quarters: the parts share no azimuth sector, no shift is measured.
TEST(AppearanceHoldout, QuarterSplitHasNoSectorShift) {
  const sim::SensorConfig s = testing::hundredMetreSensor();
  std::vector<PolarScan> fit, holdout;
  splitHoldout(render("out_and_back", s, {300}, 3), fit, holdout);
  EXPECT_TRUE(std::isnan(sectorFloorShift(fit, holdout, 2).common));
}

TEST(AppearanceHoldout, Verdicts) {
  HeldOutFigure f;
  f.gap_fit = 0.2;
  EXPECT_EQ(classifyHeldOutFigure(f).rfind("model", 0), 0u);
  f.gap_fit = 0.05, f.halves = 0.18, f.gap_holdout = 0.2;
  EXPECT_EQ(classifyHeldOutFigure(f), "the real halves' own difference");
  f.gap_holdout_scene = 0.08, f.gap_fit_scene = 0.05, f.carry = 0.04, f.gap_net = 0.06;
  EXPECT_EQ(classifyHeldOutFigure(f).rfind("scene", 0), 0u);
  f.carry = -0.12;
  EXPECT_EQ(classifyHeldOutFigure(f).rfind("model", 0), 0u);
}

}  // namespace
}  // namespace spinradar::diagnose
