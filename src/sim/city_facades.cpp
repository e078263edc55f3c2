// Facade detail of the "city_facades" scene (see city_facades.hpp).
#include "spinradar/sim/city_facades.hpp"

#include <algorithm>
#include <cmath>

#include "render_model.hpp"

namespace spinradar::sim::detail {

void addFacadeDetail(World& w, uint64_t variant, int grid, double pitch, const FacadeDetail& p,
                     std::vector<double>* building_heights) {
  Rng rng(0xFACADE00ull + variant);  // its own stream: the city's draws stay as they are
  auto uni = [&](double a, double b) { return a + (b - a) * rng.uniform(); };
  const size_t n_walls = w.walls.size();  // targets are appended, walls never
  double stack_db = 0;  // storeys of the current building (a box's four walls are consecutive)
  double top_m = 0;     // its height (only used with building_heights)
  if (building_heights) building_heights->assign(n_walls, 0.0);
  for (size_t i = 0; i < n_walls; ++i) {
    const Wall wl = w.walls[i];
    const double ex = wl.x2 - wl.x1, ey = wl.y2 - wl.y1, len = std::hypot(ex, ey);
    if (len < p.min_wall_m) continue;
    const double ux = ex / len, uy = ey / len, nx = uy, ny = -ux;  // along, outward
    if (i % 4 == 0) {
      const int floors = p.floors_min + int(rng.uniform() * (p.floors_max - p.floors_min + 1));
      stack_db = 10.0 * std::log10(double(std::min(floors, p.floors_max)));
      top_m = std::min(floors, p.floors_max) * p.storey_m + p.roof_m;
    }
    if (building_heights) {
      (*building_heights)[i] = top_m;
      w.walls[i].height = top_m;
    }
    auto add = [&](double u, double d, double rcs) {
      w.targets.push_back({wl.x1 + u * ux + d * nx, wl.y1 + u * uy + d * ny, rcs, 0, 0});
      if (building_heights) w.targets.back().height = top_m;
    };
    auto detail = [&] {
      return std::clamp(p.rcs_mean_db + p.rcs_sd_db * rng.normal(), p.rcs_lo_db, p.rcs_hi_db) + stack_db;
    };
    // The corner at the wall's start (each corner of a box starts exactly one of its walls).
    add(-0.15, 0.15, uni(p.corner_rcs_min_db, p.corner_rcs_max_db));
    for (double u = uni(0.5, p.bay_max_m); u < len - 2.0; u += uni(p.bay_min_m, p.bay_max_m)) {
      const double width = uni(p.opening_min_m, p.opening_max_m);
      add(u, uni(p.depth_min_m, p.depth_max_m), detail());
      add(u + width, uni(p.depth_min_m, p.depth_max_m), detail());
      if (rng.uniform() < p.balcony_share) add(u + width / 2, p.balcony_depth_m, detail() + p.balcony_extra_db);
    }
    for (double u = uni(1.0, p.pipe_max_m); u < len - 1.0; u += uni(p.pipe_min_m, p.pipe_max_m))
      add(u, 0.15, p.pipe_rcs_db + stack_db);
    for (double u = uni(0, p.rough_max_m); u < len; u += uni(p.rough_min_m, p.rough_max_m))
      add(u, uni(0, p.rough_depth_m), p.rough_rcs_mean_db + p.rough_rcs_sd_db * rng.normal() + stack_db);
  }
  // Street furniture along both kerbs of every street (x- and y-streets), junctions clear.
  for (int k = 0; k <= grid; ++k)
    for (int side = -1; side <= 1; side += 2)
      for (int axis = 0; axis < 2; ++axis)
        for (double u = uni(0, p.furniture_max_m); u < grid * pitch;
             u += uni(p.furniture_min_m, p.furniture_max_m)) {
          const double m = std::fmod(u, pitch);
          if (m < p.junction_clear_m || m > pitch - p.junction_clear_m) continue;
          const double off = side * uni(p.furniture_off_min_m, p.furniture_off_max_m);
          const double rcs = uni(p.furniture_rcs_min_db, p.furniture_rcs_max_db);
          if (axis == 0)
            w.targets.push_back({u, k * pitch + off, rcs, 0, 0});
          else
            w.targets.push_back({k * pitch + off, u, rcs, 0, 0});
          if (building_heights) w.targets.back().height = p.furniture_height_m;
        }
}

}  // namespace spinradar::sim::detail
