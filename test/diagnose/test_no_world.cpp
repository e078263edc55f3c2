// Issue 10: diagnosis without a world file. The scene is mapped from the first half of the
// recording, the second half is diagnosed with the mapped positions refitted as nuisance.
#include <gtest/gtest.h>

#include "diagnose/diagnose_fixtures.hpp"

using namespace spinradar;
using namespace spinradar::diagnose;
using namespace spinradar::diagnose::testing;

namespace {

// 6 m/s with turns both ways and a speed change: viewpoints differ between map and test.
Drive loop() {
  return {{{1.0, 6.0, 0.0}, {1.5, 6.0, 0.4}, {1.0, 3.0, 0.0}, {1.5, 6.0, -0.4}}, {-5, 0, 0.0}};
}

DiagnoseReport run(const nlohmann::json& hidden, uint64_t seed) {
  const sim::World world = randomWorld(seed, 90, 55.0, false);
  const DiagnoseInput in =
      makeInput(world, loop(), sim::PhysicsConfig::fromJson(hidden), 16, seed);
  return diagnoseWithoutWorld(in, {}, "early-late");
}

TEST(NoWorld, DopplerNamedAndFittedWithin15Percent) {
  const DiagnoseReport rep = run({{"doppler", 0.049}}, 81);
  ASSERT_TRUE(rep.mismatch_found);
  EXPECT_EQ(rep.effects.front().name, "doppler");
  EXPECT_NEAR(rep.effects.front().value, 0.049, 0.15 * 0.049);
  EXPECT_NE(rep.scene_model.find("early-late"), std::string::npos);
}

TEST(NoWorld, NullDriveStaysClean) {
  for (uint64_t seed : {83u, 84u}) {
    const DiagnoseReport rep = run(nlohmann::json::object(), seed);
    EXPECT_FALSE(rep.mismatch_found) << "seed " << seed;
  }
}

}  // namespace
