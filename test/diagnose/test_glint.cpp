// Glint with known truth: the matched-spread measurement on synthetic scans of point targets
// with a known per-scan tangential jitter and known motion; the simulator's glint effect (off =
// unchanged output, on = the spread it adds); the fit on concealed recordings (another route,
// seed and noise) names a glint of 0.15 m and gives it back within 10 %, and names nothing on a
// null recording.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>

#include "spinradar/diagnose/glint_fit.hpp"
#include "spinradar/diagnose/matched_spread.hpp"
#include "spinradar/sim/scenes.hpp"
#include "spinradar/sim/simulator.hpp"

namespace spinradar::diagnose {
namespace {

// A scan of point targets seen from pose (x, y, yaw): log-Gaussian blobs (8 counts of curvature
// per sigma^2, sigma 2 bins and 0.8 rows) over counts 0-9; each target moved across the line of
// sight by `tan_sd` (a new draw per scan).
PolarScan syntheticScan(const std::vector<Eigen::Vector2d>& targets, double px, double py,
                        double yaw, double tan_sd, std::mt19937& rng) {
  PolarScan s;
  s.resize(400, 2300);
  s.range_resolution = 0.0438;
  std::uniform_int_distribution<int> noise(0, 9);
  std::normal_distribution<double> n01;
  for (int a = 0; a < 400; ++a) {
    s.azimuth[a] = a * 2 * M_PI / 400;
    s.stamp_ns[a] = 0;
    for (int b = 0; b < 2300; ++b) s.row(a)[b] = uint8_t(noise(rng));
  }
  for (const auto& t : targets) {
    const double dx = t.x() - px, dy = t.y() - py;
    const double xs = std::cos(yaw) * dx + std::sin(yaw) * dy, ys = -std::sin(yaw) * dx + std::cos(yaw) * dy;
    const double r0 = std::hypot(xs, ys);
    const double phi = std::atan2(-ys, xs) + tan_sd * n01(rng) / r0;
    const double fb = s.binOfRange(r0), fa = phi * 400 / (2 * M_PI);
    for (int da = -3; da <= 3; ++da)
      for (int db = -6; db <= 6; ++db) {
        const int a = ((int(std::round(fa)) + da) % 400 + 400) % 400, b = int(std::round(fb)) + db;
        if (b < 0 || b >= 2300) continue;
        double ra = std::round(fa) + da - fa;
        const double v = 200 - 4.0 * (std::pow((b - fb) / 2.0, 2) + std::pow(ra / 0.8, 2));
        if (v > s.row(a)[b]) s.row(a)[b] = uint8_t(std::clamp(std::round(v), 0.0, 255.0));
      }
  }
  return s;
}

TEST(MatchedSpread, KnownTangentialJitterAndMotion) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-95, 95);
  std::vector<Eigen::Vector2d> targets;
  while (targets.size() < 300) {
    const Eigen::Vector2d p(u(rng), u(rng));
    if (p.norm() < 5 || p.norm() > 95) continue;
    bool apart = true;
    for (const auto& q : targets) apart = apart && (q - p).norm() > 4;
    if (apart) targets.push_back(p);
  }
  // Three scans moving 1.2 m forward, 0.3 m left and turning 1 degree per scan.
  std::vector<PolarScan> scans;
  const double step_yaw = M_PI / 180;
  for (int i = 0; i < 3; ++i) {
    scans.push_back(syntheticScan(targets, 1.2 * i, 0.3 * i, step_yaw * i, 0.1, rng));
    scans.back().stamp_ns.assign(400, int64_t(i) * 250000000);
  }
  const MatchedSpread m = measureMatchedSpread(scans);
  std::cout << "tangential " << m.all.tangential << " radial " << m.all.radial << " matches "
            << m.all.matches << "\n";
  ASSERT_EQ(m.pairs, 2);
  for (const auto& T : m.motions) {
    // Scan i+1 in the frame of scan i: rotate the world step into it.
    EXPECT_NEAR(std::atan2(T(1, 0), T(0, 0)), step_yaw, (0.1 * M_PI / 180));
    EXPECT_NEAR((T.topRightCorner<2, 1>().norm()), std::hypot(1.2, 0.3), 0.03);
  }
  // Difference of two independent draws: sqrt(2) x 0.1 m across the beam; along it only the
  // sub-bin rounding.
  EXPECT_NEAR(m.all.tangential, std::sqrt(2.0) * 0.1, 0.15 * std::sqrt(2.0) * 0.1);
  EXPECT_LT(m.all.radial, 0.04);
  EXPECT_GT(m.all.matches, 400);
}

