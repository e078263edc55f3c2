#include "spinradar/sim/sensor_config.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <type_traits>

#include <nlohmann/json.hpp>

#include "file_errors.hpp"
#include "spinradar/sim/physics.hpp"
#include "spinradar/sim/reference_scene.hpp"
#include "spinradar/core/param_check.hpp"

namespace spinradar::sim {

void SensorConfig::validate() const {
  checkParamRanges(*this, "sensor");
  if (bins > (1 << 18) - 1024)
    throw std::invalid_argument("sensor parameter 'bins' is too large for the speckle table");
  if (encoder_size < azimuths)
    throw std::invalid_argument("sensor parameter 'encoder_size' must be at least 'azimuths'");
  if (!reference_scene.empty()) {
    try {
      checkReferenceScene(reference_scene);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("sensor key 'reference_scene': ") + e.what());
    }
  }
}

void SensorConfig::curveWeights(double r, double w[4]) {
  for (int k = 0; k < 4; ++k) w[k] = 0;
  if (r <= kCurveNodes[0]) {
    w[0] = 1;
    return;
  }
  for (int k = 0; k < 3; ++k)
    if (r < kCurveNodes[k + 1]) {
      const double t = std::log(r / kCurveNodes[k]) / std::log(kCurveNodes[k + 1] / kCurveNodes[k]);
      w[k] = 1 - t, w[k + 1] = t;
      return;
    }
  w[3] = 1;
}

namespace {
double curveAt(double r, double a, double b, double c, double d) {
  double w[4];
  SensorConfig::curveWeights(r, w);
  return w[0] * a + w[1] * b + w[2] * c + w[3] * d;
}
}  // namespace

double SensorConfig::stcCurveDb(double r) const {
  return curveAt(r, stc_curve_db_5m, stc_curve_db_16m, stc_curve_db_35m, stc_curve_db_71m);
}
double SensorConfig::returnGainDb(double r) const {
  const double g = curveAt(r, return_gain_db_5m, return_gain_db_16m, return_gain_db_35m, return_gain_db_71m);
  // Beyond the last node the curve is flat unless the far slope is set (0: exactly as before).
  if (return_far_slope_db_per_decade == 0 || r <= kCurveNodes[3]) return g;
  return g + return_far_slope_db_per_decade * std::log10(r / kCurveNodes[3]);
}
double SensorConfig::clutterDensityX(double r) const {
  return curveAt(r, clutter_density_x_5m, clutter_density_x_16m, clutter_density_x_35m,
                 clutter_density_x_71m);
}
double SensorConfig::clutterDensityXMax() const {
  return std::max({clutter_density_x_5m, clutter_density_x_16m, clutter_density_x_35m,
                   clutter_density_x_71m});
}
bool SensorConfig::hasRangeCurves() const {
  for (double v : {stc_curve_db_5m, stc_curve_db_16m, stc_curve_db_35m, stc_curve_db_71m,
                   return_gain_db_5m, return_gain_db_16m, return_gain_db_35m, return_gain_db_71m,
                   return_far_slope_db_per_decade})
    if (v != 0) return true;
  for (double v : {clutter_density_x_5m, clutter_density_x_16m, clutter_density_x_35m,
                   clutter_density_x_71m})
    if (v != 1) return true;
  return false;
}

nlohmann::json SensorConfig::toJson() const {
  nlohmann::json j = nlohmann::json::object();
  visit([&](const ParamMeta& m, const auto& v) { j[m.name] = v; });
  if (!physics.empty()) j["physics"] = physics;
  // Only when set, as "physics": a file without the key is written back without it.
  if (!reference_scene.empty()) j["reference_scene"] = reference_scene;
  return j;
}

SensorConfig SensorConfig::fromJson(const nlohmann::json& j) {
  if (!j.is_object()) throw detail::JsonPathError({}, "sensor configuration must be a JSON object");
  SensorConfig c;
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (it.key() == "physics") {
      c.physics = sensorPhysicsFromJson(*it);
      continue;
    }
    if (it.key() == "reference_scene") {
      if (!it->is_string())
        throw detail::JsonPathError({{"reference_scene", -1}}, "must be a built-in scene name (a string)");
      c.reference_scene = it->get<std::string>();
      try {
        checkReferenceScene(c.reference_scene);
      } catch (const std::invalid_argument& e) {
        throw detail::JsonPathError({{"reference_scene", -1}}, e.what());
      }
      continue;
    }
    bool found = false;
    c.visit([&](const ParamMeta& m, auto& v) {
      if (it.key() != m.name) return;
      found = true;
      using T = std::decay_t<decltype(v)>;
      if constexpr (std::is_same_v<T, bool>) {
        if (!it->is_boolean()) throw detail::JsonPathError({{m.name, -1}}, "must be true or false");
        v = it->template get<bool>();
      } else if constexpr (std::is_arithmetic_v<T>) {
        if (!it->is_number()) throw detail::JsonPathError({{m.name, -1}}, "must be a number");
        v = it->template get<T>();
        if (v < m.min || v > m.max)
          throw detail::JsonPathError({{m.name, -1}}, "value outside [" + std::to_string(m.min) +
                                                          ", " + std::to_string(m.max) + "]");
      } else {
        if (!it->is_string()) throw detail::JsonPathError({{m.name, -1}}, "must be a string");
        v = it->template get<std::string>();
      }
    });
    if (!found) throw detail::JsonPathError({{it.key(), -1}}, "unknown sensor parameter");
  }
  try {
    c.validate();
  } catch (const std::invalid_argument& e) {
    throw detail::JsonPathError({}, e.what());
  }
  return c;
}

SensorConfig SensorConfig::load(const std::string& path) {
  return detail::loadJsonFile<SensorConfig>(path);
}

namespace {

std::vector<std::string> sensorDirs() {
  std::vector<std::string> dirs;
  if (const char* e = std::getenv("SPINRADAR_SENSORS_DIR")) dirs.emplace_back(e);
#ifdef SPINRADAR_SENSORS_DIR
  dirs.emplace_back(SPINRADAR_SENSORS_DIR);
#endif
  return dirs;
}

}  // namespace

std::vector<std::string> SensorConfig::namedSensors() {
  namespace fs = std::filesystem;
  std::vector<std::string> names;
  for (const auto& d : sensorDirs()) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(d, ec))
      if (e.path().extension() == ".json") names.push_back(e.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());
  return names;
}

SensorConfig SensorConfig::loadNamed(const std::string& arg) {
  namespace fs = std::filesystem;
  if (fs::exists(arg)) return load(arg);
  if (arg.find('/') == std::string::npos && arg.find('.') == std::string::npos)
    for (const auto& d : sensorDirs()) {
      fs::path p = fs::path(d) / (arg + ".json");
      if (fs::exists(p)) return load(p.string());
    }
  std::string known;
  for (const auto& n : namedSensors()) known += (known.empty() ? "" : ", ") + n;
  throw std::runtime_error(arg + ": no such sensor file, and not a calibrated sensor name (" +
                           (known.empty() ? "none found" : known) + ")");
}

void SensorConfig::save(const std::string& path) const { detail::saveJsonFile(*this, path); }

}  // namespace spinradar::sim
