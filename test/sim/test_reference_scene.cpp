// A sensor file's reference scene (key "reference_scene", include/spinradar/sim/reference_scene.hpp):
// parsed and range-checked against the built-in scene names, written back only when set, and
// the default-scene rule of simulate / serve / realism / diagnose. The CLI side (default scene
// used, an explicit --scene wins, diagnose writing the key) is test/tools/reference_scene.sh.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "spinradar/sim/reference_scene.hpp"
#include "spinradar/sim/scenes.hpp"
#include "spinradar/sim/sensor_config.hpp"

using namespace spinradar::sim;

namespace {

std::string errorOf(const nlohmann::json& j) {
  try {
    SensorConfig::fromJson(j);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// Every built-in scene is a valid reference scene, and it survives a JSON round trip.
TEST(SimReferenceScene, EveryBuiltinSceneRoundTrips) {
  for (const auto& name : builtinSceneNames()) {
    const SensorConfig c = SensorConfig::fromJson({{"reference_scene", name}});
    EXPECT_EQ(c.reference_scene, name);
    EXPECT_EQ(c.toJson().at("reference_scene"), name);
    EXPECT_EQ(SensorConfig::fromJson(c.toJson()).reference_scene, name);
    EXPECT_TRUE(isBuiltinScene(name));
  }
}

// Without the key nothing changes: no key written (a recording's sensor.json is as before),
// and the commands keep their own default.
TEST(SimReferenceScene, AbsentKeyIsNotWritten) {
  const SensorConfig plain;
  EXPECT_TRUE(plain.reference_scene.empty());
  EXPECT_FALSE(plain.toJson().contains("reference_scene"));
  const SensorConfig beam = SensorConfig::fromJson({{"beam_width_deg", 1.2}});
  EXPECT_FALSE(beam.toJson().contains("reference_scene"));
  EXPECT_EQ(sceneOrReference("", beam, "city"), "city");
  EXPECT_EQ(sceneOrReference("", beam, ""), "");
}

// An explicit scene always wins; else the file's; else the command's fallback.
TEST(SimReferenceScene, DefaultRule) {
  SensorConfig s;
  s.reference_scene = "city_heights";
  EXPECT_EQ(sceneOrReference("", s, "city"), "city_heights");
  EXPECT_EQ(sceneOrReference("city", s, "city"), "city");
  EXPECT_EQ(sceneOrReference("tight_turns", s, "city"), "tight_turns");
}

// A bad value is refused with the key and the reason; from a file, with the file's name and line.
TEST(SimReferenceScene, BadValuesRefused) {
  for (const nlohmann::json& v : {nlohmann::json("nowhere"), nlohmann::json(""), nlohmann::json("recording"),
                                  nlohmann::json("combined"), nlohmann::json("City"), nlohmann::json(3),
                                  nlohmann::json(nullptr), nlohmann::json::array({"city"})}) {
    const std::string m = errorOf({{"reference_scene", v}});
    ASSERT_FALSE(m.empty()) << v.dump() << " was accepted";
    EXPECT_NE(m.find("reference_scene"), std::string::npos) << m;
    if (v.is_string()) {
      EXPECT_NE(m.find("not a built-in scene"), std::string::npos) << m;
      EXPECT_NE(m.find("city_heights"), std::string::npos) << m;  // the valid names are listed
    } else {
      EXPECT_NE(m.find("must be a built-in scene name"), std::string::npos) << m;
    }
  }
  // A programmatic configuration is checked too.
  SensorConfig c;
  c.reference_scene = "nowhere";
  EXPECT_THROW(c.validate(), std::invalid_argument);

  const std::string path = ::testing::TempDir() + "reference_scene_bad_sensor.json";
  {
    std::ofstream f(path);
    f << "{\n \"beam_width_deg\": 1.2,\n \"reference_scene\": \"city_hieghts\"\n}\n";
  }
  try {
    SensorConfig::load(path);
    ADD_FAILURE() << "a misspelt reference scene was accepted from a file";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("reference_scene_bad_sensor.json:3"), std::string::npos) << m;
    EXPECT_NE(m.find("reference_scene"), std::string::npos) << m;
    EXPECT_NE(m.find("'city_hieghts' is not a built-in scene"), std::string::npos) << m;
  }
  std::remove(path.c_str());
}

// The shipped files: Oxford (docs/diagnose_height_visibility.md, H3) and MulRan
// (docs/mulran_heights_refit.md) were calibrated in city_heights, Boreas-RT and RADIATE in city.
TEST(SimReferenceScene, ShippedFiles) {
  const std::string dir = std::string(SPINRADAR_SOURCE_DIR) + "/config/sensors/";
  for (const char* n : {"oxford", "mulran"})
    EXPECT_EQ(SensorConfig::load(dir + n + ".json").reference_scene, "city_heights") << n;
  for (const char* n : {"boreas_rt", "radiate"})
    EXPECT_EQ(SensorConfig::load(dir + n + ".json").reference_scene, "city") << n;
}
