// The three base scenes: city, out_and_back and tight_turns (base_scenes.hpp). Layouts are
// random but fixed by the variant number; scene_catalogue.cpp builds the named variants on them.
#include "spinradar/sim/scenes.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "base_scenes.hpp"
#include "render_model.hpp"

namespace spinradar::sim {

namespace {

using detail::Rng;

double uni(Rng& r, double a, double b) { return a + (b - a) * r.uniform(); }

void addBox(World& w, double cx, double cy, double len, double wid, double yaw, double rcs_per_m) {
  double c = std::cos(yaw), s = std::sin(yaw);
  double hx = len / 2, hy = wid / 2;
  double px[4] = {hx, -hx, -hx, hx}, py[4] = {hy, hy, -hy, -hy};
  for (int i = 0; i < 4; ++i) {
    int j = (i + 1) % 4;
    w.walls.push_back({cx + c * px[i] - s * py[i], cy + s * px[i] + c * py[i],
                       cx + c * px[j] - s * py[j], cy + s * px[j] + c * py[j], rcs_per_m});
  }
}

/// Diffuse ground clutter (kerbs, grass, road surface, debris) as weak scatterers at `density`
/// per m^2 where `keep(x, y)` holds, and trees/bushes as clumps of scatterers.
template <class Keep>
void addClutter(World& w, Rng& rng, double x0, double y0, double x1, double y1, double density,
                Keep keep) {
  int n = int((x1 - x0) * (y1 - y0) * density);
  for (int i = 0; i < n; ++i) {
    double x = uni(rng, x0, x1), y = uni(rng, y0, y1);
    if (!keep(x, y)) continue;
    w.targets.push_back({x, y, -40.0 + 7.0 * rng.normal(), 0, 0});
  }
}

void addTree(World& w, Rng& rng, double cx, double cy, double radius) {
  int n = 8 + int(rng.uniform() * 12);
  double base = uni(rng, -30, -18);
  for (int i = 0; i < n; ++i) {
    double r = radius * std::sqrt(rng.uniform()), a = uni(rng, 0, 2 * M_PI);
    w.targets.push_back({cx + r * std::cos(a), cy + r * std::sin(a), base + 5 * rng.normal(), 0, 0});
  }
}

/// Builds a motion profile: speed ramps, straights and constant-radius turns.
class Route {
 public:
  static constexpr double kYawAccel = kSceneYawAccel;
  static constexpr double kRampStep = 0.01;  ///< s per constant-yaw-rate step of a ramp

  explicit Route(double v0 = 0) : v_(v0) {}
  /// Ramp the speed to v1 at |accel| (m/s^2); returns the distance covered.
  double ramp(double v1, double accel) {
    double d = 0;
    const double step = 0.1;
    while (std::abs(v1 - v_) > 1e-9) {
      double dv = std::clamp(v1 - v_, -accel * step, accel * step);
      double dur = std::abs(dv) / accel;
      double vm = v_ + dv / 2;
      seg_.push_back({dur, vm, 0.0});
      d += vm * dur;
      v_ += dv;
    }
    return d;
  }
  static double rampDistance(double v0, double v1, double accel) {
    return std::abs(v1 * v1 - v0 * v0) / (2 * accel);
  }
  void straight(double dist) {
    if (dist <= 1e-6) return;
    if (v_ <= 1e-6) throw std::logic_error("route: straight at zero speed");
    seg_.push_back({dist / v_, v_, 0.0});
  }
  /// Turn by angle (rad, + = left/CCW) at the current speed: the yaw rate ramps at
  /// kYawAccel up to v / r (a circle of radius r), holds, and ramps back to zero, so the
  /// path eases in and out as a driver turning the wheel does (no vehicle steps its yaw rate).
  void turn(double angle, double r) {
    for (const auto& s : turnProfile(v_, angle, r)) seg_.push_back(s);
  }
  /// Distance from the start of turn(angle, r) at speed v to where the entry and exit
  /// directions cross (r tan(angle / 2) for a circle; longer with the eased entry and exit).
  static double tangentLength(double v, double angle, double r) {
    if (std::abs(std::sin(angle)) < 1e-3) throw std::logic_error("route: tangent of a U-turn");
    double x = 0, y = 0, yaw = 0;
    for (const auto& s : turnProfile(v, angle, r)) {  // exact arcs, as Trajectory::fromProfile
      const double w = s.yaw_rate, next = yaw + w * s.duration;
      x += s.speed / w * (std::sin(next) - std::sin(yaw));
      y += s.speed / w * (std::cos(yaw) - std::cos(next));
      yaw = next;
    }
    return x - y * std::cos(angle) / std::sin(angle);
  }
  void wait(double dur) { seg_.push_back({dur, 0.0, 0.0}); }
  /// A leg of `dist` starting at speed v_ and ending at v_end, cruising at up to v_cruise.
  void leg(double dist, double v_cruise, double v_end, double acc, double dec) {
    double v0 = v_;
    // Lower the cruise speed if the leg is too short to reach it.
    double vc = v_cruise;
    while (vc > std::max(v0, v_end) &&
           rampDistance(v0, vc, acc) + rampDistance(vc, v_end, dec) > dist)
      vc -= 0.25;
    vc = std::max(vc, std::max(v0, v_end));
    double d1 = ramp(vc, acc);
    double d3 = rampDistance(vc, v_end, dec);
    straight(dist - d1 - d3);
    ramp(v_end, dec);
  }
  double speed() const { return v_; }
  const std::vector<Trajectory::Segment>& segments() const { return seg_; }

