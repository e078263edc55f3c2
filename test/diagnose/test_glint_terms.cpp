// Anisotropic glint and azimuth jitter with known truth: the physics keys (off = unchanged
// output, range checks, carried by a sensor file, explicit physics wins); their spread across /
// along the beam; the fit of the three terms on concealed recordings (another route, seed and
// noise than the reference) gives each back within 10 %, and names nothing on a null recording.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "spinradar/diagnose/glint_terms.hpp"
#include "spinradar/diagnose/matched_spread.hpp"
#include "spinradar/sim/scenes.hpp"
#include "spinradar/sim/simulator.hpp"

namespace spinradar::diagnose {
namespace {

sim::PhysicsConfig drive(double across = 0, double along = 0, double jitter_deg = 0) {
  sim::PhysicsConfig p;
  p.motion_distortion = true;
  p.doppler = 0.049;
  p.moving_objects = true;
  if (across > 0) p.extra["glint_across"] = across;
  if (along > 0) p.extra["glint_along"] = along;
  if (jitter_deg > 0) p.extra["azimuth_jitter"] = jitter_deg;
  return sim::PhysicsConfig::fromJson(p.toJson());
}

std::vector<PolarScan> recording(const sim::PhysicsConfig& p, int first, int n = 16,
                                 const sim::SensorConfig& sensor = {}) {
  sim::Scene sc = sim::builtinScene("out_and_back");
  sim::Simulator s(std::move(sc.world), std::move(sc.trajectory), sensor, p, 7);
  std::vector<PolarScan> out;
  for (int i = first; i < first + n; ++i) out.push_back(s.renderScan(i));
  return out;
}

TEST(GlintTermsEffect, OffIsTheOldOutputKeysCheckedSensorCarriesThem) {
  sim::PhysicsConfig zero = drive();
  zero.extra["glint_across"] = 0.0, zero.extra["glint_along"] = 0.0, zero.extra["azimuth_jitter"] = 0.0;
  const auto off = recording(drive(), 300, 1);
  EXPECT_EQ(recording(zero, 300, 1)[0].power, off[0].power);
  for (const char* k : {"glint_across", "glint_along", "azimuth_jitter"}) {
    EXPECT_THROW(sim::PhysicsConfig::fromJson({{k, -0.1}}), std::exception) << k;
    EXPECT_THROW(sim::PhysicsConfig::fromJson({{k, 6.0}}), std::exception) << k;
  }
  // A sensor file carries them in "physics" (range-checked, unknown keys rejected); a sensor
  // without them writes no "physics" entry.
  EXPECT_FALSE(sim::SensorConfig{}.toJson().contains("physics"));
  nlohmann::json j = sim::SensorConfig{}.toJson();
  j["physics"] = {{"glint_across", 0.1}, {"azimuth_jitter", 0.2}};
  const sim::SensorConfig s = sim::SensorConfig::fromJson(j);
  EXPECT_DOUBLE_EQ(s.physics.at("glint_across"), 0.1);
  EXPECT_EQ(sim::SensorConfig::fromJson(s.toJson()).physics, s.physics);
  j["physics"] = {{"doppler", 0.1}};
  EXPECT_THROW(sim::SensorConfig::fromJson(j), std::exception);
  j["physics"] = {{"glint_along", -1}};
  EXPECT_THROW(sim::SensorConfig::fromJson(j), std::exception);
  // The sensor's terms render as the same physics keys would; an explicit physics key wins.
  sim::SensorConfig carrying;
  carrying.physics = {{"glint_across", 0.2}, {"azimuth_jitter", 0.3}};
  const auto via_physics = recording(drive(0.2, 0, 0.3), 300, 1);
  EXPECT_EQ(recording(drive(), 300, 1, carrying)[0].power, via_physics[0].power);
  EXPECT_NE(via_physics[0].power, off[0].power);
  EXPECT_EQ(recording(zero, 300, 1, carrying)[0].power, off[0].power);
}

TEST(GlintTermsEffect, AcrossAlongAndJitterSpread) {
  const MatchedSpread base = measureMatchedSpread(recording(drive(), 300));
  const MatchedSpread across = measureMatchedSpread(recording(drive(0.12, 0, 0), 300));
  const MatchedSpread along = measureMatchedSpread(recording(drive(0, 0.12, 0), 300));
  const MatchedSpread jitter = measureMatchedSpread(recording(drive(0, 0, 0.25), 300));
  auto grow = [](double with, double without) { return std::sqrt(std::max(with * with - without * without, 0.0)); };
  std::cout << "base " << base.all.tangential << " / " << base.all.radial << "; across "
            << across.all.tangential << " / " << across.all.radial << "; along "
            << along.all.tangential << " / " << along.all.radial << "\n";
  // Per-axis std g adds 2 g^2 to the variance of its component only.
  EXPECT_NEAR(grow(across.all.tangential, base.all.tangential), std::sqrt(2.0) * 0.12, 0.15 * 0.17);
  EXPECT_LT(grow(across.all.radial, base.all.radial), 0.05);
  EXPECT_NEAR(grow(along.all.radial, base.all.radial), std::sqrt(2.0) * 0.12, 0.15 * 0.17);
  EXPECT_LT(grow(along.all.tangential, base.all.tangential), 0.05);
  // Azimuth jitter: the added across spread grows with range (near band vs far band).
  for (int b = 0; b < 4; ++b)
    std::cout << "band " << b << " r " << jitter.band[b].range << ": jitter "
              << jitter.band[b].tangential << " base " << base.band[b].tangential << "\n";
  const double near = grow(jitter.band[1].tangential, base.band[1].tangential);
  const double far = grow(jitter.band[3].tangential, base.band[3].tangential);
  EXPECT_GT(far, 2.5 * near);
  EXPECT_LT(grow(jitter.all.radial, base.all.radial), 0.05);
}

void expectTerm(const GlintTerm& t, double truth) {
  if (truth > 0) {
    EXPECT_TRUE(t.named) << t.key << " " << t.verdict << " " << t.value;
    EXPECT_NEAR(t.value, truth, 0.1 * truth) << t.key;
    EXPECT_LT(std::abs(t.value - truth), 3 * t.stddev + 0.02 * truth) << t.key;
  } else {
    EXPECT_FALSE(t.named) << t.key << " " << t.verdict << " " << t.value << " +- " << t.stddev;
  }
}

TEST(GlintTermsFit, ConcealedAnisotropicGlintFitted) {
  const GlintTermsFit g = fitGlintTerms(recording(drive(0.12, 0.08, 0), 300), sim::SensorConfig{}, drive());
  std::cout << glintTermsTable(g);
  expectTerm(g.across, 0.12);
  expectTerm(g.along, 0.08);
  expectTerm(g.jitter, 0);
}

TEST(GlintTermsFit, ConcealedAzimuthJitterFitted) {
  const GlintTermsFit g = fitGlintTerms(recording(drive(0, 0, 0.25), 300), sim::SensorConfig{}, drive());
  std::cout << glintTermsTable(g);
  expectTerm(g.jitter, 0.25);
  expectTerm(g.along, 0);
}

// RADIATE's fitted terms concealed on its sensor model (0.174 m bins), on the reference's route
// (another segment and seed than the reference's) and on another route: glint_along comes back
// within 10 % beside the azimuth jitter and the across glint, which widen the along spread too.
// (The reference rendered at the fit then shows 0.132-0.141 m along against the recordings'
// 0.124-0.127 m: the along figure's segment-to-segment scatter at fixed terms, not a fit error;
// docs/diagnose_glint.md.)
TEST(GlintTermsFit, ConcealedAlongBesideJitterOnRadiateSensor) {
  sim::SensorConfig radiate = sim::SensorConfig::loadNamed("radiate");
  radiate.physics.clear();
  sim::Scene sc = sim::builtinScene("city");
  sim::Simulator sim(std::move(sc.world), std::move(sc.trajectory), radiate, drive(0.06, 0.07, 0.3), 7);
  std::vector<PolarScan> city;
  for (int i = 100; i < 116; ++i) city.push_back(sim.renderScan(i));
  for (const auto& rec : {city, recording(drive(0.06, 0.07, 0.3), 300, 16, radiate)}) {
    const GlintTermsFit g = fitGlintTerms(rec, radiate, drive());
    std::cout << glintTermsTable(g);
    expectTerm(g.along, 0.07);
    expectTerm(g.jitter, 0.3);
  }
}

TEST(GlintTermsFit, NullNamesNothingOneScanNotIdentifiable) {
  const GlintTermsFit g = fitGlintTerms(recording(drive(), 300), sim::SensorConfig{}, drive());
  std::cout << glintTermsTable(g);
  expectTerm(g.across, 0);
  expectTerm(g.along, 0);
  expectTerm(g.jitter, 0);
  EXPECT_TRUE(g.named().empty());
  const auto one = recording(drive(), 300, 1);
  const GlintTermsFit n = fitGlintTerms({one[0], one[0]}, sim::SensorConfig{}, drive());
  EXPECT_FALSE(n.measured);
  EXPECT_EQ(n.across.verdict, "not identifiable");
}

}  // namespace
}  // namespace spinradar::diagnose
