// The appearance stage's reference scene taken from the recording itself (issue 20,
// AppearanceOptions::scene = "recording"): a known target comes back where it is and as strong
// as it is; the held-out rows are never read; and on a recording of another scene than the
// built-in reference (out_and_back, not city) the sensor is recovered with the recording's own
// scene, and a null recording names nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <iostream>

#include "diagnose/appearance_fixtures.hpp"
#include "spinradar/diagnose/appearance.hpp"
#include "spinradar/sim/simulator.hpp"

namespace spinradar::diagnose {
namespace {

sim::SensorConfig baseSensor() { return testing::hundredMetreSensor(); }

// A standing sensor seeing one point target.
PolarScan oneTarget(const sim::SensorConfig& s, double x, double y, double rcs) {
  sim::World w;
  w.targets.push_back({x, y, rcs});
  const sim::Trajectory standing({{0.0, {}}, {2.0, {}}});
  return sim::Simulator(w, standing, s, {}, 7).renderScan(0);
}

TEST(AppearanceScene, KnownTargetComesBackWhereAndAsStrongAsItIs) {
  const sim::SensorConfig s = baseSensor();
  for (const double rcs : {0.0, 15.0}) {
    const PolarScan scan = oneTarget(s, 30.0, -12.0, rcs);
    const sim::World w = recordingWorld(scan, s, AppearanceOptions{});
    // The strongest scatterer is the target (speckle never stands 12 dB over the median).
    ASSERT_FALSE(w.targets.empty()) << rcs;
    const sim::Target* best = &w.targets.front();
    for (const auto& t : w.targets)
      if (t.rcs > best->rcs) best = &t;
    EXPECT_NEAR(best->x, 30.0, 0.3) << rcs;
    EXPECT_NEAR(best->y, -12.0, 0.5) << rcs;  // a row is 0.9 deg: 0.5 m at 32 m
    EXPECT_NEAR(best->rcs, rcs, 3.0) << rcs;  // quantiser, speckle and the row grid
    // Nothing else near the target's strength (speckle stands out as far weaker returns).
    int strong = 0;
    for (const auto& t : w.targets) strong += t.rcs > rcs - 20;
    EXPECT_EQ(strong, 1) << rcs;
  }
}

// MulRan labels row a with encoder 14 a + 9 (of 5600): its azimuths sit 9/14 of a row past the
// rendered row grid. The scene must come back on the rows it was recorded in, not 0.64 rows late
// (before the fix the target's re-render peaked one row on, 2-5 dB down, split over two rows).
TEST(AppearanceScene, RecordedRowsNotTheirAzimuthLabelsPlaceTheScene) {
  const sim::SensorConfig s = baseSensor();
  for (const double row : {100.0, 100.3}) {  // on a row, and between rows
    const double phi = row * 2 * M_PI / s.azimuths, r = 40.0;
    PolarScan scan = oneTarget(s, r * std::cos(phi), -r * std::sin(phi), 10.0);
    for (double& a : scan.azimuth) a += 9.0 / 14.0 * 2 * M_PI / s.azimuths;  // MulRan labels
    const sim::World w = recordingWorld(scan, s, AppearanceOptions{});
    const sim::Trajectory standing({{0.0, {}}, {2.0, {}}});
    const PolarScan again = sim::Simulator(w, standing, s, {}, 9).renderScan(0);
    const int b = int(std::lround(scan.binOfRange(r)));
    auto peakRow = [&](const PolarScan& sc, int& level) {
      int best = -1;
      level = -1;
      for (int a = 90; a < 110; ++a)
        for (int bb = b - 3; bb <= b + 3; ++bb)
          if (sc.row(a)[bb] > level) level = sc.row(a)[bb], best = a;
      return best;
    };
    int lr = 0, ls = 0;
    const int ar = peakRow(scan, lr), as = peakRow(again, ls);
    EXPECT_EQ(as, ar) << row;
    EXPECT_NEAR(ls, lr, 1.5 * s.power_scale) << row;  // the quantiser's step and the row grid
  }
}

TEST(AppearanceScene, HeldOutRowsAreNeverRead) {
  const sim::SensorConfig s = baseSensor();
  const PolarScan scan = oneTarget(s, 30.0, -12.0, 10.0);
  std::vector<PolarScan> fit, holdout;
  splitHoldout({scan}, fit, holdout);
  ASSERT_EQ(fit.size(), 1u);
  PolarScan changed = fit[0];
  for (int r = 0; r < changed.azimuths; ++r)
    if (!changed.valid[r])
      for (int b = 100; b < changed.bins; b += 50) changed.row(r)[b] = 200;
  EXPECT_EQ(recordingWorld(fit[0], s, {}).toJson(), recordingWorld(changed, s, {}).toJson());
  AppearanceOptions opt;
  opt.scene = "recording";
  const AppearanceOptions o = withReferenceScene(opt, {scan});
  ASSERT_TRUE(o.scene_scans);
  EXPECT_EQ(o.scene_scans->front().valid, fit[0].valid);
  EXPECT_THROW(renderReference(s, {}, opt, 1), std::invalid_argument);  // no scans given
}

// Known truth: the recording is the out_and_back road (open roadside, other content than the
// reference city). Noise floor 3 dB up: with the recording's own scene it comes back within
// 1 dB (the Concealed tolerance) and nothing else is named; the city reference names a spurious
// near-range leakage (17.7 dB) with it. The null recording names nothing with the recording's
// scene (the city: the same spurious leakage). A beam of 2.4 deg is not identifiable with the
// recording's scene (the scene takes up the blur: it comes back 1.49 deg), so it is never named
// there, and nothing spurious is (the city gets 2.34 deg, and the leakage).
TEST(AppearanceScene, SensorRecoveredOnAnotherSceneWithItsOwnScene) {
  AppearanceOptions rec_opt = testing::catalogueOnlyOptions();
  rec_opt.scene = "out_and_back";
  enum Hidden { kNoise, kNull, kBeam };
  for (const Hidden hidden : {kNoise, kNull, kBeam}) {
    sim::SensorConfig truth = baseSensor();
    if (hidden == kNoise) truth.noise_floor_db += 3;
    if (hidden == kBeam) truth.beam_width_deg = 2.4;
    const auto rec = renderReference(truth, {}, rec_opt, 4242);
    for (const std::string scene : {"city", "recording"}) {
      AppearanceOptions opt = testing::catalogueOnlyOptions();
      opt.scene = scene;
      const AppearanceReport rep = diagnoseAppearance(rec, baseSensor(), {}, opt);
      const std::string named = testing::namedFindings(rep);
      if (std::getenv("SPINRADAR_TEST_VERBOSE"))
        std::cerr << "case " << hidden << " scene " << scene << ": named '" << named << "' noise "
                  << rep.fitted.noise_floor_db << " beam " << rep.fitted.beam_width_deg << "\n";
      if (scene == "city") {
        // The contrast this mode is for: the street scene names a leakage that is not there.
        EXPECT_NE(named.find("leakage_db"), std::string::npos) << hidden << ": " << named;
        continue;
      }
      if (hidden == kNoise) {
        EXPECT_NEAR(rep.fitted.noise_floor_db, truth.noise_floor_db, 1.0) << named;
        EXPECT_EQ(named.find("noise_floor_db"), 0u) << named;
        EXPECT_EQ(named.find(' ', 0), named.size() - 1) << "more than one named: " << named;
      } else {
        EXPECT_TRUE(named.empty()) << hidden << ": " << named;
      }
      // Not identifiable with the recording's scene: fitted, never named, and said so.
      for (const auto& f : rep.findings) {
        if (notIdentifiableWithOwnScene(f.parameter)) {
          EXPECT_EQ(f.verdict, "not identifiable") << f.parameter;
        }
      }
    }
  }
}

// Known truth with MulRan's row labels (9/14 of a row past the render's grid, as the sample's
// encoder 14 a + 9): a noise floor 3 dB up comes back within 1 dB and alone; the null names nothing.
// (Noise is the same on every row, so this held before the row-grid fix too; the test above is
// the one the fix is needed for.)
TEST(AppearanceScene, ConcealedNoiseRecoveredWithMulranRowLabels) {
  AppearanceOptions rec_opt = testing::catalogueOnlyOptions();
  rec_opt.scene = "out_and_back";
  for (const bool noise : {true, false}) {
    sim::SensorConfig truth = baseSensor();
    if (noise) truth.noise_floor_db += 3;
    auto rec = renderReference(truth, {}, rec_opt, 4242);
    for (PolarScan& sc : rec)
      for (double& a : sc.azimuth) a += 9.0 / 14.0 * 2 * M_PI / sc.azimuths;
    AppearanceOptions opt = testing::catalogueOnlyOptions();
    opt.scene = "recording";
    const AppearanceReport rep = diagnoseAppearance(rec, baseSensor(), {}, opt);
    const std::string named = testing::namedFindings(rep);
    if (std::getenv("SPINRADAR_TEST_VERBOSE"))
      std::cerr << "noise " << noise << ": named '" << named << "' fitted "
                << rep.fitted.noise_floor_db << " truth " << truth.noise_floor_db << "\n";
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
