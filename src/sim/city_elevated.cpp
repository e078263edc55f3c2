// Elevated structure of the "city_elevated" scene (see city_elevated.hpp).
#include "spinradar/sim/city_elevated.hpp"

#include <algorithm>
#include <cmath>

#include "render_model.hpp"

namespace spinradar::sim::detail {

void addElevatedDetail(World& w, uint64_t variant, int grid, double pitch, double half_street,
                       const ElevatedDetail& p, const std::vector<double>* building_heights) {
  Rng rng(0xE1E7A7EDull + variant);  // its own stream: the facade scene's draws stay as they are
  auto uni = [&](double a, double b) { return a + (b - a) * rng.uniform(); };
  auto count = [&](int lo, int hi) { return lo + std::min(int(rng.uniform() * (hi - lo + 1)), hi - lo); };
  // Height of what is added next (with building_heights), else the blanket flag.
  double h = 0;
  auto add = [&](double x, double y, double rcs) {
    Target t{x, y, rcs, 0, 0};
    if (building_heights)
      t.height = h;
    else
      t.elevated = true;
    w.targets.push_back(t);
  };
  auto top = [&](size_t wall) { return building_heights ? (*building_heights)[wall] : 0.0; };
  const size_t n_walls = w.walls.size() / 4 * 4;  // the city's walls are boxes of four
  for (size_t b = 0; b < n_walls; b += 4) {
    const Wall* box = &w.walls[b];
    double longest = 0;
    for (int k = 0; k < 4; ++k)
      longest = std::max(longest, std::hypot(box[k].x2 - box[k].x1, box[k].y2 - box[k].y1));
    if (longest < p.min_wall_m) continue;  // a parked car
    const int rise = count(0, p.rise_max);
    const double rise_db = rise > 0 ? 10.0 * std::log10(double(rise)) : 0.0;
    const double loss = p.elevation_loss_db;
    for (int k = 0; k < 4; ++k) {
      const Wall& wl = box[k];
      const double ex = wl.x2 - wl.x1, ey = wl.y2 - wl.y1, len = std::hypot(ex, ey);
      const double ux = ex / len, uy = ey / len, nx = uy, ny = -ux;  // along, outward
      auto at = [&](double u, double d, double rcs) { add(wl.x1 + u * ux + d * nx, wl.y1 + u * uy + d * ny, rcs); };
      h = top(b + k);
      for (double u = uni(0, p.roof_max_m); u < len; u += uni(p.roof_min_m, p.roof_max_m))
        at(u, uni(0, p.roof_depth_m), p.roof_rcs_mean_db + p.roof_rcs_sd_db * rng.normal() - loss);
      if (rise == 0) continue;  // level roofline: nothing of the storeys shows over the row in front
      h = top(b + k) - p.upper_below_top_m;
      auto reveal = [&] {
        return std::clamp(p.reveal_rcs_mean_db + p.reveal_rcs_sd_db * rng.normal(), p.reveal_rcs_lo_db,
                          p.reveal_rcs_hi_db) + rise_db - loss;
      };
      for (double u = uni(0.5, p.bay_max_m); u < len - 2.0; u += uni(p.bay_min_m, p.bay_max_m)) {
        const double width = uni(p.opening_min_m, p.opening_max_m);
        at(u, uni(0, p.rough_depth_m), reveal());
        at(u + width, uni(0, p.rough_depth_m), reveal());
      }
      for (double u = uni(0, p.rough_max_m); u < len; u += uni(p.rough_min_m, p.rough_max_m))
        at(u, uni(0, p.rough_depth_m), p.rough_rcs_mean_db + p.rough_rcs_sd_db * rng.normal() + rise_db - loss);
    }
    // Rooftop plant: corner c1 = end of wall 0; the roof spans wall 0 and wall 1 from it.
    const double cx = box[0].x1, cy = box[0].y1;
    const double ax = box[0].x2 - cx, ay = box[0].y2 - cy, bx = box[1].x2 - box[1].x1, by = box[1].y2 - box[1].y1;
    const double la = std::hypot(ax, ay), lb = std::hypot(bx, by);
    h = top(b) + p.plant_above_top_m;
    for (int n = count(0, p.plant_max), i = 0; i < n && la > 2 && lb > 2; ++i) {
      const double s = uni(1.0, la - 1.0) / la, t = uni(1.0, lb - 1.0) / lb;
      add(cx + s * ax + t * bx, cy + s * ay + t * by, uni(p.plant_rcs_min_db, p.plant_rcs_max_db) - loss);
    }
  }
  // Tree crowns in the back gardens and courtyards of every block, seen over the roofs.
  for (int i = 0; i < grid; ++i)
    for (int j = 0; j < grid; ++j)
      for (int n = count(0, p.crowns_max), k = 0; k < n; ++k) {
        const double x = uni(i * pitch + half_street, (i + 1) * pitch - half_street);
        const double y = uni(j * pitch + half_street, (j + 1) * pitch - half_street);
        const double radius = uni(p.crown_min_m, p.crown_max_m);
        h = p.crown_height_per_radius * radius;
        for (int m = count(p.crown_points_min, p.crown_points_max), q = 0; q < m; ++q) {
          const double r = radius * std::sqrt(rng.uniform()), a = uni(0, 2 * M_PI);
          add(x + r * std::cos(a), y + r * std::sin(a), p.crown_rcs_mean_db + p.crown_rcs_sd_db * rng.normal());
        }
      }
}

}  // namespace spinradar::sim::detail
