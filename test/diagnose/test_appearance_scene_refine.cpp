// The own reference scene's tenth-round options (docs/diagnose_scene.md, "tenth round"): the
// scatterers' strengths refined jointly along azimuth (scene_refine_passes) and a margin per
// range band (scene_margin_bands_db). Known truth from simulator renders: an extended return
// re-simulated from the refined scene keeps the recorded azimuth profile where the row-by-row
// rebuild renders it wider; weak far returns under the 10 dB margin come into the scene with a
// lower far-band margin while the near bands keep theirs; a lone point target (null) keeps its
// strength; a return between range bins is placed there with scene_range_subbin; the held-out
// rows stay unread.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <iostream>

#include "diagnose/appearance_fixtures.hpp"
#include "spinradar/diagnose/appearance.hpp"
#include "spinradar/sim/simulator.hpp"

namespace spinradar::diagnose {
namespace {

PolarScan render(const sim::World& w, const sim::SensorConfig& s, uint64_t seed) {
  const sim::Trajectory standing({{0.0, {}}, {2.0, {}}});
  return sim::Simulator(w, standing, s, {}, seed).renderScan(0);
}

// Targets at range r on rows row0.. (one per `step` rows), rcs each.
sim::World arc(const sim::SensorConfig& s, double r, double row0, int count, double step,
               double rcs) {
  sim::World w;
  for (int i = 0; i < count; ++i) {
    const double phi = (row0 + i * step) * 2 * M_PI / s.azimuths;
    w.targets.push_back({r * std::cos(phi), -r * std::sin(phi), rcs});
  }
  return w;
}

// Mean power (dB, counts decoded at the model's counts per dB) over rows [a, b) at bins b0 +-3.
double bandDb(const PolarScan& sc, int a, int b, int bin, const sim::SensorConfig& s) {
  double sum = 0;
  int n = 0;
  for (int r = a; r < b; ++r)
    for (int bb = bin - 3; bb <= bin + 3; ++bb, ++n)
      sum += std::pow(10.0, sc.row(r)[bb] / s.power_scale / 10.0);
  return 10 * std::log10(sum / n);
}

// An extended return: 13 targets half a row apart (a wall 6 rows wide at 40 m). The row-by-row
// scene renders it 1.4 dB brighter than recorded; the refined one keeps the core within 1 dB
// and its flanks (2-4 rows off its ends) no brighter.
TEST(AppearanceSceneRefine, ExtendedReturnKeepsItsAzimuthProfile) {
  const sim::SensorConfig s = testing::hundredMetreSensor();
  const double r = 40.0;
  const PolarScan rec = render(arc(s, r, 100.0, 13, 0.5, 5.0), s, 7);
  const int bin = int(std::lround(rec.binOfRange(r)));
  double flank[2] = {0, 0}, core[2] = {0, 0};
  const double flank_rec = 0.5 * (bandDb(rec, 96, 99, bin, s) + bandDb(rec, 108, 111, bin, s));
  const double core_rec = bandDb(rec, 100, 107, bin, s);
  for (const int passes : {0, 30}) {
    AppearanceOptions opt;
    opt.scene_refine_passes = passes;
    const PolarScan again = render(recordingWorld(rec, s, opt), s, 9);
    const int k = passes > 0;
    flank[k] = 0.5 * (bandDb(again, 96, 99, bin, s) + bandDb(again, 108, 111, bin, s)) - flank_rec;
    core[k] = bandDb(again, 100, 107, bin, s) - core_rec;
    if (std::getenv("SPINRADAR_TEST_VERBOSE"))
      std::cerr << "passes " << passes << ": flank " << flank[k] << " dB, core " << core[k]
                << " dB over the recording (flanks " << bandDb(again, 96, 99, bin, s) -
                       bandDb(rec, 96, 99, bin, s)
                << " / " << bandDb(again, 108, 111, bin, s) - bandDb(rec, 108, 111, bin, s) << ")\n";
  }
  // Measured: core +1.40 -> +0.39 dB, flanks +1.99 -> +1.94 dB (the flanks stay ~2 dB over).
  EXPECT_LT(std::abs(core[1]), 1.0);
  EXPECT_GT(core[0], core[1] + 0.5);  // the row-by-row rebuild renders the wall brighter
  EXPECT_LT(flank[1], flank[0] + 0.1);
}

// Null: a lone point target keeps its strength and stays the only strong scatterer.
TEST(AppearanceSceneRefine, LonePointTargetUnchanged) {
  const sim::SensorConfig s = testing::hundredMetreSensor();
  const PolarScan rec = render(arc(s, 30.0, 200.3, 1, 1.0, 10.0), s, 7);
  AppearanceOptions opt;
  opt.scene_refine_passes = 30;
  const sim::World w = recordingWorld(rec, s, opt);
  int strong = 0;
  double best = -1e9;
  for (const auto& t : w.targets) strong += t.rcs > -10, best = std::max(best, t.rcs);
  EXPECT_EQ(strong, 1);
  EXPECT_NEAR(best, 10.0, 3.0);
}

// Weak returns at 70 m, about 7 dB over their bins' upper quartile (a noise floor raised so they
// sit there): with the 10 dB margin few are in the scene, with a 5 dB far-band margin nearly all
// (a scatterer within 0.5 m of the target); the near bands keep their margin (the same returns
// at 20 m stay out). The lower margin also takes speckle peaks in (exponential speckle passes the
// upper quartile + 5 dB in about 1 % of the cells): the price of the weak returns.
TEST(AppearanceSceneRefine, FarBandMarginTakesWeakReturns) {
  sim::SensorConfig s = testing::hundredMetreSensor();
  s.noise_floor_db = 30;
  sim::World w;
  for (const double r : {20.0, 70.0}) {
    const double phi = 150 * 2 * M_PI / s.azimuths;
    sim::World one;
    one.targets.push_back({r * std::cos(phi), -r * std::sin(phi), 0.0});
    const PolarScan probe = render(one, s, 3);
    const int b = int(std::lround(probe.binOfRange(r)));
    const double got = probe.row(150)[b] / s.power_scale;  // dB of a 0 dBsm target, noise included
    for (int i = 0; i < 8; ++i) {
      const double p = (30 + 40 * i) * 2 * M_PI / s.azimuths;
      w.targets.push_back({r * std::cos(p), -r * std::sin(p), s.noise_floor_db + 8.4 - got});
    }
  }
  auto hits = [&](const sim::World& scene, double r) {
    int k = 0;
    for (const auto& t : w.targets) {
      if (std::abs(std::hypot(t.x, t.y) - r) > 0.1) continue;
      for (const auto& u : scene.targets)
        if (std::hypot(u.x - t.x, u.y - t.y) < 0.5 + 0.01 * r) {
          ++k;
          break;
        }
    }
    return k;
  };
  const PolarScan rec = render(w, s, 5);
  AppearanceOptions opt;
  const sim::World w10 = recordingWorld(rec, s, opt);
  opt.scene_margin_bands_db = {10, 10, 10, 5};
  const sim::World w5 = recordingWorld(rec, s, opt);
  if (std::getenv("SPINRADAR_TEST_VERBOSE"))
    std::cerr << "targets found at 70 m: " << hits(w10, 70) << " -> " << hits(w5, 70)
              << "; at 20 m: " << hits(w10, 20) << " -> " << hits(w5, 20) << "; scatterers "
              << w10.targets.size() << " -> " << w5.targets.size() << "\n";
  EXPECT_LE(hits(w10, 70.0), 3);
  EXPECT_GE(hits(w5, 70.0), 6);
  EXPECT_EQ(hits(w5, 20.0), hits(w10, 20.0));
  opt.scene_margin_bands_db = {10, 10, 10};
  EXPECT_THROW(recordingWorld(rec, s, opt), std::invalid_argument);
  opt.scene_margin_bands_db = {10, 10, 10, -1};
  EXPECT_THROW(recordingWorld(rec, s, opt), std::invalid_argument);
}

// A target 0.4 bins past a bin's centre: by default its scatterer sits at the first bin of the
// recorded peak's flat top, over a bin short; with scene_range_subbin (the flat top's middle and
// a parabola) within 0.3 bins; the re-rendered peak count within 1.5 counts either way.
TEST(AppearanceSceneRefine, SubBinRangeRecovered) {
  const sim::SensorConfig s = testing::hundredMetreSensor();
  const PolarScan probe = render(sim::World{}, s, 3);
  const double r = probe.rangeOfBin(700.4), phi = 220 * 2 * M_PI / s.azimuths;
  sim::World truth;
  truth.targets.push_back({r * std::cos(phi), -r * std::sin(phi), 10.0});
  const PolarScan rec = render(truth, s, 7);
  for (const bool sub : {false, true}) {
    AppearanceOptions opt;
    opt.scene_range_subbin = sub;
    const sim::World w = recordingWorld(rec, s, opt);
    ASSERT_FALSE(w.targets.empty());
    const sim::Target* best = &w.targets.front();
    for (const auto& t : w.targets)
      if (t.rcs > best->rcs) best = &t;
    const double off = (std::hypot(best->x, best->y) - r) / s.range_resolution;
    const PolarScan again = render(w, s, 9);
    int pr = 0, pa = 0;
    for (int b = 690; b < 711; ++b)
      pr = std::max(pr, int(rec.row(220)[b])), pa = std::max(pa, int(again.row(220)[b]));
    if (std::getenv("SPINRADAR_TEST_VERBOSE"))
      std::cerr << "subbin " << sub << ": " << off << " bins off, peak " << pa << " against " << pr
                << ", rcs " << best->rcs << "\n";
    // Measured: default 1.4 bins short (the quantised peak's flat top spans 3 bins and ties go
    // to its first), sub-bin 0.23 bins short.
    if (sub) {
      EXPECT_LT(std::abs(off), 0.3);
      EXPECT_NEAR(best->rcs, 10.0, 1.5);
    } else {
      EXPECT_LT(off, -0.9);
    }
    EXPECT_NEAR(pa, pr, 1.5 * s.power_scale);
  }
}

TEST(AppearanceSceneRefine, HeldOutRowsAreNeverRead) {
  const sim::SensorConfig s = testing::hundredMetreSensor();
  const PolarScan scan = render(arc(s, 40.0, 20.0, 9, 0.5, 5.0), s, 7);
  std::vector<PolarScan> fit, holdout;
  splitHoldout({scan}, fit, holdout);
  ASSERT_EQ(fit.size(), 1u);
  PolarScan changed = fit[0];
  for (int r = 0; r < changed.azimuths; ++r)
    if (!changed.valid[r])
      for (int b = 100; b < changed.bins; b += 50) changed.row(r)[b] = 200;
  AppearanceOptions opt;
  opt.scene_refine_passes = 30;
  opt.scene_margin_bands_db = {10, 10, 8, 6};
  opt.scene_range_subbin = true;
  EXPECT_EQ(recordingWorld(fit[0], s, opt).toJson(), recordingWorld(changed, s, opt).toJson());
}

// Known truth end to end with the refined scene and a lower far margin: noise +3 dB on
// out_and_back comes back within 1 dB and alone; the null names nothing.
TEST(AppearanceSceneRefine, ConcealedNoiseRecoveredNullNamesNothing) {
  AppearanceOptions rec_opt = testing::catalogueOnlyOptions();
  rec_opt.scene = "out_and_back";
  for (const bool noise : {true, false}) {
    sim::SensorConfig truth = testing::hundredMetreSensor();
    if (noise) truth.noise_floor_db += 3;
    const auto rec = renderReference(truth, {}, rec_opt, 4242);
    AppearanceOptions opt = testing::catalogueOnlyOptions();
    opt.scene = "recording";
    opt.scene_refine_passes = 30;
    opt.scene_margin_bands_db = {10, 10, 8, 6};
    opt.scene_range_subbin = true;
    const AppearanceReport rep = diagnoseAppearance(rec, testing::hundredMetreSensor(), {}, opt);
    const std::string named = testing::namedFindings(rep);
    if (std::getenv("SPINRADAR_TEST_VERBOSE"))
      std::cerr << "noise " << noise << ": named '" << named << "' fitted "
                << rep.fitted.noise_floor_db << "\n";
    if (noise) {
      EXPECT_NEAR(rep.fitted.noise_floor_db, truth.noise_floor_db, 1.0) << named;
      EXPECT_EQ(named.find("noise_floor_db"), 0u) << named;
      EXPECT_EQ(named.find(' ', 0), named.size() - 1) << "more than one named: " << named;
    } else {
      EXPECT_TRUE(named.empty()) << named;
    }
  }
}

}  // namespace
}  // namespace spinradar::diagnose
