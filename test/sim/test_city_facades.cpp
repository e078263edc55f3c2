// The "city_facades" scene (src/sim/city_facades.cpp): the city, unchanged, plus facade detail
// that a rendered scan shows 50-100 m down the streets, where the plain city has none.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "spinradar/sim/city_facades.hpp"
#include "spinradar/sim/scenes.hpp"
#include "spinradar/sim/simulator.hpp"

using namespace spinradar;
using namespace spinradar::sim;

namespace {

// Distance along the ray from (ox, oy) towards (tx, ty) to the first wall, or +inf.
double firstWall(const World& w, double ox, double oy, double tx, double ty) {
  const double dx = tx - ox, dy = ty - oy;
  double best = INFINITY;
  for (const Wall& wl : w.walls) {
    const double ex = wl.x2 - wl.x1, ey = wl.y2 - wl.y1, den = dx * ey - dy * ex;
    if (std::abs(den) < 1e-12) continue;
    const double qx = wl.x1 - ox, qy = wl.y1 - oy;
    const double t = (qx * ey - qy * ex) / den, u = (qx * dy - qy * dx) / den;
    if (t > 0 && u >= 0 && u <= 1) best = std::min(best, t * std::hypot(dx, dy));
  }
  return best;
}

}  // namespace

// "city" is a prefix of "city_facades": the same walls, the same targets in the same order, the
// same route; the facade scene only appends targets (so "city" is what it was: nothing of its
// own random stream is drawn by the facade detail).
TEST(CityFacades, IsTheCityPlusAppendedTargets) {
  for (uint64_t variant : {0, 1, 2}) {
    const Scene c = builtinScene("city", variant), f = builtinScene("city_facades", variant);
    ASSERT_EQ(c.world.walls.size(), f.world.walls.size());
    for (size_t i = 0; i < c.world.walls.size(); ++i) {
      const Wall &a = c.world.walls[i], &b = f.world.walls[i];
      ASSERT_TRUE(a.x1 == b.x1 && a.y1 == b.y1 && a.x2 == b.x2 && a.y2 == b.y2 && a.rcs_per_m == b.rcs_per_m);
    }
    ASSERT_GT(f.world.targets.size(), c.world.targets.size() + 1000) << variant;
    for (size_t i = 0; i < c.world.targets.size(); ++i) {
      const Target &a = c.world.targets[i], &b = f.world.targets[i];
      ASSERT_TRUE(a.x == b.x && a.y == b.y && a.rcs == b.rcs && a.vx == b.vx && a.vy == b.vy) << i;
    }
    ASSERT_EQ(c.trajectory.samples().size(), f.trajectory.samples().size());
    for (size_t i = 0; i < c.trajectory.samples().size(); i += 97) {
      EXPECT_EQ(c.trajectory.samples()[i].pose.x, f.trajectory.samples()[i].pose.x);
      EXPECT_EQ(c.trajectory.samples()[i].pose.yaw, f.trajectory.samples()[i].pose.yaw);
    }
    // The added detail is static, within the documented strengths, and outside every building
    // (in front of its facade).
    const detail::FacadeDetail p;
    const double lo = std::min({p.rcs_lo_db, p.furniture_rcs_min_db, p.corner_rcs_min_db,
                                p.rough_rcs_mean_db - 8 * p.rough_rcs_sd_db});
    const double hi = std::max({p.rcs_hi_db + 10 * std::log10(p.floors_max) + p.balcony_extra_db,
                                p.furniture_rcs_max_db, p.corner_rcs_max_db,
                                p.rough_rcs_mean_db + 8 * p.rough_rcs_sd_db + 10 * std::log10(p.floors_max)});
    for (size_t i = c.world.targets.size(); i < f.world.targets.size(); ++i) {
      const Target& t = f.world.targets[i];
      EXPECT_EQ(t.vx, 0.0);
      EXPECT_EQ(t.vy, 0.0);
      EXPECT_GE(t.rcs, lo);
      EXPECT_LE(t.rcs, hi);
    }
    // Buildings are axis-aligned boxes of four consecutive walls: no detail inside one.
    int inside = 0;
    for (size_t b = 0; b + 3 < f.world.walls.size(); b += 4) {
      const Wall& w0 = f.world.walls[b];
      if (std::hypot(w0.x2 - w0.x1, w0.y2 - w0.y1) < p.min_wall_m) continue;  // a car
      double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
      for (size_t k = b; k < b + 4; ++k) {
        const Wall& wl = f.world.walls[k];
        x0 = std::min({x0, wl.x1, wl.x2}), x1 = std::max({x1, wl.x1, wl.x2});
        y0 = std::min({y0, wl.y1, wl.y2}), y1 = std::max({y1, wl.y1, wl.y2});
      }
      for (size_t i = c.world.targets.size(); i < f.world.targets.size(); ++i) {
        const Target& t = f.world.targets[i];
        inside += t.x > x0 + 0.01 && t.x < x1 - 0.01 && t.y > y0 + 0.01 && t.y < y1 - 0.01;
      }
    }
    EXPECT_EQ(inside, 0) << variant;
  }
  // Different variants lay the detail out differently.
  EXPECT_NE(builtinScene("city_facades", 0).world.targets.back().x,
            builtinScene("city_facades", 1).world.targets.back().x);
}

