// Confounded effects: a stamp latency on a straight road at constant speed looks like a
// Doppler shift (both move returns along the track); the report must say the data cannot
// separate them and name the manoeuvre that would. With turns both ways the tie is broken.
#include <gtest/gtest.h>

#include "diagnose/diagnose_fixtures.hpp"

using namespace spinradar;
using namespace spinradar::diagnose;
using namespace spinradar::diagnose::testing;

namespace {

bool mentions(const DiagnoseReport& r, const std::string& a, const std::string& b) {
  for (const auto& n : r.notes)
    if (n.find(a) != std::string::npos && n.find(b) != std::string::npos) return true;
  return false;
}

TEST(Confounding, LatencyOnStraightRoadIsFlaggedAgainstDoppler) {
  for (uint64_t seed : {61u, 62u}) {
    const sim::World world = randomWorld(seed, 90, 55.0, false);
    const Drive drive{{{3.0, 10.0, 0.0}}, {-12, 0, 0.0}};
    sim::PhysicsConfig hidden;
    hidden.timestamp_offset = 0.03;
    const DiagnoseReport rep =
        spinradar::diagnose::diagnose(makeInput(world, drive, hidden, 4, seed));
    ASSERT_TRUE(rep.mismatch_found) << "seed " << seed;
    const auto& e = rep.effects.front();
    // Range residuals cannot tell them apart; the report says so and names the drive.
    EXPECT_TRUE(mentions(rep, "cannot be told apart", "doppler") ||
                mentions(rep, "cannot separate", "doppler"))
        << "seed " << seed;
    EXPECT_TRUE(mentions(rep, "doppler", "turns")) << "seed " << seed;
    EXPECT_EQ(e.name, "timestamp_offset");
    EXPECT_NEAR(e.value, 0.03, 0.003);
  }
}

TEST(Confounding, TurnsBothWaysSeparateLatencyFromDoppler) {
  const sim::World world = randomWorld(63, 90, 55.0, false);
  const Drive drive{{{0.8, 8.0, 0.0}, {1.0, 8.0, 0.35}, {1.0, 6.0, -0.35}}, {-5, 0, 0.0}};
  sim::PhysicsConfig hidden;
  hidden.timestamp_offset = 0.03;
  const DiagnoseReport rep = spinradar::diagnose::diagnose(makeInput(world, drive, hidden, 5, 63));
  ASSERT_TRUE(rep.mismatch_found);
  EXPECT_EQ(rep.effects.front().name, "timestamp_offset");
  EXPECT_TRUE(rep.effects.front().confounded_with.empty());
  EXPECT_NEAR(rep.effects.front().value, 0.03, 0.003);
}

// Two effects hidden at once whose range signatures oppose each other: switched on alone in the
// re-simulation each one raises the residual, together they remove it. Both must be reported.
TEST(Confounding, LatencyAndDopplerTogetherAreBothConfirmed) {
  for (uint64_t seed : {64u, 65u}) {
    const sim::World world = randomWorld(seed, 90, 55.0, false);
    const Drive drive{{{0.8, 8.0, 0.0}, {1.0, 8.0, 0.35}, {1.0, 6.0, -0.35}}, {-5, 0, 0.0}};
    sim::PhysicsConfig hidden;
    hidden.timestamp_offset = 0.03;
    hidden.doppler = 0.049;
    const DiagnoseReport rep =
        spinradar::diagnose::diagnose(makeInput(world, drive, hidden, 5, seed));
    ASSERT_TRUE(rep.mismatch_found) << "seed " << seed;
    double latency = 0, beta = 0;
    for (const auto& e : rep.effects) {
      if (e.name == "timestamp_offset") latency = e.value;
      if (e.name == "doppler") beta = e.value;
    }
    EXPECT_NEAR(latency, 0.03, 0.003) << "seed " << seed;
    EXPECT_NEAR(beta, 0.049, 0.0049) << "seed " << seed;
    EXPECT_LT(rep.after.position_rms, 0.5 * rep.before.position_rms) << "seed " << seed;
  }
}

}  // namespace
