// Alternating chirps of unequal range resolution with known truth (appearance_chirp.cpp): a
// recording whose odd rows have a range response 1.4 times as wide as the even rows' (Boreas-RT's
// up chirp) gives the ratio back within 10 % and names it (nothing else: the even rows' spread is
// fitted with it); the base model names nothing. The simulator side: odd rows' returns come out
// wider by about the ratio, even rows unchanged, and the default (ratio 1) renders byte-identical
// scans.
#include <gtest/gtest.h>

#include <cstdlib>
#include <iostream>

#include "diagnose/appearance_fixtures.hpp"
#include "spinradar/diagnose/appearance.hpp"
#include "spinradar/sim/scenes.hpp"
#include "spinradar/sim/simulator.hpp"
#include "../../src/diagnose/appearance_detail.hpp"

namespace spinradar::diagnose {
namespace {

// 100 m, Boreas-RT-like noise well over zero (its fitted floor: 43 dB) so that the noise is seen.
sim::SensorConfig baseSensor() {
  sim::SensorConfig s = testing::hundredMetreSensor();
  s.noise_floor_db = 20.0;
  return s;
}

AppearanceOptions quick() { return testing::catalogueOnlyOptions(); }

const AppearanceFinding* findingOf(const AppearanceReport& rep, const std::string& key) {
  for (const auto& f : rep.findings)
    if (f.parameter == key) return &f;
  return nullptr;
}

TEST(OddRangeSpread, RenderedWiderOnOddRowsOnly) {
  sim::SensorConfig wide = baseSensor();
  wide.range_psf_odd_ratio = 1.4;
  const auto one = renderReference(baseSensor(), {}, quick(), 7);
  const auto two = renderReference(wide, {}, quick(), 7);
  const detail::ParityWidths a = detail::parityRangeWidths(one, 1.0, 2.7);
  const detail::ParityWidths b = detail::parityRangeWidths(two, 1.0, 2.7);
  ASSERT_GT(a.n_even, 50);
  ASSERT_GT(a.n_odd, 50);
  EXPECT_NEAR(a.ratio, 1.0, 0.05);
  EXPECT_NEAR(b.even, a.even, 0.1 * a.even);  // even rows as before
  EXPECT_GT(b.ratio, 1.25);                   // odd rows wider by about the ratio
  EXPECT_LT(b.ratio, 1.5);
}

TEST(OddRangeSpread, DefaultIsByteIdentical) {
  sim::SensorConfig same = baseSensor();
  same.range_psf_odd_ratio = 1.0;
  const auto one = renderReference(baseSensor(), {}, quick(), 5);
  const auto two = renderReference(same, {}, quick(), 5);
  ASSERT_EQ(one.size(), two.size());
  for (size_t i = 0; i < one.size(); ++i) EXPECT_TRUE(one[i].power == two[i].power) << i;
}

TEST(OddRangeSpread, ConcealedRatioFitted) {
  sim::SensorConfig truth = baseSensor();
  truth.range_psf_odd_ratio = 1.4;
  const auto rec = renderReference(truth, {}, quick(), 4242);  // not the fit's seed
  const AppearanceReport rep = diagnoseAppearance(rec, baseSensor(), {}, quick());
  if (std::getenv("SPINRADAR_TEST_VERBOSE")) std::cerr << rep.summaryMarkdown();
  const AppearanceFinding* f = findingOf(rep, "range_psf_odd_ratio");
  ASSERT_NE(f, nullptr);
  EXPECT_TRUE(f->named) << f->verdict;
  EXPECT_NEAR(f->value, 1.4, 0.14);
  EXPECT_LE(std::abs(f->value - 1.4), 4 * f->stddev + 0.14);
  EXPECT_NEAR(rep.fitted.range_psf_odd_ratio, 1.4, 0.14);
  // The even rows' spread is fitted with it (the truth, 2.7 bins), and nothing else is named.
  EXPECT_NEAR(rep.fitted.range_psf_sigma_bins, 2.7, 0.27);
  EXPECT_EQ(testing::namedFindings(rep).find("range_psf_odd_ratio"), 0u) << testing::namedFindings(rep);
  EXPECT_EQ(testing::namedFindings(rep).find(' ') + 1, testing::namedFindings(rep).size())
      << testing::namedFindings(rep);
}

TEST(OddRangeSpread, NullNamesNothing) {
  const auto rec = renderReference(baseSensor(), {}, quick(), 4242);
  const AppearanceReport rep = diagnoseAppearance(rec, baseSensor(), {}, quick());
  const AppearanceFinding* f = findingOf(rep, "range_psf_odd_ratio");
  ASSERT_NE(f, nullptr);
  EXPECT_FALSE(f->named) << f->value << " +- " << f->stddev;
  EXPECT_EQ(rep.fitted.range_psf_odd_ratio, 1.0);
  EXPECT_TRUE(testing::namedFindings(rep).empty()) << testing::namedFindings(rep);
}

}  // namespace
}  // namespace spinradar::diagnose
