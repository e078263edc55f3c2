// The built-in scenes by name (scenes.hpp): the three base scenes (base_scenes.hpp) and the
// city variants built on them (facade detail, elevated structure, heights, an open grid).
#include <stdexcept>
#include <string>
#include <vector>

#include "spinradar/sim/city_elevated.hpp"
#include "spinradar/sim/city_facades.hpp"
#include "spinradar/sim/city_heights.hpp"
#include "spinradar/sim/city_layout.hpp"
#include "spinradar/sim/scenes.hpp"
#include "base_scenes.hpp"

namespace spinradar::sim {

using detail::city;
using detail::outAndBack;
using detail::tightTurns;

std::vector<std::string> builtinSceneNames() {
  return {"city", "city_elevated", "city_facades", "city_facades_heights", "city_heights",
          "city_open", "out_and_back", "tight_turns"};
}

Scene builtinScene(const std::string& name, uint64_t variant, double t0) {
  if (name == "city") return city(variant, t0);
  if (name == "city_facades") {  // the city + far structure (city_facades.hpp)
    Scene sc = city(variant, t0);
    sc.name = name;
    sc.description += "; facade detail (window bays, doors, balconies, corners) and street "
                      "furniture as point scatterers";
    const detail::CityLayout l;
    detail::addFacadeDetail(sc.world, variant, l.grid, l.pitch_m);
    return sc;
  }
  if (name == "city_elevated") {  // city_facades + what is seen over its walls (city_elevated.hpp)
    Scene sc = builtinScene("city_facades", variant, t0);
    sc.name = name;
    sc.description += "; elevated structure seen over the first row of buildings (roof edges, "
                      "rooftop plant, upper storeys, tree crowns in the blocks)";
    const detail::CityLayout l;
    detail::addElevatedDetail(sc.world, variant, l.grid, l.pitch_m, l.half_street_m);
    return sc;
  }
  if (name == "city_heights" || name == "city_facades_heights") {  // heights (city_heights.hpp)
    Scene sc = city(variant, t0);
    detail::addCityHeights(sc, variant, name == "city_heights");
    return sc;
  }
  if (name == "city_open") {  // city_facades' detail on a more open street grid (city_layout.hpp)
    const detail::CityLayout l = detail::openCityLayout();
    Scene sc = city(variant, t0, l);
    sc.name = name;
    sc.description = "open street grid (" + std::to_string(int(l.pitch_m)) + " m pitch, " +
                     std::to_string(int(2 * l.half_street_m)) +
                     " m streets, buildings set back further and with wider gaps) with facade detail and "
                     "street furniture; the city's route, furniture and traffic";
    detail::FacadeDetail fd;
    const double s = l.half_street_m - 7.0;  // the furniture stays at the kerb
    fd.furniture_off_min_m += s, fd.furniture_off_max_m += s, fd.junction_clear_m += s;
    detail::addFacadeDetail(sc.world, variant, l.grid, l.pitch_m, fd);
    return sc;
  }
  if (name == "out_and_back") return outAndBack(variant, t0);
  if (name == "tight_turns") return tightTurns(variant, t0);
  std::string list;
  for (const auto& n : builtinSceneNames()) list += (list.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown scene '" + name + "' (built-in scenes: " + list + ")");
}

}  // namespace spinradar::sim
