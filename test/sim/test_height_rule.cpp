// The height rule (src/sim/height_rule.hpp): walls and targets with a "height", a sensor
// mount_height. Known truth: a target of height h at range r behind a wall of top H crossing its
// line of sight at d < r is seen iff (h - h_s) d > (H - h_s) r. Without heights the renderer is
// the plain depth map, byte for byte; the scenes "city_facades_heights" / "city_heights".
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <optional>

#include <nlohmann/json.hpp>

#include "sim_test_util.hpp"
#include "spinradar/sim/scenes.hpp"

using namespace spinradar;
using namespace spinradar::sim;
using namespace spinradar::sim::testing;

namespace {

// A 10 m wall across the forward axis at distance d, and a strong point target straight ahead
// at range r behind it. The sensor stands still at the origin.
World wallAndTarget(double d, std::optional<double> wall_h, double r, std::optional<double> target_h,
                    bool with_target = true) {
  World w;
  w.walls.push_back({d, -5, d, 5, 2.0});
  w.walls[0].height = wall_h;
  if (with_target) {
    w.targets.push_back({r, 0, 25.0, 0, 0});
    w.targets[0].height = target_h;
  }
  return w;
}

PolarScan render(const World& w, double mount_height = 2.0) {
  SensorConfig s;
  s.mount_height = mount_height;
  Simulator sim(w, constantMotion(0, 0), s, PhysicsConfig{}, 3);
  return sim.renderScan(2);
}

int binOf(double r, double res) { return int(std::lround(r / res - 0.5)); }

// Seen: the scan differs from the one without the target, with a peak at its azimuth and range
// well above the noise there. Hidden: the scan is the one without it, byte for byte (the noise
// does not depend on the scatterers, so any leak would show).
enum class Seen { kYes, kNo, kBroken };
Seen seen(double d, std::optional<double> wall_h, double r, double h, double h_s = 2.0) {
  const PolarScan with = render(wallAndTarget(d, wall_h, r, h), h_s);
  const PolarScan without = render(wallAndTarget(d, wall_h, r, h, false), h_s);
  if (with.power == without.power) return Seen::kNo;
  const double res = with.range_resolution;
  const int b = binOf(r, res);
  const Peak p = findPeak(with, 0, -1, b - 40, b + 40), noise = findPeak(without, 0, -1, b - 40, b + 40);
  const bool at_target = std::min(p.azimuth, with.azimuths - p.azimuth) <= 1 &&
                         std::abs(p.fine_bin - (r / res - 0.5)) < 1.0 && p.value > noise.value + 20;
  return at_target ? Seen::kYes : Seen::kBroken;
}

}  // namespace

// A parked car (1.5 m) in front of a 2 m antenna: a target on the ground far enough behind it
// is below the line over its roof only within r < 4 d; a 1.5 m target behind it always shows.
TEST(SimHeightRule, LowWallHidesOnlyWhatIsBelowTheLine) {
  EXPECT_EQ(seen(20, 1.5, 30, 0.0), Seen::kNo);    // ground: -2 * 20 > -0.5 * 30 is false
  EXPECT_EQ(seen(20, 1.5, 30, 1.5), Seen::kYes);   // -0.5 * 20 > -0.5 * 30
  EXPECT_EQ(seen(8, 1.5, 40, 0.0), Seen::kYes);    // ground beyond 4 d: -16 > -20
  EXPECT_EQ(seen(8, 1.5, 28, 0.0), Seen::kNo);     // ground within 4 d: -16 > -14 is false
}

// A tall wall: the target must rise above h* = h_s + (H - h_s) r / d; the boundary follows the
// formula over several geometries (0.3 m either side).
TEST(SimHeightRule, BoundaryFollowsTheFormula) {
  struct G {
    double d, H, r;
  };
  for (const G g : {G{20, 10, 30}, G{10, 6, 45}, G{25, 3, 60}, G{15, 12, 20}}) {
    const double h_star = 2.0 + (g.H - 2.0) * g.r / g.d;
    EXPECT_EQ(seen(g.d, g.H, g.r, h_star + 0.3), Seen::kYes) << g.d << " " << g.H << " " << g.r;
    EXPECT_EQ(seen(g.d, g.H, g.r, h_star - 0.3), Seen::kNo) << g.d << " " << g.H << " " << g.r;
  }
}