// In a rendered scan (default sensor, no motion distortion: the whole rotation from the
// mid-scan pose) the facade details 50-100 m away that the sensor has a line of sight to show
// as returns above the plain city's level at the same cells; the cells of details hidden
// behind a building stay as dark as in the plain city.
TEST(CityFacades, DetailIsVisibleFiftyToHundredMetresDownTheStreet) {
  const Scene c = builtinScene("city"), f = builtinScene("city_facades");
  const SensorConfig sensor;
  const PhysicsConfig physics;  // no motion distortion, no moving objects
  const Simulator sim_c(c.world, c.trajectory, sensor, physics, 5), sim_f(f.world, f.trajectory, sensor, physics, 5);
  int visible = 0, brighter = 0, hidden = 0, hidden_brighter = 0;
  for (int k : {20, 60, 140}) {  // scans on straights and in a turn
    const PolarScan sc = sim_c.renderScan(k), sf = sim_f.renderScan(k);
    const double t_mid = c.trajectory.startTime() + (k + 0.5) / sensor.rotation_hz;
    const Pose2 p = c.trajectory.at(t_mid);
    for (size_t i = c.world.targets.size(); i < f.world.targets.size(); ++i) {
      const Target& t = f.world.targets[i];
      const double dx = t.x - p.x, dy = t.y - p.y, r = std::hypot(dx, dy);
      if (r < 50 || r > 100) continue;
      // Clockwise sensor azimuth of the detail.
      const double xs = std::cos(p.yaw) * dx + std::sin(p.yaw) * dy;
      const double ys = -std::sin(p.yaw) * dx + std::cos(p.yaw) * dy;
      double az = std::atan2(-ys, xs);
      if (az < 0) az += 2 * M_PI;
      const int a0 = int(std::lround(az / (2 * M_PI) * sensor.azimuths)) % sensor.azimuths;
      const int b0 = int(r / sensor.range_resolution);
      auto peak = [&](const PolarScan& s) {
        int m = 0;
        for (int da = -1; da <= 1; ++da)
          for (int db = -4; db <= 4; ++db) {
            const int a = (a0 + da + s.azimuths) % s.azimuths, b = std::clamp(b0 + db, 0, s.bins - 1);
            m = std::max(m, int(s.row(a)[b]));
          }
        return m;
      };
      const bool more = peak(sf) >= peak(sc) + 6;  // 6 counts ~ 6 dB
      if (firstWall(f.world, p.x, p.y, t.x, t.y) > r + 0.05) {
        ++visible;
        brighter += more;
      } else if (firstWall(f.world, p.x, p.y, t.x, t.y) < r - 3.0) {  // well behind a wall
        ++hidden;
        hidden_brighter += more;
      }
    }
  }
  std::printf("facade details at 50-100 m: %d in sight (%d brighter), %d hidden (%d brighter)\n", visible,
              brighter, hidden, hidden_brighter);
  ASSERT_GE(visible, 30) << "too few facade details in sight at 50-100 m to judge";
  ASSERT_GE(hidden, 30);
  EXPECT_GT(brighter, visible / 2) << brighter << " of " << visible;
  EXPECT_LT(hidden_brighter, hidden / 10 + 1) << hidden_brighter << " of " << hidden;
}