sim::PhysicsConfig drive(double glint) {
  sim::PhysicsConfig p;
  p.motion_distortion = true;
  p.doppler = 0.049;
  p.moving_objects = true;
  if (glint > 0) p.extra["glint"] = glint;
  return sim::PhysicsConfig::fromJson(p.toJson());
}

std::vector<PolarScan> recording(double glint, int first, int n = 16) {
  sim::Scene sc = sim::builtinScene("out_and_back");
  sim::Simulator s(std::move(sc.world), std::move(sc.trajectory), sim::SensorConfig{}, drive(glint), 7);
  std::vector<PolarScan> out;
  for (int i = first; i < first + n; ++i) out.push_back(s.renderScan(i));
  return out;
}

TEST(GlintEffect, ZeroIsTheOldOutputAndOnAddsItsSpread) {
  sim::PhysicsConfig zero = drive(0);
  zero.extra["glint"] = 0.0;
  const auto off = recording(0, 300, 2);
  sim::Scene sc = sim::builtinScene("out_and_back");
  sim::Simulator s(std::move(sc.world), std::move(sc.trajectory), sim::SensorConfig{}, zero, 7);
  EXPECT_EQ(s.renderScan(300).power, off[0].power);
  EXPECT_THROW(sim::PhysicsConfig::fromJson({{"glint", -0.1}}), std::exception);
  // Per-axis std g adds 2 g^2 to the variance of the matched difference across the beam.
  const double base = measureMatchedSpread(recording(0, 300)).all.tangential;
  const double with = measureMatchedSpread(recording(0.1, 300)).all.tangential;
  const double expect = std::sqrt(base * base + 2 * 0.1 * 0.1);
  EXPECT_NEAR(with, expect, 0.12 * expect) << "base " << base;
}

TEST(GlintFit, ConcealedGlintNamedAndFittedNullNamesNothing) {
  // Reference: the city route; recordings: out_and_back, another seed.
  const GlintFit g = fitGlint(recording(0.15, 300), sim::SensorConfig{}, drive(0));
  std::cout << glintTable(g) << "fitted " << g.value << " +- " << g.stddev << " (z " << g.z << ")\n";
  EXPECT_TRUE(g.named) << g.verdict;
  EXPECT_NEAR(g.value, 0.15, 0.015);
  EXPECT_GT(g.stddev, 0.0);
  EXPECT_LT(std::abs(g.value - 0.15), 3 * g.stddev);
  const GlintFit null = fitGlint(recording(0, 300), sim::SensorConfig{}, drive(0));
  std::cout << "null: " << null.value << " +- " << null.stddev << " (z " << null.z << ")\n";
  EXPECT_FALSE(null.named) << null.verdict << " " << null.value;
  // One scan (or masked copies of one) is no pair: not identifiable.
  const auto one = recording(0, 300, 1);
  EXPECT_EQ(fitGlint({one[0], one[0]}, sim::SensorConfig{}, drive(0)).verdict, "not identifiable");
  // Scans spread over the route (every 40th, as the appearance reference renders) are no pairs.
  sim::Scene sc = sim::builtinScene("out_and_back");
  sim::Simulator s(std::move(sc.world), std::move(sc.trajectory), sim::SensorConfig{}, drive(0.3), 7);
  const std::vector<PolarScan> spread = {s.renderScan(100), s.renderScan(140), s.renderScan(180)};
  EXPECT_EQ(measureMatchedSpread(spread).pairs, 0);
  EXPECT_FALSE(fitGlint(spread, sim::SensorConfig{}, drive(0)).named);
}

}  // namespace
}  // namespace spinradar::diagnose
