// A sensor file's reference scene (reference_scene.hpp): the name check and the default rule.
#include "spinradar/sim/reference_scene.hpp"

#include <algorithm>
#include <stdexcept>

#include "spinradar/sim/scenes.hpp"

namespace spinradar::sim {

bool isBuiltinScene(const std::string& name) {
  const auto names = builtinSceneNames();
  return std::find(names.begin(), names.end(), name) != names.end();
}

void checkReferenceScene(const std::string& name) {
  if (isBuiltinScene(name)) return;
  std::string list;
  for (const auto& n : builtinSceneNames()) list += (list.empty() ? "" : ", ") + n;
  throw std::invalid_argument("'" + name + "' is not a built-in scene (" + list + ")");
}

std::string sceneOrReference(const std::string& given, const SensorConfig& sensor,
                             const std::string& fallback) {
  if (!given.empty()) return given;
  if (!sensor.reference_scene.empty()) return sensor.reference_scene;
  return fallback;
}

}  // namespace spinradar::sim