// The antenna's height is the sensor's mount_height: raised to 20 m it sees a 13.5 m target
// over a 10 m wall that hides it from 2 m ((13.5 - 20) 20 > (10 - 20) 30).
TEST(SimHeightRule, MountHeightIsTheSensors) {
  EXPECT_EQ(seen(20, 10, 30, 13.5, 2.0), Seen::kNo);
  EXPECT_EQ(seen(20, 10, 30, 13.5, 20.0), Seen::kYes);
}

// A wall without a height is infinitely tall: it hides a target of any height, as before.
TEST(SimHeightRule, WallWithoutHeightHidesEverything) {
  EXPECT_EQ(seen(20, std::nullopt, 30, 900.0), Seen::kNo);
  EXPECT_EQ(seen(20, std::nullopt, 30, 0.0), Seen::kNo);
}

// Walls behind walls: a 20 m building shows over a 5 m one in front ((20-2)/30 > (5-2)/20), a
// 6 m one does not ((6-2)/30 < 3/20); the front wall is the same either way.
TEST(SimHeightRule, WallBehindALowerWall) {
  auto scan = [](std::optional<double> back_h, bool with_back) {
    World w;
    w.walls.push_back({20, -5, 20, 5, 2.0});
    w.walls[0].height = 5.0;
    if (with_back) {
      w.walls.push_back({30, -6, 30, 6, 6.0});  // narrower in angle than the front wall
      w.walls[1].height = back_h;
    }
    return render(w);
  };
  const PolarScan front = scan(std::nullopt, false), low = scan(6.0, true), high = scan(20.0, true);
  EXPECT_EQ(low.power, front.power);
  const int b = binOf(30, front.range_resolution);
  EXPECT_GT(findPeak(high, 0, 2, b - 20, b + 20).value, findPeak(front, 0, 2, b - 20, b + 20).value + 20);
  const int b20 = binOf(20, front.range_resolution);
  EXPECT_EQ(findPeak(high, 0, 2, b20 - 10, b20 + 10).value, findPeak(front, 0, 2, b20 - 10, b20 + 10).value);
}

// Defaults: a world with a height key that changes nothing (targets on the ground, every wall
// without a height) runs the height rule and renders the built-in city exactly as the plain
// depth map does (the rule's skyline of infinitely tall walls is the first wall).
TEST(SimHeightRule, WithoutFiniteWallsTheRuleIsTheDepthMap) {
  const Scene sc = builtinScene("city_facades", 0);
  World grounded = sc.world;
  grounded.targets[0].height = 0.0;
  ASSERT_TRUE(grounded.hasHeights());
  ASSERT_FALSE(sc.world.hasHeights());
  SensorConfig s = SensorConfig::loadNamed("oxford");
  Simulator plain(sc.world, sc.trajectory, s, fullPhysics(), 5), rule(grounded, sc.trajectory, s, fullPhysics(), 5);
  for (int k : {100, 400})
    EXPECT_EQ(plain.renderScan(k).power, rule.renderScan(k).power) << "scan " << k;
}

// The same with multipath ghosts (their mirror-wall test) on a small street: two facades, a
// car between, point targets on both sides.
TEST(SimHeightRule, WithoutFiniteWallsGhostsAreTheDepthMaps) {
  World w;
  w.walls.push_back({-40, 8, 60, 8, 3.0});
  w.walls.push_back({60, -8, -40, -8, 3.0});
  w.walls.push_back({12, 4, 16, 4, 8.0});
  for (int k = 0; k < 12; ++k) w.targets.push_back({-20.0 + 7 * k, k % 2 ? 5.5 : -6.0, 12.0, 0, 0});
  w.targets.push_back({25, 12, 20.0, 0, 0});  // behind a facade
  World grounded = w;
  grounded.targets[3].height = 0.0;
  PhysicsConfig p = fullPhysics();
  p.extra["multipath"] = true;
  Simulator plain(w, constantMotion(8, 0.05), SensorConfig{}, p, 2), rule(grounded, constantMotion(8, 0.05), SensorConfig{}, p, 2);
  EXPECT_EQ(plain.renderScan(3).power, rule.renderScan(3).power);
}

