// Elevated targets (Target::elevated, src/sim/render_scan.cpp): seen over walls, which the 2-D
// depth map otherwise lets hide everything behind the first wall hit; and the "city_elevated"
// scene that uses them (city_elevated.hpp). Known truth: a wall between the sensor and a target.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "sim_test_util.hpp"
#include "spinradar/sim/scenes.hpp"

using namespace spinradar;
using namespace spinradar::sim;
using namespace spinradar::sim::testing;

namespace {

// A 10 m wall across the sensor's forward axis at 20 m, and a strong point target behind it at
// 30 m straight ahead (sensor azimuth 0). The sensor stands still at the origin.
World wallAndTarget(bool elevated, bool with_target = true) {
  World w;
  w.walls.push_back({20, -5, 20, 5, 2.0});
  if (with_target) {
    Target t{30, 0, 25.0, 0, 0};
    t.elevated = elevated;
    w.targets.push_back(t);
  }
  return w;
}

PolarScan render(const World& w) {
  Simulator sim(w, constantMotion(0, 0), SensorConfig{}, PhysicsConfig{}, 3);
  return sim.renderScan(2);
}

int binOf(double r, double res) { return int(std::lround(r / res - 0.5)); }  // nearest bin centre

}  // namespace

// Without the flag the target behind the wall leaves no trace: the scan is the wall's alone,
// byte for byte (the noise does not depend on the scatterers, so any leak would show).
TEST(SimElevated, HiddenBehindAWallWithoutTheFlag) {
  const PolarScan hidden = render(wallAndTarget(false)), wall_only = render(wallAndTarget(false, false));
  EXPECT_EQ(hidden.power, wall_only.power);
}

// With the flag the same target shows at its true range bin and azimuth, well above the noise,
// and the wall in front of it is still there.
TEST(SimElevated, SeenOverTheWallWithTheFlag) {
  const PolarScan seen = render(wallAndTarget(true)), wall_only = render(wallAndTarget(false, false));
  const double res = seen.range_resolution;
  const int b30 = binOf(30.0, res), b20 = binOf(20.0, res);
  const Peak p = findPeak(seen, 0, -1, b30 - 40, b30 + 40);
  const int n = seen.azimuths;
  EXPECT_LE(std::min(p.azimuth, n - p.azimuth), 1) << "azimuth " << p.azimuth;
  EXPECT_NEAR(p.fine_bin, 30.0 / res - 0.5, 1.0);
  const Peak noise = findPeak(wall_only, 0, -1, b30 - 40, b30 + 40);
  EXPECT_GT(p.value, noise.value + 20) << "target " << p.value << " against the noise's " << noise.value;
  const Peak wall = findPeak(seen, 0, -1, b20 - 20, b20 + 20);
  EXPECT_EQ(wall.value, findPeak(wall_only, 0, -1, b20 - 20, b20 + 20).value);
}

// In the open the flag changes nothing: it only lifts the occlusion.
TEST(SimElevated, NoEffectWithoutAWall) {
  World a = oneTarget(30, 0), b = oneTarget(30, 0);
  b.targets[0].elevated = true;
  EXPECT_EQ(render(a).power, render(b).power);
}

// The world file: "elevated" is written only when set (older worlds keep their bytes), read
// back, and anything but a boolean is refused with the key in the message.
TEST(SimElevated, WorldJson) {
  const World plain = wallAndTarget(false), lifted = wallAndTarget(true);
  EXPECT_FALSE(plain.toJson()["targets"][0].contains("elevated"));
  EXPECT_EQ(lifted.toJson()["targets"][0]["elevated"], true);
  EXPECT_TRUE(World::fromJson(lifted.toJson()).targets[0].elevated);
  EXPECT_FALSE(World::fromJson(plain.toJson()).targets[0].elevated);
  nlohmann::json bad = lifted.toJson();
  bad["targets"][0]["elevated"] = 1;
  try {
    World::fromJson(bad);
    FAIL() << "a numeric 'elevated' was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("elevated"), std::string::npos) << e.what();
  }
}

// "city_elevated" is "city_facades" target for target and wall for wall, plus appended targets
// that are all elevated; city_facades itself has none.
TEST(SimElevated, CityElevatedExtendsCityFacades) {
  for (uint64_t variant : {0, 1}) {
    const Scene f = builtinScene("city_facades", variant), e = builtinScene("city_elevated", variant);
    ASSERT_EQ(f.world.walls.size(), e.world.walls.size());
    ASSERT_GT(e.world.targets.size(), f.world.targets.size() + 1000);
    for (size_t i = 0; i < f.world.targets.size(); ++i) {
      const Target &a = f.world.targets[i], &b = e.world.targets[i];
      ASSERT_TRUE(a.x == b.x && a.y == b.y && a.rcs == b.rcs && a.vx == b.vx && !a.elevated && !b.elevated) << i;
    }
    for (size_t i = f.world.targets.size(); i < e.world.targets.size(); ++i)
      ASSERT_TRUE(e.world.targets[i].elevated) << i;
    EXPECT_EQ(e.trajectory.samples().size(), f.trajectory.samples().size());
  }
}
