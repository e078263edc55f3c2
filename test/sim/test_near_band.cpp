// Where the simulated 2.5-10 m Cen2018 keypoints come from (issue 20): with the calibrated Oxford
// model the receiver noise there gives none; a wall along the street gives about one per azimuth
// row that sees it within 10 m, so the band's count follows the scene's street width (one
// wall at 4 m vs 8 m), not the noise model or the returns' level.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "sim_test_util.hpp"
#include "spinradar/sim/realism.hpp"

namespace spinradar::sim {
namespace {

SensorConfig oxford() {
  return SensorConfig::load(std::string(SPINRADAR_SOURCE_DIR) + "/config/sensors/oxford.json");
}

// A wall parallel to the drive at `lateral` m on the left (rcs per metre as the city scene's).
World streetWall(double lateral) {
  World w;
  if (lateral > 0) w.walls.push_back({-60.0, lateral, 60.0, lateral, 1.0});
  return w;
}

double nearCen2018(const World& w, const SensorConfig& s) {
  Simulator sim(w, testing::constantMotion(1.0, 0.0, {}, 1.0), s, PhysicsConfig{}, 7);
  return computeRealism({sim.renderScan(1)}, "near").band_cen[0];  // 2.5-10 m
}

TEST(NearBand, NoiseGivesNoCen2018Keypoints) {
  EXPECT_LT(nearCen2018(World{}, oxford()), 3.0);
}

TEST(NearBand, StreetWallSetsTheCount) {
  const SensorConfig s = oxford();
  // Rows (of 400) that see the wall within 10 m: 2 acos(d / 10) of 360 deg.
  auto rows = [](double d) { return 400.0 * 2.0 * std::acos(d / 10.0) / (2.0 * M_PI); };
  const double at4 = nearCen2018(streetWall(4.0), s), at8 = nearCen2018(streetWall(8.0), s);
  for (const auto& [d, n] : {std::pair{4.0, at4}, std::pair{8.0, at8}}) {  // 147 and 82 rows
    EXPECT_GT(n, 0.8 * rows(d)) << d << " m: " << n;
    EXPECT_LT(n, 1.35 * rows(d)) << d << " m: " << n;
  }
  EXPECT_GT(at4 - at8, 40.0) << at4 << " vs " << at8;
  // 40 dB dimmer returns at 5 and 16 m still leave most of them (the wall is far above the
  // row's threshold at 4-10 m).
  SensorConfig dim = s;
  dim.return_gain_db_5m = dim.return_gain_db_16m = -40.0;
  EXPECT_GT(nearCen2018(streetWall(4.0), dim), 0.5 * at4);
}

}  // namespace
}  // namespace spinradar::sim
