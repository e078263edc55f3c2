// Facade detail of the "city_facades" scene (see city_facades.hpp).
#include "city_facades.hpp"

#include <algorithm>
#include <cmath>

#include "render_model.hpp"

namespace spinradar::sim::detail {

void addFacadeDetail(World& w, uint64_t variant, int grid, double pitch, const FacadeDetail& p) {
  Rng rng(0xFACADE00ull + variant);  // its own stream: the city's draws stay as they are
  auto uni = [&](double a, double b) { return a + (b - a) * rng.uniform(); };
  const size_t n_walls = w.walls.size();  // targets are appended, walls never
  for (size_t i = 0; i < n_walls; ++i) {
    const Wall wl = w.walls[i];
    const double ex = wl.x2 - wl.x1, ey = wl.y2 - wl.y1, len = std::hypot(ex, ey);
    if (len < p.min_wall_m) continue;
    const double ux = ex / len, uy = ey / len, nx = uy, ny = -ux;  // along, outward
    // The corner at the wall's start (each corner of a box starts exactly one of its walls).
    w.targets.push_back({wl.x1 + 0.15 * (nx - ux), wl.y1 + 0.15 * (ny - uy),
                         uni(p.corner_rcs_min_db, p.corner_rcs_max_db), 0, 0});
    for (double u = uni(0.5, p.bay_max_m); u < len - 0.5; u += uni(p.bay_min_m, p.bay_max_m)) {
      const bool balcony = rng.uniform() < p.balcony_share;
      const double d = balcony ? p.balcony_depth_m : uni(p.depth_min_m, p.depth_max_m);
      const double rcs = std::clamp(p.rcs_mean_db + p.rcs_sd_db * rng.normal(), p.rcs_lo_db,
                                    p.rcs_hi_db) + (balcony ? p.balcony_extra_db : 0.0);
      w.targets.push_back({wl.x1 + u * ux + d * nx, wl.y1 + u * uy + d * ny, rcs, 0, 0});
    }
  }
  // Street furniture along both kerbs of every street (x- and y-streets), junctions clear.
  for (int k = 0; k <= grid; ++k)
    for (int side = -1; side <= 1; side += 2)
      for (int axis = 0; axis < 2; ++axis)
        for (double u = uni(0, p.furniture_max_m); u < grid * pitch;
             u += uni(p.furniture_min_m, p.furniture_max_m)) {
          const double m = std::fmod(u, pitch);
          if (m < 9 || m > pitch - 9) continue;
          const double off = side * uni(p.furniture_off_min_m, p.furniture_off_max_m);
          const double rcs = uni(p.furniture_rcs_min_db, p.furniture_rcs_max_db);
          if (axis == 0)
            w.targets.push_back({u, k * pitch + off, rcs, 0, 0});
          else
            w.targets.push_back({k * pitch + off, u, rcs, 0, 0});
        }
}

}  // namespace spinradar::sim::detail
