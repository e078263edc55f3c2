#pragma once
// The three base scenes of the simulator (scenes.cpp); scene_catalogue.cpp names them and
// builds the city's variants on city() (private to the simulator part).
#include <cstdint>

#include "spinradar/sim/city_layout.hpp"
#include "spinradar/sim/scenes.hpp"

namespace spinradar::sim::detail {

/// The city route through a street grid; L's defaults are the scene `city` (city_layout.hpp).
Scene city(uint64_t variant, double t0, const CityLayout& L = {});
/// A straight 1 km road driven out, a U-turn, and back on the other lane.
Scene outAndBack(uint64_t variant, double t0);
/// An open yard: slalom and loops at 3-8 m/s, yaw rates up to about 1 rad/s.
Scene tightTurns(uint64_t variant, double t0);

}  // namespace spinradar::sim::detail
