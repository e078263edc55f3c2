#pragma once
// A calibrated sensor file's reference scene (file key "reference_scene"): the built-in scene
// its appearance was fitted in. A file's parameters are only "calibrated" in that scene: the
// Oxford fit of the height round takes 8 dB out of the 16 m returns because the facades behind
// 1.5 m parked cars show there, and the same file in a scene without heights renders far too
// dark (docs/diagnose_height_visibility.md). So the scene travels with the file, and the
// commands that render a sensor use it when the user names no scene.
#include <string>

#include "spinradar/sim/sensor_config.hpp"

namespace spinradar::sim {

/// True for a name builtinScene() accepts.
bool isBuiltinScene(const std::string& name);

/// Throws std::invalid_argument naming the scene and listing the built-in ones unless `name`
/// is a built-in scene ("recording" and "combined" of diagnose are not: they are the
/// recording's own returns, which a file cannot carry).
void checkReferenceScene(const std::string& name);

/// The scene a command renders: `given` (an explicit --scene always wins), else the sensor
/// file's reference scene, else `fallback` (the command's default before the key existed, so a
/// file without the key behaves exactly as before).
std::string sceneOrReference(const std::string& given, const SensorConfig& sensor,
                             const std::string& fallback);

}  // namespace spinradar::sim
