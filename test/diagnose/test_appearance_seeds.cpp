// The appearance stage over several noise seeds (AppearanceOptions::render_seeds, fit_seeds;
// CLI --render-seeds, --appearance-fit-seeds; docs/diagnose_render_seeds.md). Known truth: one
// seed is today's single render; the before / after figures over N seeds are the means of the
// single-seed figures and the worst gaps the mean of each seed's worst gap; the fit's objective
// is the mean over its own seeds, which never meet the report's.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "../../src/diagnose/appearance_detail.hpp"
#include "diagnose/appearance_fixtures.hpp"
#include "spinradar/sim/realism.hpp"

namespace spinradar::diagnose {
namespace {

double worstOf(const sim::RealismStats& sim, const sim::RealismStats& real) {
  double w = 0;
  for (const auto& g : fittedBandGaps(sim, real)) w = std::max(w, g.second);
  return w;
}

TEST(AppearanceSeeds, FitAndReportSeedsNeverMeet) {
  AppearanceOptions opt;
  EXPECT_EQ(fitSeeds(opt), std::vector<uint64_t>({opt.seed}));         // today's fit
  EXPECT_EQ(reportSeeds(opt), std::vector<uint64_t>({opt.seed + 1}));  // today's report
  opt.fit_seeds = 64;
  opt.render_seeds = 999;
  const auto f = fitSeeds(opt), r = reportSeeds(opt);
  std::set<uint64_t> all(f.begin(), f.end());
  all.insert(r.begin(), r.end());
  EXPECT_EQ(all.size(), f.size() + r.size());
  opt.render_seeds = 0;
  EXPECT_THROW(reportSeeds(opt), std::invalid_argument);
  opt.fit_seeds = 0;
  EXPECT_THROW(fitSeeds(opt), std::invalid_argument);
}

TEST(AppearanceSeeds, BeforeAfterOverSeedsAreSingleSeedMeans) {
  AppearanceOptions opt = testing::quickAppearanceOptions();
  opt.holdout_scene_check = false;
  // The "recording": the base sensor with its receiver 4 dB noisier, another seed; the model
  // before = base, after = the truth.
  const sim::SensorConfig base = testing::curveSensor();
  sim::SensorConfig truth = base;
  truth.noise_floor_db += 4;
  const auto real = renderReference(truth, {}, opt, 501), holdout = renderReference(truth, {}, opt, 502);
  AppearanceReport one, three;
  one.base = three.base = base;
  one.fitted = three.fitted = truth;
  detail::realismBeforeAfter(real, holdout, opt, one);
  // One seed: today's figures (seed + 1), bit for bit.
  const auto single_after = realismOf(truth, {}, opt, opt.seed + 1, "");
  EXPECT_EQ(one.worst_gap_after, worstOf(single_after, one.realism_real));
  EXPECT_EQ(one.worst_holdout_after, worstOf(single_after, one.realism_holdout));
  for (int k = 0; k < kBands; ++k) EXPECT_EQ(one.realism_after.band_q90[k], single_after.band_q90[k]);

  opt.render_seeds = 3;
  detail::realismBeforeAfter(real, holdout, opt, three);
  double worst_before = 0, worst_after = 0, worst_hold = 0, lo = 1e9, hi = 0;
  double cen[kBands] = {0, 0, 0, 0};
  for (uint64_t s = opt.seed + 1; s <= opt.seed + 3; ++s) {
    const auto b = realismOf(base, {}, opt, s, ""), a = realismOf(truth, {}, opt, s, "");
    worst_before += worstOf(b, three.realism_real) / 3;
    const double w = worstOf(a, three.realism_real);
    worst_after += w / 3;
    lo = std::min(lo, w), hi = std::max(hi, w);
    worst_hold += worstOf(a, three.realism_holdout) / 3;
    for (int k = 0; k < kBands; ++k) cen[k] += a.band_cen[k] / 3;
  }
  EXPECT_NEAR(three.worst_gap_before, worst_before, 1e-12);
  EXPECT_NEAR(three.worst_gap_after, worst_after, 1e-12);
  EXPECT_NEAR(three.worst_holdout_after, worst_hold, 1e-12);
  EXPECT_EQ(three.worst_after_seeds.lo, lo);
  EXPECT_EQ(three.worst_after_seeds.hi, hi);
  EXPECT_EQ(three.worst_after_seeds.n, 3);
  for (int k = 0; k < kBands; ++k) EXPECT_NEAR(three.realism_after.band_cen[k], cen[k], 1e-9);
  // The base model is off by the 4 dB of noise, the truth is not: over seeds as in one.
  EXPECT_GT(three.worst_gap_before, three.worst_gap_after);
  const auto j = three.toJson();
  EXPECT_EQ(j.at("render_seeds"), 3);
  EXPECT_NEAR(j.at("worst_band_gap_over_seeds").at("after").at("mean").get<double>(), worst_after, 1e-12);
  EXPECT_TRUE(j.at("realism_bands").contains("sim_after_max"));
}

TEST(AppearanceSeeds, FitObjectiveIsTheMeanOverTheFitSeeds) {
  AppearanceOptions opt = testing::quickAppearanceOptions();
  opt.scans = 2;
  opt.fit_seeds = 3;
  const sim::SensorConfig s = testing::curveSensor();
  const auto over = realismOverSeedsOf(s, {}, opt, fitSeeds(opt), "");
  double mean[kBands] = {0, 0, 0, 0};
  for (uint64_t seed : {opt.seed, opt.seed + kFitSeedStride, opt.seed + 2 * kFitSeedStride}) {
    const auto r = realismOf(s, {}, opt, seed, "");
    for (int k = 0; k < kBands; ++k) mean[k] += r.band_cacfar[k] / 3;
  }
  for (int k = 0; k < kBands; ++k) EXPECT_NEAR(over.mean.band_cacfar[k], mean[k], 1e-9) << k;
}

}  // namespace
}  // namespace spinradar::diagnose