 private:
  static std::vector<Trajectory::Segment> turnProfile(double v, double angle, double r) {
    if (v <= 1e-6) throw std::logic_error("route: turn at zero speed");
    const double sign = angle > 0 ? 1 : -1, total = std::abs(angle);
    // Trapezoid in yaw rate; a triangle when the turn is too short to reach v / r.
    double w = v / r, t_ramp = w / kYawAccel;
    if (w * t_ramp > total) {
      w = std::sqrt(total * kYawAccel);
      t_ramp = w / kYawAccel;
    }
    const double t_hold = total / w - t_ramp;
    const int n = std::max(1, int(std::ceil(t_ramp / kRampStep)));
    const double dt = t_ramp / n;
    std::vector<Trajectory::Segment> out;
    // Each ramp step holds the rate at its midpoint: the ramps turn by exactly w * t_ramp.
    for (int i = 0; i < n; ++i) out.push_back({dt, v, sign * w * (i + 0.5) / n});
    if (t_hold > 1e-9) out.push_back({t_hold, v, sign * w});
    for (int i = n - 1; i >= 0; --i) out.push_back({dt, v, sign * w * (i + 0.5) / n});
    return out;
  }

  double v_;
  std::vector<Trajectory::Segment> seg_;
};

}  // namespace

namespace detail {

// ---- city ---------------------------------------------------------------------------------

// The layout's numbers are in city_layout.hpp (its defaults are this scene).
Scene city(uint64_t variant, double t0, const CityLayout& L) {
  Scene sc;
  sc.name = "city";
  sc.description =
      "7x7 street grid (64 m pitch, 14 m streets) with facades, poles, parked and moving cars; "
      "a ~5 min route with 12 turns at 5 m/s and straights at 10-15 m/s";
  Rng rng(0xC1770000ull + variant);
  const int G = L.grid;
  const double P = L.pitch_m, half_street = L.half_street_m;
  const double s = half_street - 7.0;  // kerb-side objects move out with the kerb (0: the city)
  World& w = sc.world;
  // Buildings: each block split into 1-3 buildings along a random axis, with setbacks.
  for (int i = 0; i < G; ++i)
    for (int j = 0; j < G; ++j) {
      double x0 = i * P + half_street, x1 = (i + 1) * P - half_street;
      double y0 = j * P + half_street, y1 = (j + 1) * P - half_street;
      int n = 1 + int(rng.uniform() * 3);
      bool along_x = rng.uniform() < 0.5;
      double lo = along_x ? x0 : y0, hi = along_x ? x1 : y1;
      double pos = lo;
      for (int k = 0; k < n; ++k) {
        double end = k == n - 1 ? hi : pos + (hi - lo) / n;
        // A gap at most half a building's share keeps every building a box (the city's never is).
        double gap = k == n - 1 ? 0.0 : std::min(uni(rng, L.gap_min_m, L.gap_max_m), 0.5 * (hi - lo) / n);
        const double sm = L.setback_max_m;
        double sb[4] = {uni(rng, 0, sm), uni(rng, 0, sm), uni(rng, 0, sm), uni(rng, 0, sm)};
        double bx0 = along_x ? pos : x0 + sb[0], bx1 = along_x ? end - gap : x1 - sb[1];
        double by0 = along_x ? y0 + sb[2] : pos, by1 = along_x ? y1 - sb[3] : end - gap;
        double rpm = uni(rng, 0.0, 8.0);
        double cx = (bx0 + bx1) / 2, cy = (by0 + by1) / 2;
        addBox(w, cx, cy, bx1 - bx0, by1 - by0, 0.0, rpm);
        pos = end;
      }
    }
  // Poles (lamp posts, signs, trees) along every street, both sides.
  for (int k = 0; k <= G; ++k)
    for (int side = -1; side <= 1; side += 2)
      for (double u = uni(rng, 0, 10); u < G * P; u += uni(rng, 15, 35)) {
        if (std::fmod(u, P) < 9 + s || std::fmod(u, P) > P - 9 - s) continue;  // keep junctions clear
        double off = side * uni(rng, 6.0 + s, 6.8 + s);
        double rcs = uni(rng, 5, 18);
        w.targets.push_back({u, k * P + off, rcs, 0, 0});   // along x-streets
        w.targets.push_back({k * P + off, u, rcs, 0, 0});   // along y-streets
      }
  // Parked cars (boxes) at the kerbs.
  for (int k = 0; k <= G; ++k)
    for (int side = -1; side <= 1; side += 2)
      for (double u = 10; u < G * P; u += 6.0) {
        double m = std::fmod(u, P);
        if (m < 10 + s || m > P - 12 - s || rng.uniform() > 0.35) continue;
        double off = side * (4.8 + s);
        double rpm = uni(rng, 6, 12);
        addBox(w, u + 2.2, k * P + off, 4.4, 1.8, 0.0, rpm);
        addBox(w, k * P + off, u + 2.2, 4.4, 1.8, M_PI / 2, rpm);
      }
  // Moving cars: three scatterers each, streaming along lanes of some streets.
  for (int k = 1; k < G; k += 2)
    for (int dir = -1; dir <= 1; dir += 2)
      for (int axis = 0; axis < 2; ++axis) {
        double v = dir * uni(rng, 6, 12);
        double lane = -dir * 2.5;  // drive on the right
        for (double u = -3000 + uni(rng, 0, 200); u < G * P + 3000; u += uni(rng, 180, 320)) {
          for (int p = -1; p <= 1; ++p) {
            double along = u + p * 1.8;
            double rcs = p == 0 ? 14.0 : 18.0;
            if (axis == 0)
              w.targets.push_back({along, k * P + lane, rcs, v, 0});
            else
              w.targets.push_back({k * P - lane, along, rcs, 0, v});
          }
        }
      }

  // Ground clutter in the streets and front yards, trees along the kerbs.
  // Kerbs, verges and front yards: 4.5-9.5 m from a street's centre line (not the carriageway).
  auto verge = [&](double x, double y) {
    double mx = std::fmod(x + P, P), my = std::fmod(y + P, P);
    double dx = std::min(mx, P - mx), dy = std::min(my, P - my);
    bool near_x = dx < half_street + 2.5, near_y = dy < half_street + 2.5;
    if (!near_x && !near_y) return false;
    if ((near_x && dx < 4.5 + s) || (near_y && dy < 4.5 + s)) return false;
    return true;
  };
  addClutter(w, rng, -40, -40, G * P + 40, G * P + 40, 0.3, verge);
  for (int k = 0; k <= G; ++k)
    for (int side = -1; side <= 1; side += 2)
      for (double u = uni(rng, 0, 20); u < G * P; u += uni(rng, 15, 45)) {
        double m = std::fmod(u, P);
        if (m < 10 + s || m > P - 10 - s) continue;
        double off = side * uni(rng, 7.5 + s, 9.0 + s);
        if (rng.uniform() < 0.5)
          addTree(w, rng, u, k * P + off, uni(rng, 1.0, 2.5));
        else
          addTree(w, rng, k * P + off, u, uni(rng, 1.0, 2.5));
      }
  // Outside the grid: open land with scattered trees.
  for (int i = 0; i < 150; ++i) {
    double a = uni(rng, 0, 2 * M_PI), r = uni(rng, 0.75, 1.2) * G * P;
    addTree(w, rng, G * P / 2 + r * std::cos(a), G * P / 2 + r * std::sin(a), uni(rng, 1.5, 4));
  }

  // Route over the street grid (node polyline, successive legs perpendicular).
  const int nodes[][2] = {{0, 0}, {4, 0}, {4, 3}, {2, 3}, {2, 5}, {6, 5}, {6, 1},
                          {3, 1}, {3, 6}, {0, 6}, {0, 2}, {5, 2}, {5, 4}, {1, 4}};
  const int nn = sizeof(nodes) / sizeof(nodes[0]);
  const double R = 8.0, v_turn = 5.0;
  Route route;
  double in_turn = 0;  // distance already used by the previous turn
  for (int k = 0; k + 1 < nn; ++k) {
    double len = (std::abs(nodes[k + 1][0] - nodes[k][0]) + std::abs(nodes[k + 1][1] - nodes[k][1])) * P;
    bool last = k + 2 == nn;
    // The turn starts its tangent length before the crossing, so the car stays mid-street.
    double out_turn = last ? 0.0 : Route::tangentLength(v_turn, M_PI / 2, R);
    double v_cruise = uni(rng, 10.0, 15.0);
    route.leg(len - in_turn - out_turn, v_cruise, last ? 0.0 : v_turn, 2.0, 2.5);
    if (!last) {
      double hx = nodes[k + 1][0] - nodes[k][0], hy = nodes[k + 1][1] - nodes[k][1];
      double nx = nodes[k + 2][0] - nodes[k + 1][0], ny = nodes[k + 2][1] - nodes[k + 1][1];
      double cross = ((hx > 0) - (hx < 0)) * ((ny > 0) - (ny < 0)) - ((hy > 0) - (hy < 0)) * ((nx > 0) - (nx < 0));
      route.turn(cross > 0 ? M_PI / 2 : -M_PI / 2, R);
      in_turn = out_turn;
    }
  }
  route.wait(1.0);
  sc.trajectory = Trajectory::fromProfile(route.segments(), {0, 0, 0}, t0);
  return sc;
}

// ---- out and back ---------------------------------------------------------------------------

Scene outAndBack(uint64_t variant, double t0) {
  Scene sc;
  sc.name = "out_and_back";
  sc.description =
      "straight 1 km road with poles, buildings and parked cars; out at 15-20 m/s, U-turn, back "
      "at 10-18 m/s on the other lane (same places seen in opposite directions)";
  Rng rng(0x0A7BAC00ull + variant);
  World& w = sc.world;
  const double L = 1000;
  for (int side = -1; side <= 1; side += 2) {
    for (double x = uni(rng, -20, 0); x < L + 40; x += uni(rng, 18, 32))
      w.targets.push_back({x, side * uni(rng, 6.5, 8.0), uni(rng, 5, 18), 0, 0});
    for (double x = uni(rng, -40, 0); x < L + 60;) {
      double len = uni(rng, 15, 60), depth = uni(rng, 10, 20);
      double y0 = side * uni(rng, 12, 20);
      addBox(w, x + len / 2, y0 + side * depth / 2, len, depth, 0.0, uni(rng, 0, 8));
      x += len + uni(rng, 5, 35);
    }
    for (double x = 0; x < L; x += 7)
      if (rng.uniform() < 0.2) addBox(w, x, side * 4.8, 4.4, 1.8, 0.0, uni(rng, 6, 12));
    for (double x = uni(rng, -30, 0); x < L + 40; x += uni(rng, 10, 40))
      addTree(w, rng, x, side * uni(rng, 9, 40), uni(rng, 1.0, 3.0));
  }
  addClutter(w, rng, -60, -60, L + 60, 60, 0.12, [](double, double y) { return std::abs(y) > 5.0; });
  Route route;
  route.leg(300, 15.0, 15.0, 2.0, 2.0);
  route.leg(300, 20.0, 20.0, 1.5, 2.0);
  route.leg(320, 12.0, 3.0, 2.0, 2.0);
  route.turn(M_PI, 2.0);  // U-turn onto the other lane (y -2.4 -> +2.4 with the eased ends)
  route.leg(300, 12.0, 12.0, 2.0, 2.0);
  route.leg(300, 18.0, 18.0, 1.5, 2.0);
  route.leg(320, 10.0, 0.0, 2.0, 2.0);
  route.wait(1.0);
  sc.trajectory = Trajectory::fromProfile(route.segments(), {0, -2.4, 0}, t0);
  return sc;
}

// ---- tight turns -----------------------------------------------------------------------------

Scene tightTurns(uint64_t variant, double t0) {
  Scene sc;
  sc.name = "tight_turns";
  sc.description =
      "open yard with poles, containers and a perimeter fence; slalom, left and right loops at "
      "3-8 m/s (yaw rates up to ~1 rad/s)";
  Rng rng(0x7197E000ull + variant);
  World& w = sc.world;
  for (int i = 0; i < 70; ++i) {
    double r = uni(rng, 25, 110), a = uni(rng, 0, 2 * M_PI);
    w.targets.push_back({60 + r * std::cos(a), r * std::sin(a), uni(rng, 5, 18), 0, 0});
  }
  for (int i = 0; i < 24; ++i) {
    double r = uni(rng, 45, 100), a = uni(rng, 0, 2 * M_PI);
    addBox(w, 60 + r * std::cos(a), r * std::sin(a), 12.2, 2.5, uni(rng, 0, M_PI), uni(rng, 4, 10));
  }
  for (int i = 0; i < 40; ++i) {
    double r = uni(rng, 30, 120), a = uni(rng, 0, 2 * M_PI);
    addTree(w, rng, 60 + r * std::cos(a), r * std::sin(a), uni(rng, 1.0, 3.0));
  }
  addClutter(w, rng, -70, -130, 190, 130, 0.08, [](double, double) { return true; });
  // Perimeter fence with gaps.
  const double X0 = -70, X1 = 190, Y0 = -130, Y1 = 130;
  auto fence = [&](double x1, double y1, double x2, double y2) {
    int n = 8;
    for (int k = 0; k < n; ++k) {
      if (rng.uniform() < 0.2) continue;
      double a = double(k) / n, b = (k + 0.9) / n;
      w.walls.push_back({x1 + a * (x2 - x1), y1 + a * (y2 - y1), x1 + b * (x2 - x1),
                         y1 + b * (y2 - y1), uni(rng, 0, 6)});
    }
  };
  fence(X0, Y0, X1, Y0);
  fence(X1, Y0, X1, Y1);
  fence(X1, Y1, X0, Y1);
  fence(X0, Y1, X0, Y0);
  Route route;
  route.leg(30, 6.0, 6.0, 1.5, 2.0);
  for (int k = 0; k < 6; ++k) route.turn(k % 2 ? -0.9 : 0.9, 7.0);  // slalom
  route.leg(20, 8.0, 5.0, 1.5, 2.0);
  route.turn(2 * M_PI, 5.0);   // left loop, 1 rad/s
  route.leg(15, 6.0, 5.0, 1.5, 2.0);
  route.turn(-2 * M_PI, 5.0);  // right loop
  route.leg(15, 7.0, 4.0, 1.5, 2.0);
  route.turn(M_PI, 4.0);       // tight hairpin
  route.leg(40, 8.0, 6.0, 1.5, 2.0);
  for (int k = 0; k < 4; ++k) route.turn(k % 2 ? 1.2 : -1.2, 6.0);
  route.leg(20, 6.0, 3.0, 1.5, 2.0);
  route.turn(-M_PI, 3.0);
  route.leg(25, 6.0, 0.0, 1.5, 2.0);
  route.wait(1.0);
  sc.trajectory = Trajectory::fromProfile(route.segments(), {0, 0, 0}, t0);
  return sc;
}

}  // namespace detail

}  // namespace spinradar::sim
