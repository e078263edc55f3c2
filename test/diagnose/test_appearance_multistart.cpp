// Multi-start per-band calibration (issue 20, fitRangeCurves with curve_starts > 1): the
// range-curve fit must not depend on where it starts. A simulated recording with hidden range
// curves is fitted from perturbed starts; the single Levenberg-Marquardt run lands in another
// minimum from some of them, the multi-start fit gives the hidden curves back from every start.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include "diagnose/appearance_fixtures.hpp"
#include "spinradar/diagnose/appearance.hpp"
#include "spinradar/sim/realism.hpp"

namespace spinradar::diagnose {
namespace {

sim::SensorConfig baseSensor() { return testing::curveSensor(); }

struct Start { double noise, returns, density; };

// A recording whose far noise is 6 dB higher (receiver curve +6 dB at 71 m, returns kept:
// return gain -6 dB), or the null (hidden 0); the floor figure pins the noise side
// (ConcealedFarNoiseFloorFitted in test_appearance_bands.cpp, from one good start).
sim::RealismStats hiddenFarNoise(double hidden, const AppearanceOptions& opt) {
  sim::SensorConfig truth = baseSensor();
  truth.stc_curve_db_71m = hidden;
  truth.return_gain_db_71m = -hidden;
  return sim::computeRealism(renderReference(truth, {}, opt, 4244), "recording");
}

AppearanceOptions floorOptions(int starts) {
  AppearanceOptions opt = testing::quickAppearanceOptions();
  opt.curve_iterations = 8;
  opt.fit_band_floor = true;
  opt.curve_starts = starts;
  return opt;
}

double worstFittedGap(const sim::SensorConfig& s, const sim::RealismStats& real,
                      const AppearanceOptions& opt) {
  double w = 0;
  for (const auto& [name, gap] : fittedBandGaps(realismOf(s, {}, opt, opt.seed, ""), real))
    w = std::max(w, gap);
  return w;
}

// Every node of the hidden curves back within the tolerances: 1 dB for the noise and
// the returns' level, 10 % for the clutter density.
void expectHiddenCurves(const sim::SensorConfig& f, double hidden, const std::string& where,
                        bool noise_only = false) {
  const double noise[4] = {f.stc_curve_db_5m, f.stc_curve_db_16m, f.stc_curve_db_35m,
                           f.stc_curve_db_71m};
  const double returns[4] = {noise[0] + f.return_gain_db_5m, noise[1] + f.return_gain_db_16m,
                             noise[2] + f.return_gain_db_35m, noise[3] + f.return_gain_db_71m};
  const double density[4] = {f.clutter_density_x_5m, f.clutter_density_x_16m,
                             f.clutter_density_x_35m, f.clutter_density_x_71m};
  for (int j = 0; j < 4; ++j) {
    EXPECT_NEAR(noise[j], j == 3 ? hidden : 0.0, 1.0) << where << " node " << j;
    if (noise_only) continue;
    EXPECT_NEAR(returns[j], 0.0, 1.0) << where << " node " << j;
    EXPECT_NEAR(density[j], 1.0, 0.1) << where << " node " << j;
  }
}

// From starts 12 dB under the noise (the far counts quantise to code 0: no gradient) or with the
// noise and returns 8 dB apart, the single run stops in another minimum; the multi-start fit
// gives the same curves from every start, the hidden ones.
TEST(AppearanceMultiStart, HiddenFarNoiseFromEveryStart) {
  const auto real = hiddenFarNoise(6.0, floorOptions(1));
  int wrong = 0;
  sim::SensorConfig first;
  for (const Start st : {Start{-12, 0, 0}, Start{-8, 8, 0}}) {
    const auto s0 = perturbCurveStart(baseSensor(), st.noise, st.returns, st.density);
    const auto single = fitRangeCurves(real, s0, {}, floorOptions(1));
    const double w1 = worstFittedGap(single, real, floorOptions(1));
    const auto multi = fitRangeCurves(real, s0, {}, floorOptions(3));
    const double w3 = worstFittedGap(multi, real, floorOptions(3));
    const std::string where = "start " + std::to_string(st.noise) + "," + std::to_string(st.returns);
    if (std::getenv("SPINRADAR_TEST_VERBOSE"))
      std::cerr << where << ": worst gap single " << w1 << " (noise 16 m " << single.stc_curve_db_16m
                << ") multi " << w3 << "\n" << multi.toJson().dump(1) << "\n";
    if (w1 > 0.15) ++wrong;
    EXPECT_LT(w3, 0.15) << where;
    expectHiddenCurves(multi, 6.0, where);
    if (st.noise == -12)
      first = multi;
    else
      EXPECT_EQ(multi.toJson(), first.toJson()) << where;  // the same from every start
  }
  EXPECT_EQ(wrong, 2);  // the single run: 68 % and 19 % worst gaps from these starts
}

// The null recording (hidden 0) from the start under the noise: the single run ends 9-12 dB off
// at 16 and 35 m; the multi-start fit leaves every noise node within 1 dB of the truth (names
// no receiver change) and every fitted figure within 15 %. Not asserted: the returns' level and
// the clutter density of the null. Three scans of this scene do not pin them: the lowest misfit
// (0.005, from the flat start 6 dB apart) has the returns +6 dB at 5 and 71 m and the clutter
// x0.4-1.4; the 2.5-10 m figures are not fitted and few returns lie at 50-100 m.
TEST(AppearanceMultiStart, NullFromFarStartNamesNothing) {
  const auto real = hiddenFarNoise(0.0, floorOptions(1));
  const auto s0 = perturbCurveStart(baseSensor(), -12, 0, 0);
  const auto single = fitRangeCurves(real, s0, {}, floorOptions(1));
  EXPECT_GT(std::abs(single.stc_curve_db_16m), 3.0);
  EXPECT_GT(worstFittedGap(single, real, floorOptions(1)), 0.15);
  const auto multi = fitRangeCurves(real, s0, {}, floorOptions(3));
  EXPECT_LT(worstFittedGap(multi, real, floorOptions(3)), 0.15);
  expectHiddenCurves(multi, 0.0, "null", true);
}

}  // namespace
}  // namespace spinradar::diagnose
