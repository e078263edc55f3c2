// Appearance fit with the clutter field held (AppearanceOptions::hold_clutter, CLI
// --appearance-hold clutter; issue 20): the textured clutter (clutterFieldKeys) stays at the start
// sensor's values and only the sensor terms are fitted. Known truth: a recording rendered with a
// given clutter field (far multipliers x4, as a calibrated file carries) and a hidden sensor term;
// the fit from the true clutter field with the sensor term off gives the term back and leaves
// every clutter key bit-identical, from every start of the multi-start range-curve fit.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "diagnose/appearance_fixtures.hpp"
#include "spinradar/diagnose/appearance.hpp"
#include "spinradar/sim/realism.hpp"

namespace spinradar::diagnose {
namespace {

// The clutter field of the recording and of every start: denser far (x4 at 35 and 71 m).
sim::SensorConfig clutterField() {
  sim::SensorConfig s = testing::curveSensor();
  s.clutter_density_x_35m = 4.0;
  s.clutter_density_x_71m = 4.0;
  s.clutter_rcs_db = -28.0;
  return s;
}

void expectClutterHeld(const sim::SensorConfig& fitted, const sim::SensorConfig& start) {
  const auto f = fitted.toJson(), s = start.toJson();
  for (const auto& key : clutterFieldKeys()) EXPECT_EQ(f.at(key), s.at(key)) << key;
}

TEST(AppearanceHold, OneDefinitionOfTheClutterField) {
  AppearanceOptions opt;
  EXPECT_FALSE(isHeldParameter(opt, "clutter_density"));
  opt.hold_clutter = true;
  for (const auto& key : clutterFieldKeys()) EXPECT_TRUE(isHeldParameter(opt, key)) << key;
  for (const char* key : {"stc_curve_db_71m", "return_gain_db_35m", "noise_texture_db",
                          "noise_floor_db", "beam_width_deg"})
    EXPECT_FALSE(isHeldParameter(opt, key)) << key;
  // withHeldParameters puts every clutter key back and nothing else.
  sim::SensorConfig moved = perturbCurveStart(clutterField(), 3, -2, 1.5);
  moved.clutter_rcs_db = -40;
  const sim::SensorConfig back = withHeldParameters(moved, clutterField(), opt);
  expectClutterHeld(back, clutterField());
  EXPECT_EQ(back.stc_curve_db_71m, moved.stc_curve_db_71m);
  EXPECT_EQ(back.return_gain_db_16m, moved.return_gain_db_16m);
}

// Range curves: the recording's far noise is 6 dB higher (receiver curve +6 dB at 71 m, returns
// kept); the multi-start fit (3 starts: the flat ones move the clutter density by x2 / x1/2 when
// it is not held) with the clutter held gives the noise curve back within 1 dB at every node.
TEST(AppearanceHold, HiddenFarNoiseWithTheClutterHeld) {
  AppearanceOptions opt = testing::quickAppearanceOptions();
  opt.curve_iterations = 8;
  opt.fit_band_floor = true;
  opt.curve_starts = 3;
  opt.hold_clutter = true;
  sim::SensorConfig truth = clutterField();
  truth.stc_curve_db_71m = 6.0;
  truth.return_gain_db_71m = -6.0;
  const auto real = sim::computeRealism(renderReference(truth, {}, opt, 4244), "recording");
  const sim::SensorConfig start = clutterField();
  std::vector<std::string> log;
  const sim::SensorConfig f = fitRangeCurves(real, start, {}, opt, &log);
  ASSERT_FALSE(log.empty());
  expectClutterHeld(f, start);
  const double noise[4] = {f.stc_curve_db_5m, f.stc_curve_db_16m, f.stc_curve_db_35m,
                           f.stc_curve_db_71m};
  for (int j = 1; j < 4; ++j) EXPECT_NEAR(noise[j], j == 3 ? 6.0 : 0.0, 1.0) << "node " << j;
  double worst = 0;
  for (const auto& [name, gap] : fittedBandGaps(realismOf(f, {}, opt, opt.seed, ""), real))
    worst = std::max(worst, gap);
  EXPECT_LT(worst, 0.15);
}

// Catalogue stage: a receiver 4 dB noisier than the start, the clutter field as in the start.
// Held, the clutter density is not a parameter of the fit; the noise floor comes back.
TEST(AppearanceHold, HiddenNoiseFloorWithTheClutterHeld) {
  AppearanceOptions opt = testing::quickAppearanceOptions();
  opt.iterations = 3;
  opt.realism = false;
  opt.holdout = false;
  opt.curve_iterations = 0;
  opt.fit_glint = false;
  opt.hold_clutter = true;
  sim::SensorConfig truth = clutterField();
  truth.noise_floor_db += 4.0;
  const auto rec = renderReference(truth, {}, opt, 77);
  const sim::SensorConfig start = clutterField();
  const AppearanceReport rep = diagnoseAppearance(rec, start, {}, opt);
  expectClutterHeld(rep.fitted, start);
  EXPECT_NEAR(rep.fitted.noise_floor_db, truth.noise_floor_db, 1.0);
  for (const auto& f : rep.findings) EXPECT_NE(f.parameter, "clutter_density");
}

}  // namespace
}  // namespace spinradar::diagnose
