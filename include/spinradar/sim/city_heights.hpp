#pragma once
// Heights for the city scenes (docs/diagnose_height_visibility.md): "city_facades_heights" is
// "city_facades" item for item with a height on every wall and on the items that stand up
// (buildings by their storeys, parked cars 1.5 m, poles, moving cars, facade detail, street
// furniture); "city_heights" adds city_elevated's structure (roof edges, upper storeys, rooftop
// plant, tree crowns) with heights instead of the blanket "elevated" flag. The renderer's height
// rule (src/sim/height_rule.hpp) then decides what a roof-mounted antenna sees over what: the
// parked cars stop hiding the facades behind them, and what stands behind the first row of
// buildings shows only where it rises above the line over that row. Ground clutter, the kerb
// trees' scatterers and the open land's trees stay unset (on the ground).
#include <cstdint>

#include "spinradar/sim/scenes.hpp"

namespace spinradar::sim::detail {

/// The heights of the city's own items (the rest are in FacadeDetail and ElevatedDetail).
struct CityHeights {
  double car_m = 1.5;    ///< parked cars (the city's 4.4 x 1.8 m boxes): under the antenna
  double pole_m = 4.0;   ///< lamp posts, sign posts (the city's first targets)
  double mover_m = 1.5;  ///< moving cars
};

/// Turns the "city" scene `sc` (as built, nothing added) into "city_facades_heights" or, with
/// `elevated_structure`, "city_heights": the facade detail (and the elevated structure) of
/// `variant` added with the same draws as city_facades (city_elevated), and the heights set.
void addCityHeights(Scene& sc, uint64_t variant, bool elevated_structure,
                    const CityHeights& p = CityHeights{});

}  // namespace spinradar::sim::detail
