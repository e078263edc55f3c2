// Where the simulated 2.5-10 m Cen2018 keypoints come from (issue 20): with a calibrated Oxford
// model the receiver noise there gives none; a wall along the street gives about one per azimuth
// row that sees it within 10 m, so the band's count follows the scene's street width (one
// wall at 4 m vs 8 m), not the noise model or the returns' level.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>

#include "sim_test_util.hpp"
#include "spinradar/sim/realism.hpp"

namespace spinradar::sim {
namespace {

// The Oxford model of the first per-band calibration (config/sensors/oxford.json at commit
// 69ff318), kept here so that the test does not move with each recalibration.
SensorConfig oxford() {
  return SensorConfig::load(std::string(SPINRADAR_SOURCE_DIR) + "/test/sim/near_band_sensor.json");
}

// A wall parallel to the drive at `lateral` m on the left (rcs per metre as the city scene's).
World streetWall(double lateral) {
  World w;
  if (lateral > 0) w.walls.push_back({-60.0, lateral, 60.0, lateral, 1.0});
  return w;
}

RealismStats realism(const World& w, const SensorConfig& s) {
  Simulator sim(w, testing::constantMotion(1.0, 0.0, {}, 1.0), s, PhysicsConfig{}, 7);
  return computeRealism({sim.renderScan(1)}, "near");
}

double nearCen2018(const World& w, const SensorConfig& s) {
  return realism(w, s).band_cen[0];  // 2.5-10 m
}

// A street: walls along the drive at `left` m and `right` m.
World street(double left, double right) {
  World w;
  w.walls.push_back({-60.0, left, 60.0, left, 1.0});
  w.walls.push_back({-60.0, -right, 60.0, -right, 1.0});
  return w;
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

namespace spinradar::sim {
namespace {

// Why every 2.5-10 m figure is "scene-dependent, not fitted" in the appearance stage
// (diagnose::sceneDependentFigures): going from the reference city scene's street (walls at
// 4-8 m on both sides, here 6 | 6 m) to the Oxford sample's (one side 5.4-7.8 m, the other
// 10-12.5 m, here 6 | 11 m) moves each near-band figure by 40-70 %, more than twice what a 6 dB
// sensor change at the 5 m node does (mean 2.7x, the others 3.5-6x); at 10-25 m the Cen2018 count follows the sensor, not the
// street.
TEST(NearBand, NearFiguresFollowTheStreetNotTheSensor) {
  const SensorConfig s = oxford();
  SensorConfig noise = s, dim = s, noise16 = s;
  noise.stc_curve_db_5m += 6;      // receiver noise and returns 6 dB up at 5 m
  dim.return_gain_db_5m -= 6;      // returns 6 dB down at 5 m
  noise16.stc_curve_db_16m += 3;   // receiver 3 dB up at 16 m
  const RealismStats city = realism(street(6, 6), s), oxford = realism(street(6, 11), s),
                     up = realism(street(6, 6), noise), down = realism(street(6, 6), dim),
                     up16 = realism(street(6, 6), noise16);
  auto rel = [](double a, double b) { return std::abs(a - b) / b; };
  auto figures = [](const RealismStats& r, int k) {
    return std::array<double, 4>{r.band_mean[k], r.band_q90[k], r.band_cacfar[k], r.band_cen[k]};
  };
  const auto c = figures(city, 0), o = figures(oxford, 0), u = figures(up, 0), d = figures(down, 0);
  for (int i = 0; i < 4; ++i) {
    const double by_street = rel(o[i], c[i]), by_sensor = std::max(rel(u[i], c[i]), rel(d[i], c[i]));
    EXPECT_GT(by_street, 0.35) << "figure " << i << ": " << c[i] << " -> " << o[i];
    if (std::getenv("SPINRADAR_TEST_VERBOSE"))
      std::cerr << "near figure " << i << ": street " << by_street << ", sensor " << by_sensor << "\n";
    EXPECT_GT(by_street, 2 * by_sensor) << "figure " << i << ": street " << by_street
                                        << ", sensor " << by_sensor;
  }
  // 10-25 m Cen2018: the street moves it less than 15 %, 3 dB of receiver gain more.
  EXPECT_LT(rel(oxford.band_cen[1], city.band_cen[1]), 0.15);
  EXPECT_GT(rel(up16.band_cen[1], city.band_cen[1]), rel(oxford.band_cen[1], city.band_cen[1]));
}

}  // namespace
}  // namespace spinradar::sim
