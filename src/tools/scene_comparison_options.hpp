#pragma once
// The options `realism` and `spread` share: the real samples, built-in scenes and recording
// folders they put side by side, and the physics and sensor the scenes are simulated under.
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "spinradar/sim/physics.hpp"

namespace spinradar::cli {

struct SceneComparisonOptions {
  std::string realdata = "../shared/realdata";
  std::vector<std::string> scenes;  ///< the command sets its default
  std::vector<std::string> recordings;
  std::string physics, sensor;
  bool no_real = false;
};

inline void addSceneComparisonOptions(CLI::App& app, SceneComparisonOptions& o) {
  app.add_option("--realdata", o.realdata, "Folder of real samples")->capture_default_str();
  app.add_option("--scene", o.scenes, "Built-in scenes to simulate")->capture_default_str();
  app.add_option("--recording", o.recordings, "Extra recording folders");
  app.add_option("--physics", o.physics, "Physics JSON (default: distortion, Doppler, movers)");
  app.add_option("--sensor", o.sensor,
                 "Sensor: JSON file or calibrated name (oxford, mulran, boreas_rt, radiate)");
  app.add_flag("--no-real", o.no_real, "Compare simulations (and --recording folders) only");
}

/// The physics the scenes are simulated under: --physics, else motion distortion, Doppler
/// (beta 0.049 s) and moving objects, as the recordings the real samples are compared with.
inline sim::PhysicsConfig comparisonPhysics(const SceneComparisonOptions& o) {
  if (!o.physics.empty()) return sim::PhysicsConfig::load(o.physics);
  sim::PhysicsConfig physics;
  physics.moving_objects = true;
  physics.motion_distortion = true;
  physics.doppler = 0.049;
  return physics;
}

}  // namespace spinradar::cli
