// Heights for the city scenes (see city_heights.hpp).
#include "spinradar/sim/city_heights.hpp"

#include <vector>

#include "spinradar/sim/city_elevated.hpp"
#include "spinradar/sim/city_facades.hpp"
#include "spinradar/sim/city_layout.hpp"

namespace spinradar::sim::detail {

void addCityHeights(Scene& sc, uint64_t variant, bool elevated_structure, const CityHeights& p) {
  sc.name = elevated_structure ? "city_heights" : "city_facades_heights";
  sc.description += elevated_structure
                        ? "; facade detail, street furniture and the elevated structure, with heights: "
                          "each seen where it rises above the line of sight over what is in front"
                        : "; facade detail and street furniture, with heights: buildings by their "
                          "storeys, parked cars 1.5 m";
  World& w = sc.world;
  const CityLayout l;
  // The city's own targets: poles first, then the moving cars, then ground clutter and trees.
  const size_t n_city = w.targets.size();
  bool poles = true;
  for (size_t i = 0; i < n_city; ++i) {
    Target& t = w.targets[i];
    const bool mover = t.vx != 0 || t.vy != 0;
    poles = poles && !mover;
    if (poles) t.height = p.pole_m;
    if (mover) t.height = p.mover_m;
  }
  std::vector<double> tops;  // building height per wall index, 0 = not a building
  addFacadeDetail(w, variant, l.grid, l.pitch_m, FacadeDetail{}, &tops);
  for (size_t i = 0; i < tops.size(); ++i)
    if (tops[i] <= 0) w.walls[i].height = p.car_m;  // the city's only other walls: parked cars
  if (elevated_structure) addElevatedDetail(w, variant, l.grid, l.pitch_m, l.half_street_m, ElevatedDetail{}, &tops);
}

}  // namespace spinradar::sim::detail
