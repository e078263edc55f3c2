#pragma once
// Built-in scenes: a world and a sensor trajectory through it, by name, so that nothing has to
// be written by hand to get started.
//   "city"         grid of blocks with facades, poles, parked and moving cars; a ~3 min route
//                  with turns at intersections and speeds up to 15 m/s
//   "city_facades" the same city (scatterer for scatterer, same route) plus facade detail and
//                  street furniture: point scatterers that stay bright at grazing incidence,
//                  the far structure of real streets (docs/city_scene_far_structure.md)
//   "city_elevated" city_facades (target for target) plus elevated targets seen over the first
//                  row of buildings: roof edges, rooftop plant, upper storeys, tree crowns
//                  (docs/diagnose_elevated_structure.md)
//   "city_facades_heights" city_facades item for item with heights (buildings by storeys,
//                  parked cars 1.5 m): the renderer's height rule instead of walls that hide
//                  everything (docs/diagnose_height_visibility.md, city_heights.hpp)
//   "city_heights" city_facades_heights plus city_elevated's structure with heights instead of
//                  the "elevated" flag
//   "city_open"    city_facades' detail on a more open street grid (city_layout.hpp)
//   "out_and_back" a straight 1 km road with roadside structures, driven out at 10-20 m/s,
//                  U-turn, and back on the other lane
//   "tight_turns"  an open yard with poles, containers and walls; slalom and tight loops
//                  (yaw rates up to ~1 rad/s) at 3-8 m/s
// Turns ease in and out: the yaw rate ramps at kSceneYawAccel, never steps.
#include <cstdint>
#include <string>
#include <vector>

#include "spinradar/sim/scene.hpp"

namespace spinradar::sim {

/// Largest yaw acceleration of the built-in routes (rad/s^2): a 0.6 rad/s city turn eases in
/// over 0.6 s, a 1 rad/s loop over 1 s (at 5 m/s about 500 deg/s at the steering wheel).
constexpr double kSceneYawAccel = 1.0;

struct Scene {
  std::string name;
  std::string description;
  World world;
  Trajectory trajectory;
};

/// Names accepted by builtinScene().
std::vector<std::string> builtinSceneNames();

/// The scene by name. `variant` changes the random layout details (object placement,
/// reflectivities) but not the street plan or route. `t0` is the trajectory start time (s).
/// Throws std::invalid_argument listing the valid names for an unknown name.
Scene builtinScene(const std::string& name, uint64_t variant = 0, double t0 = 0.0);

}  // namespace spinradar::sim
