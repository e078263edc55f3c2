// Physics configuration: effect name -> value, absent meaning off.
#include "spinradar/sim/physics.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>

#include "file_errors.hpp"

namespace spinradar::sim {

using detail::JsonPathError;

namespace {

double num(const nlohmann::json& v, const char* key, double lo, double hi) {
  if (!v.is_number()) throw JsonPathError({{key, -1}}, "must be a number");
  double d = v.get<double>();
  if (!std::isfinite(d) || d < lo || d > hi)
    throw JsonPathError({{key, -1}}, "value " + std::to_string(d) + " outside [" +
                                         std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return d;
}

bool flag(const nlohmann::json& v, const char* key) {
  if (v.is_boolean()) return v.get<bool>();
  if (v.is_number()) return v.get<double>() != 0;
  throw JsonPathError({{key, -1}}, "must be true or false");
}

bool isOn(const nlohmann::json& v) {
  if (v.is_null()) return false;
  if (v.is_boolean()) return v.get<bool>();
  if (v.is_number()) return v.get<double>() != 0;
  return true;  // objects/strings configure an effect that is on
}

// Checks the simulator's own extra effects; an unknown key (a misspelt "dopler") is an error,
// as in the sensor JSON, rather than an effect silently left out.
void checkExtra(const std::string& key, const nlohmann::json& v) {
  const char* k = key.c_str();
  if (key == "stamp_bursts") {
    if (v.is_object()) {
      for (auto it = v.begin(); it != v.end(); ++it) {
        if (it.key() != "size" && it.key() != "spacing" && it.key() != "delay")
          throw JsonPathError({{k, -1}, {it.key(), -1}},
                              "unknown field (expected size, spacing, delay)");
        if (!it->is_number()) throw JsonPathError({{k, -1}, {it.key(), -1}}, "must be a number");
      }
      if (v.contains("size") && v["size"].get<double>() < 1)
        throw JsonPathError({{k, -1}, {"size", -1}}, "must be at least 1");
    } else {
      flag(v, k);
    }
  } else if (key == "rotation_jitter") {
    num(v, k, 0.0, 0.2);
  } else if (key == "multipath") {
    if (!v.is_boolean()) num(v, k, -80.0, 0.0);
  } else if (key == "attenuation") {
    num(v, k, 0.0, 1000.0);
  } else if (key == "encoder_wobble") {
    num(v, k, -0.1, 0.1);
  } else if (key == "glint" || key == "glint_across" || key == "glint_along") {
    num(v, k, 0.0, 5.0);
  } else if (key == "azimuth_jitter") {
    num(v, k, 0.0, 5.0);
  } else if (key == "chirp_alternate") {
    flag(v, k);
  } else if (key == "scan_pose_time") {
    if (!v.is_string() || (v != "mid" && v != "start"))
      throw JsonPathError({{k, -1}}, "must be \"mid\" or \"start\"");
  } else {
    throw JsonPathError({{k, -1}},
                        "unknown effect (expected motion_distortion, doppler, timestamp_offset, "
                        "azimuth_offset, range_offset, moving_objects, stamp_bursts, "
                        "rotation_jitter, multipath, attenuation, encoder_wobble, "
                        "chirp_alternate, scan_pose_time, glint, glint_across, glint_along, "
                        "azimuth_jitter)");
  }
}

}  // namespace

PhysicsConfig PhysicsConfig::fromJson(const nlohmann::json& j) {
  if (!j.is_object()) throw JsonPathError({}, "physics configuration must be a JSON object");
  PhysicsConfig p;
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string& key = it.key();
    const nlohmann::json& v = *it;
    if (v.is_null()) continue;  // explicit null = off
    if (key == "motion_distortion") {
      p.motion_distortion = flag(v, "motion_distortion");
    } else if (key == "doppler") {
      // true = the CIR204-H's beta; a number is beta itself (s).
      p.doppler = v.is_boolean() ? (v.get<bool>() ? 0.049 : 0.0) : num(v, "doppler", -1.0, 1.0);
    } else if (key == "timestamp_offset") {
      p.timestamp_offset = num(v, "timestamp_offset", -10.0, 10.0);
    } else if (key == "azimuth_offset") {
      p.azimuth_offset = num(v, "azimuth_offset", -M_PI, M_PI);
    } else if (key == "range_offset") {
      p.range_offset = num(v, "range_offset", -50.0, 50.0);
    } else if (key == "moving_objects") {
      p.moving_objects = flag(v, "moving_objects");
    } else {
      checkExtra(key, v);
      p.extra[key] = v;
    }
  }
  return p;
}

nlohmann::json PhysicsConfig::toJson() const {
  nlohmann::json j = nlohmann::json::object();
  if (motion_distortion) j["motion_distortion"] = true;
  if (doppler != 0) j["doppler"] = doppler;
  if (timestamp_offset != 0) j["timestamp_offset"] = timestamp_offset;
  if (azimuth_offset != 0) j["azimuth_offset"] = azimuth_offset;
  if (range_offset != 0) j["range_offset"] = range_offset;
  if (moving_objects) j["moving_objects"] = true;
  for (auto it = extra.begin(); it != extra.end(); ++it)
    if (isOn(*it)) j[it.key()] = *it;
  return j;
}

PhysicsConfig PhysicsConfig::load(const std::string& path) {
  return detail::loadJsonFile<PhysicsConfig>(path);
}

void PhysicsConfig::save(const std::string& path) const { detail::saveJsonFile(*this, path); }

std::vector<std::string> PhysicsConfig::activeEffects() const {
  std::vector<std::string> out;
  if (motion_distortion) out.push_back("motion_distortion");
  if (doppler != 0) out.push_back("doppler");
  if (timestamp_offset != 0) out.push_back("timestamp_offset");
  if (azimuth_offset != 0) out.push_back("azimuth_offset");
  if (range_offset != 0) out.push_back("range_offset");
  if (moving_objects) out.push_back("moving_objects");
  for (auto it = extra.begin(); it != extra.end(); ++it)
    if (isOn(*it)) out.push_back(it.key());
  return out;
}

PhysicsConfig PhysicsConfig::withSensorPhysics(const std::map<std::string, double>& sp) const {
  PhysicsConfig p = *this;
  for (const auto& [key, value] : sp)
    if (!p.extra.contains(key)) p.extra[key] = value;
  return p;
}

const std::vector<std::string> kSensorPhysicsKeys = {"glint", "glint_across", "glint_along",
                                                     "azimuth_jitter"};

std::map<std::string, double> sensorPhysicsFromJson(const nlohmann::json& j) {
  if (!j.is_object()) throw JsonPathError({{"physics", -1}}, "must be a JSON object");
  std::map<std::string, double> out;
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string& key = it.key();
    if (std::find(kSensorPhysicsKeys.begin(), kSensorPhysicsKeys.end(), key) == kSensorPhysicsKeys.end())
      throw JsonPathError({{"physics", -1}, {key, -1}},
                          "not a sensor physics key (expected glint, glint_across, glint_along, "
                          "azimuth_jitter)");
    try {
      checkExtra(key, *it);
    } catch (const JsonPathError& e) {
      throw JsonPathError({{"physics", -1}, {key, -1}}, e.reason);
    }
    out[key] = it->get<double>();
  }
  return out;
}

}  // namespace spinradar::sim
