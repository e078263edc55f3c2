// Per-band calibration of the appearance stage: range curves (receiver gain, return gain,
// clutter density over range) hidden in a simulated recording are fitted back so that every
// per-band realism figure is within 15 %; the held-out split and the per-rotation counts of
// masked scans are exact.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <iostream>

#include "diagnose/appearance_fixtures.hpp"
#include "spinradar/diagnose/appearance.hpp"
#include "spinradar/sim/realism.hpp"

namespace spinradar::diagnose {
namespace {

sim::SensorConfig baseSensor() { return testing::curveSensor(); }

AppearanceOptions quick() {
  AppearanceOptions o = testing::quickAppearanceOptions();
  o.curve_iterations = 8;
  return o;
}

// Worst relative per-band gap over the fitted figures the recording has enough of: a count
// below 30 per scan (a few scans) is dominated by its own Poisson scatter.
double worstGap(const sim::RealismStats& s, const sim::RealismStats& r) {
  double w = 0;
  auto rel = [&](double a, double b) {
    if (b >= 30) w = std::max(w, std::abs(a - b) / b);
  };
  for (int k = 0; k < 4; ++k) {
    if (isSceneDependent(k, "mean")) continue;  // the whole near band (test_near_band.cpp)
    rel(s.band_mean[k] * 30, r.band_mean[k] * 30);
    rel(s.band_q90[k] * 30, r.band_q90[k] * 30);
    rel(s.band_cacfar[k], r.band_cacfar[k]);
    rel(s.band_cen[k], r.band_cen[k]);
  }
  return w;
}

TEST(AppearanceBands, HeldOutSplit) {
  const auto scans = renderReference(baseSensor(), {}, quick(), 5);
  std::vector<PolarScan> fit, hold;
  splitHoldout(scans, fit, hold);
  ASSERT_EQ(fit.size(), 2u);
  ASSERT_EQ(hold.size(), 1u);
  EXPECT_EQ(fit[1].power, scans[1].power);
  EXPECT_EQ(hold[0].power, scans[2].power);

  // One scan: quarters 0 and 2 against 1 and 3, rows masked; counts stay per full rotation, so
  // the two halves average to the whole scan's plain CA-CFAR count (a per-row detector).
  splitHoldout({scans[0]}, fit, hold);
  ASSERT_EQ(fit.size(), 1u);
  ASSERT_EQ(hold.size(), 1u);
  EXPECT_EQ(fit[0].valid[0], 1);
  EXPECT_EQ(fit[0].valid[100], 0);
  EXPECT_EQ(fit[0].valid[250], 1);
  EXPECT_EQ(hold[0].valid[399], 1);
  sim::RealismOptions ro;
  ro.detect = false;
  const auto whole = sim::computeRealism({scans[0]}, "whole", ro);
  const auto a = sim::computeRealism(fit, "a", ro), b = sim::computeRealism(hold, "b", ro);
  for (int k = 0; k < 4; ++k)
    EXPECT_NEAR(0.5 * (a.band_cacfar[k] + b.band_cacfar[k]), whole.band_cacfar[k], 1e-6) << k;
}

// The simulator's curves: a receiver gain step shows in the band mean where it is set.
TEST(AppearanceBands, CurvesActWhereSet) {
  sim::SensorConfig s = baseSensor();
  sim::RealismOptions ro;
  ro.detect = false;
  const auto base = sim::computeRealism(renderReference(s, {}, quick(), 5), "base", ro);
  s.stc_curve_db_71m = 6.0;
  const auto up = sim::computeRealism(renderReference(s, {}, quick(), 5), "up", ro);
  EXPECT_NEAR(up.band_mean[0], base.band_mean[0], 0.05);  // 5 m node untouched
  EXPECT_GT(up.band_mean[3] - base.band_mean[3], 3.0);    // mostly at 71 m
}

// What a wider street does to the recording (test/sim/test_near_band.cpp, one side at 6 m and
// the other at 11 m instead of 6 m): the 2.5-10 m figures change, nothing else.
sim::RealismStats widerStreet(sim::RealismStats r) {
  r.band_mean[0] *= 0.55;
  r.band_q90[0] *= 0.3;
  r.band_cacfar[0] *= 0.6;
  r.band_cen[0] *= 0.5;
  return r;
}

TEST(AppearanceBands, ConcealedRangeCurvesFitted) {
  sim::SensorConfig truth = baseSensor();
  truth.stc_curve_db_35m = 5.0;       // receiver gain bump at 25-50 m
  truth.return_gain_db_71m = -6.0;    // far returns dimmer (elevation pattern)
  truth.clutter_density_x_16m = 3.0;  // more clutter at 10-25 m
  const auto rec = renderReference(truth, {}, quick(), 4242);  // not the fit's seed
  // The recording's street is wider than the reference scene's: the scene-dependent figure
  // differs, the sensor change must still come back.
  for (const char* f : {"mean", "q90", "cacfar", "cen2018"}) ASSERT_TRUE(isSceneDependent(0, f));
  const auto real = widerStreet(sim::computeRealism(rec, "recording"));
  const AppearanceOptions opt = quick();
  const auto before = realismOf(baseSensor(), {}, opt, opt.seed + 1, "before");
  std::vector<std::string> steps;
  const sim::SensorConfig fitted = fitRangeCurves(real, baseSensor(), {}, opt, &steps);
  const auto after = realismOf(fitted, {}, opt, opt.seed + 1, "after");
  if (std::getenv("SPINRADAR_TEST_VERBOSE"))
    std::cerr << sim::formatRealismTable({real, before, after}) << fitted.toJson().dump(1);
  EXPECT_GT(worstGap(before, real), 0.2);
  EXPECT_LT(worstGap(after, real), 0.15);
  // The curves come back near the truth where the figures pin them (noise level in dB, the
  // density as a ratio).
  EXPECT_NEAR(fitted.stc_curve_db_35m, 5.0, 1.5);
  // The density ratio comes back low (true 3; 1.78-2.06 over recording seeds 4242-4245 on
  // the city route with eased turns; 0.68 without the hidden density): assert well above that.
  EXPECT_GT(fitted.clutter_density_x_16m / std::max(fitted.clutter_density_x_35m, 1e-3), 1.6);
  // Left out, not fitted: the near-band gaps stay what the street makes them.
  EXPECT_GT(after.band_q90[0] / real.band_q90[0], 2.0);
  for (const auto& [name, gap] : fittedBandGaps(after, real))
    EXPECT_EQ(name.find("2.5-10 m"), std::string::npos) << name;
}

// A scene-dependent figure cannot drive the fit: the street width of the recording (any value
// of that figure) leaves every fitted curve exactly as it is.
TEST(AppearanceBands, SceneDependentFigureCannotDriveTheFit) {
  sim::SensorConfig truth = baseSensor();
  truth.stc_curve_db_16m = 4.0;
  const auto real = sim::computeRealism(renderReference(truth, {}, quick(), 4243), "recording");
  AppearanceOptions opt = quick();
  opt.curve_iterations = 2;
  const sim::SensorConfig a = fitRangeCurves(real, baseSensor(), {}, opt);
  const sim::SensorConfig b = fitRangeCurves(widerStreet(real), baseSensor(), {}, opt);
  EXPECT_NE(a.toJson(), baseSensor().toJson());  // the fit moved
  EXPECT_EQ(a.toJson(), b.toJson());
}

// Receiver noise against weak clutter (issue 20, Oxford's Cen2018 counts): a recording whose far
// noise floor is 6 dB higher (receiver curve +6 dB at 71 m, returns kept: return gain -6 dB)
// raises the far mean as denser weak clutter would; the floor figure (lower half of the counts,
// receiver noise) tells them apart, and the fit with it gives the noise node back within 1 dB.
// The null recording (base model, another seed) leaves the node within 1 dB of zero.
TEST(AppearanceBands, ConcealedFarNoiseFloorFitted) {
  AppearanceOptions opt = quick();
  opt.fit_band_floor = true;
  for (const double hidden : {6.0, 0.0}) {
    sim::SensorConfig truth = baseSensor();
    truth.stc_curve_db_71m = hidden;
    truth.return_gain_db_71m = -hidden;
    const auto real = sim::computeRealism(renderReference(truth, {}, quick(), 4244), "recording");
    // The start carries the far level as dense weak clutter (Oxford's default fit: clutter at
    // its bound x20 at 35 and 71 m over a noise floor quantised to code 0).
    sim::SensorConfig start = baseSensor();
    start.clutter_density_x_35m = start.clutter_density_x_71m = 8.0;
    const sim::SensorConfig fitted = fitRangeCurves(real, start, {}, opt);
    const auto after = realismOf(fitted, {}, opt, opt.seed + 1, "after");
    if (std::getenv("SPINRADAR_TEST_VERBOSE"))
      std::cerr << "hidden " << hidden << ": noise node 71 m " << fitted.stc_curve_db_71m
                << ", returns " << fitted.stc_curve_db_71m + fitted.return_gain_db_71m
                << ", floor 50-100 m real " << real.band_floor[3] << " fitted "
                << after.band_floor[3] << ", clutter x71 " << fitted.clutter_density_x_71m << "\n";
    // Without the floor figure the same fit kept the clutter (x12 at 71 m) and the noise node
    // at 1.1 dB (floor 0.8 against 5.2 counts); the returns' node is not pinned here (9 dB off
    // with a 6 dB noise change: few returns at 50-100 m in three scans).
    EXPECT_NEAR(fitted.stc_curve_db_71m, hidden, 1.0) << hidden;
    EXPECT_LT(fitted.clutter_density_x_71m, 4.0) << hidden;
    EXPECT_NEAR(after.band_floor[3], real.band_floor[3], 0.15 * real.band_floor[3] + 0.1) << hidden;
  }
}

// The share of zero counts (fit_band_zeros) pins the noise level where the floor figure cannot:
// a recording whose far noise is 6 dB lower (receiver curve -6 dB at 71 m, returns kept) has
// over half its 50-100 m counts at code 0, so its floor (lower half of the counts) is 0 as in any
// darker model. The zero share gives the node back within 1 dB; the null (base model, another
// seed) leaves it within 1 dB of zero.
TEST(AppearanceBands, ConcealedDarkFarNoiseFittedByZeroShare) {
  AppearanceOptions opt = quick();
  opt.fit_band_zeros = true;
  opt.fit_cen2018 = false;  // the noise side only: Cen2018 counts move with the dark rows too
  for (const double hidden : {-6.0, 0.0}) {
    sim::SensorConfig truth = baseSensor();
    truth.stc_curve_db_71m = hidden;
    truth.return_gain_db_71m = -hidden;
    const auto real = sim::computeRealism(renderReference(truth, {}, quick(), 4244), "recording");
    const sim::SensorConfig fitted = fitRangeCurves(real, baseSensor(), {}, opt);
    const auto after = realismOf(fitted, {}, opt, opt.seed + 1, "after");
    if (std::getenv("SPINRADAR_TEST_VERBOSE"))
      std::cerr << "hidden " << hidden << ": noise node 71 m " << fitted.stc_curve_db_71m
                << ", zeros 50-100 m real " << real.band_zero[3] << " fitted " << after.band_zero[3]
                << ", floor real " << real.band_floor[3] << "\n";
    if (hidden < 0) {
      EXPECT_GT(real.band_zero[3], 0.5);  // the floor figure is blind here
    }
    EXPECT_NEAR(fitted.stc_curve_db_71m, hidden, 1.0) << hidden;
    EXPECT_NEAR(after.band_zero[3], real.band_zero[3], 0.1 * real.band_zero[3]) << hidden;
  }
}

// Left out of the fit (fit_cen2018 off), the Cen2018 counts cannot move it: a recording with
// any Cen2018 figures gives the same curves.
TEST(AppearanceBands, Cen2018LeftOutCannotDriveTheFit) {
  sim::SensorConfig truth = baseSensor();
  truth.stc_curve_db_16m = 4.0;
  const auto real = sim::computeRealism(renderReference(truth, {}, quick(), 4243), "recording");
  AppearanceOptions opt = quick();
  opt.curve_iterations = 2;
  opt.fit_band_floor = true;
  opt.fit_cen2018 = false;
  auto fewer = real;
  for (double& c : fewer.band_cen) c *= 0.3;
  const sim::SensorConfig a = fitRangeCurves(real, baseSensor(), {}, opt);
  const sim::SensorConfig b = fitRangeCurves(fewer, baseSensor(), {}, opt);
  EXPECT_NE(a.toJson(), baseSensor().toJson());  // the fit moved
  EXPECT_EQ(a.toJson(), b.toJson());
}

}  // namespace
}  // namespace spinradar::diagnose