// The world file: "height" written only when set (older worlds keep their bytes), read back;
// negative, NaN and non-number heights refused with the key named, in a file with the file's name.
TEST(SimHeightRule, WorldJson) {
  const World plain = wallAndTarget(20, std::nullopt, 30, std::nullopt), tall = wallAndTarget(20, 7.5, 30, 3.25);
  EXPECT_FALSE(plain.toJson()["targets"][0].contains("height"));
  EXPECT_FALSE(plain.toJson()["walls"][0].contains("height"));
  const World back = World::fromJson(tall.toJson());
  EXPECT_EQ(back.walls[0].height, 7.5);
  EXPECT_EQ(back.targets[0].height, 3.25);
  EXPECT_FALSE(World::fromJson(plain.toJson()).walls[0].height.has_value());
  for (const char* part : {"targets", "walls"})
    for (const nlohmann::json& v : {nlohmann::json(-1.0), nlohmann::json(std::numeric_limits<double>::quiet_NaN()),
                                    nlohmann::json("3"), nlohmann::json(2000.0)}) {
      nlohmann::json bad = tall.toJson();
      bad[part][0]["height"] = v;
      try {
        World::fromJson(bad);
        ADD_FAILURE() << part << " height " << v.dump() << " was accepted";
      } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("height"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
      }
    }
  const std::string path = ::testing::TempDir() + "height_rule_bad_world.json";
  {
    nlohmann::json bad = tall.toJson();
    bad["walls"][0]["height"] = -2.0;
    std::ofstream(path) << bad.dump();
  }
  try {
    World::load(path);
    ADD_FAILURE() << "negative wall height accepted from a file";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("height_rule_bad_world.json"), std::string::npos) << m;
    EXPECT_NE(m.find("height"), std::string::npos) << m;
  }
  std::remove(path.c_str());
}

// mount_height is a range-checked sensor parameter.
TEST(SimHeightRule, MountHeightRangeChecked) {
  EXPECT_THROW(SensorConfig::fromJson({{"mount_height", -1.0}}), std::runtime_error);
  EXPECT_THROW(SensorConfig::fromJson({{"mount_height", "2"}}), std::runtime_error);
  EXPECT_EQ(SensorConfig::fromJson({{"mount_height", 3.5}}).mount_height, 3.5);
  EXPECT_EQ(SensorConfig{}.mount_height, 2.0);
}

// The scenes: city_facades_heights is city_facades item for item (same places, strengths,
// walls) with heights; city_heights is city_elevated the same, heights in place of the flag.
// Buildings 7-16 m by their storeys, parked cars 1.5 m, everything appended has a height.
TEST(SimHeightRule, HeightScenesAreTheirFlatScenesWithHeights) {
  for (const auto& [flat_name, tall_name] : {std::pair{"city_facades", "city_facades_heights"},
                                            std::pair{"city_elevated", "city_heights"}}) {
    const Scene flat = builtinScene(flat_name, 1), tall = builtinScene(tall_name, 1);
    ASSERT_EQ(flat.world.walls.size(), tall.world.walls.size());
    ASSERT_EQ(flat.world.targets.size(), tall.world.targets.size());
    int cars = 0, buildings = 0;
    for (size_t i = 0; i < flat.world.walls.size(); ++i) {
      const Wall &a = flat.world.walls[i], &b = tall.world.walls[i];
      ASSERT_TRUE(a.x1 == b.x1 && a.y2 == b.y2 && a.rcs_per_m == b.rcs_per_m && !a.height && b.height) << i;
      const double len = std::hypot(b.x2 - b.x1, b.y2 - b.y1);
      if (*b.height == 1.5) {
        ++cars;
        EXPECT_LT(len, 6.0);
      } else {
        ++buildings;
        EXPECT_TRUE(*b.height >= 7.0 && *b.height <= 16.0) << *b.height;
      }
    }
    EXPECT_GT(cars, 100);
    EXPECT_GT(buildings, 200);
    size_t n_city = builtinScene("city", 1).world.targets.size();
    for (size_t i = 0; i < flat.world.targets.size(); ++i) {
      const Target &a = flat.world.targets[i], &b = tall.world.targets[i];
      ASSERT_TRUE(a.x == b.x && a.y == b.y && a.rcs == b.rcs && a.vx == b.vx && !b.elevated) << i;
      if (i >= n_city) {
        ASSERT_TRUE(b.height && *b.height > 0) << i;
      }
    }
  }
}
