// Simulator: the scene as scatterers (walls sampled into facade texture), the grid over them,
// effect settings, and the public API. The per-scan rendering is in render_scan.cpp.
#include "spinradar/sim/simulator.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "simulator_impl.hpp"

namespace spinradar::sim {

using detail::Scatterer;

namespace detail {

ExtraEffects ExtraEffects::from(const PhysicsConfig& p) {
  ExtraEffects e;
  const auto& x = p.extra;
  auto on = [&](const char* k) {
    auto it = x.find(k);
    if (it == x.end() || it->is_null()) return false;
    if (it->is_boolean()) return it->get<bool>();
    if (it->is_number()) return it->get<double>() != 0;
    return true;
  };
  if (on("stamp_bursts")) {
    e.bursts = true;
    const auto& b = x["stamp_bursts"];
    if (b.is_object()) {
      e.burst_size = std::max(1, b.value("size", 16));
      e.burst_spacing = b.value("spacing", 135e-6);
      e.burst_delay = b.value("delay", 0.0);
    }
  }
  if (on("rotation_jitter")) e.rotation_jitter = x["rotation_jitter"].get<double>();
  if (on("encoder_wobble")) e.encoder_wobble = x["encoder_wobble"].get<double>();
  if (on("chirp_alternate")) e.chirp_alternate = true;
  if (on("glint")) e.glint = x["glint"].get<double>();
  if (on("glint_across")) e.glint_across = x["glint_across"].get<double>();
  if (on("glint_along")) e.glint_along = x["glint_along"].get<double>();
  if (on("azimuth_jitter")) e.azimuth_jitter = x["azimuth_jitter"].get<double>() * M_PI / 180.0;
  if (on("attenuation")) e.attenuation_db_per_km = x["attenuation"].get<double>();
  if (on("multipath")) {
    e.multipath = true;
    if (x["multipath"].is_number()) e.multipath_db = x["multipath"].get<double>();
  }
  auto it = x.find("scan_pose_time");
  if (it != x.end() && it->is_string() && *it == "start") e.pose_at_start = true;
  return e;
}

}  // namespace detail

namespace {

uint64_t bitsOf(double v) {
  uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

SensorConfig checked(SensorConfig s) {
  s.validate();
  return s;
}

}  // namespace

Simulator::Impl::Impl(World w, Trajectory t, SensorConfig s, PhysicsConfig p, uint64_t sd)
    : world(std::move(w)),
      traj(std::move(t)),
      sensor(checked(std::move(s))),
      physics(p.withSensorPhysics(sensor.physics)),
      seed(sd),
      heights(world.hasHeights()),
      fx(detail::ExtraEffects::from(physics)),
      model(sensor) {
  if (traj.samples().size() < 2) throw std::invalid_argument("simulator: empty trajectory");
  if (sensor.range_psf_odd_ratio != 1.0) {
    SensorConfig odd = sensor;
    odd.range_psf_sigma_bins = std::min(sensor.range_psf_sigma_bins * sensor.range_psf_odd_ratio, 20.0);
    model_odd = std::make_unique<detail::RenderModel>(odd);
  }
  t_ref = traj.startTime();
  buildScatterers();
  for (auto* v : {&statics, &movers})
    for (auto& sc : *v) sc.rcs_lin = float(std::pow(10.0, sc.rcs_db / 10.0));
  buildGrid();
  const int J = sensor.azimuths * 8;  // kDepthOversample in render_scan.cpp
  depth_cos.resize(J);
  depth_sin.resize(J);
  for (int j = 0; j < J; ++j) {
    depth_cos[j] = std::cos((j + 0.5) * 2 * M_PI / J);
    depth_sin[j] = std::sin((j + 0.5) * 2 * M_PI / J);
  }
}

void Simulator::Impl::buildScatterers() {
  for (const Target& t : world.targets) {
    Scatterer s;
    s.x = t.x;
    s.y = t.y;
    s.rcs_db = float(t.rcs);
    s.elevated = t.elevated;
    s.height = float(t.height.value_or(0.0));
    if (t.vx != 0 || t.vy != 0) {
      // Without the moving_objects effect the static world is rendered: movers are left out.
      if (!physics.moving_objects) continue;
      s.vx = float(t.vx);
      s.vy = float(t.vy);
      movers.push_back(s);
    } else {
      statics.push_back(s);
    }
  }
  // Walls: scatterers every ~wall_spacing with jittered positions and a texture that depends
  // only on the wall's geometry, so a world reloaded from JSON renders identically.
  for (size_t wi = 0; wi < world.walls.size(); ++wi) {
    const Wall& w = world.walls[wi];
    double ex = w.x2 - w.x1, ey = w.y2 - w.y1;
    double len = std::hypot(ex, ey);
    int n = std::max(1, int(std::lround(len / sensor.wall_spacing)));
    double sp = len / n;
    uint64_t key = detail::Rng::splitmix(bitsOf(w.x1) ^ detail::Rng::splitmix(
                       bitsOf(w.y1) ^ detail::Rng::splitmix(bitsOf(w.x2) ^
                                                            detail::Rng::splitmix(bitsOf(w.y2)))));
    detail::Rng rng(key);
    double base = w.rcs_per_m + 10.0 * std::log10(sp);
    for (int i = 0; i < n; ++i) {
      double u = (i + 0.5 + 0.6 * (rng.uniform() - 0.5)) / n;
      Scatterer s;
      s.x = w.x1 + u * ex;
      s.y = w.y1 + u * ey;
      double tex = sensor.wall_texture_db * rng.normal();
      if (rng.uniform() < 0.04) tex += 10.0;  // window frames, pipes, signs: sparse bright spots
      s.rcs_db = float(base + tex);
      s.nx = float(-ey / len);
      s.ny = float(ex / len);
      s.wall = int32_t(wi);
      s.height = w.height ? float(*w.height) : std::numeric_limits<float>::infinity();
      statics.push_back(s);
    }
  }
  // Multipath: the double-bounce ghost of a point target in a wall lies at its mirror image;
  // it shows when the line of sight to the ghost passes through that wall.
  if (fx.multipath) {
    size_t n_direct = statics.size();
    for (size_t i = 0; i < n_direct; ++i) {
      if (statics[i].wall >= 0) continue;
      for (size_t wi = 0; wi < world.walls.size(); ++wi) {
        const Wall& w = world.walls[wi];
        double ex = w.x2 - w.x1, ey = w.y2 - w.y1;
        double len = std::hypot(ex, ey);
        double nx = -ey / len, ny = ex / len;
        double d = (statics[i].x - w.x1) * nx + (statics[i].y - w.y1) * ny;
        double along = ((statics[i].x - w.x1) * ex + (statics[i].y - w.y1) * ey) / len;
        if (std::abs(d) < 0.5 || std::abs(d) > 40.0 || along < -20 || along > len + 20) continue;
        Scatterer g = statics[i];
        g.x -= 2 * d * nx;
        g.y -= 2 * d * ny;
        g.rcs_db = float(statics[i].rcs_db + fx.multipath_db);
        g.mirror = int32_t(wi);
        statics.push_back(g);
      }
    }
  }
  addTexturedClutter();
}

void Simulator::Impl::addTexturedClutter() {
  // Real scans are full of small returns (kerbs, vegetation, road furniture, ground) standing
  // out of their neighbourhood; they are fixed in the world, so they are scatterers, placed
  // over the area the sensor sees along the route (a fixed RNG: same field for every seed).
  if (sensor.clutter_density <= 0) return;
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (const auto& smp : traj.samples()) {
    x0 = std::min(x0, smp.pose.x);
    y0 = std::min(y0, smp.pose.y);
    x1 = std::max(x1, smp.pose.x);
    y1 = std::max(y1, smp.pose.y);
  }
  const double m = sensor.maxRange();
  x0 -= m, y0 -= m, x1 += m, y1 += m;
  // A density curve over range (clutter_density_x_*) thins a field laid at its largest node.
  const double x_max = sensor.clutterDensityXMax();
  if (x_max <= 0) return;
  const double n_exp = (x1 - x0) * (y1 - y0) * sensor.clutter_density * x_max;
  const bool thinned = sensor.clutter_density_x_5m != 1 || sensor.clutter_density_x_16m != 1 ||
                       sensor.clutter_density_x_35m != 1 || sensor.clutter_density_x_71m != 1;
  if (n_exp > 2e7)
    throw std::invalid_argument("sensor parameter 'clutter_density': " + std::to_string(n_exp) +
                                " scatterers over this route, more than 2e7");
  detail::Rng rng(0xC1077E12ull);
  const size_t n = size_t(n_exp);
  statics.reserve(statics.size() + n);
  for (size_t i = 0; i < n; ++i) {
    Scatterer c;
    c.x = x0 + (x1 - x0) * rng.uniform();
    c.y = y0 + (y1 - y0) * rng.uniform();
    c.rcs_db = float(sensor.clutter_rcs_db + sensor.clutter_rcs_sd_db * rng.normal());
    // Nested thinning: the first k scatterers are a uniform field of density k / area, so
    // scatterer i shows where the density multiplier exceeds i / (area * clutter_density)
    // (a larger multiplier only adds scatterers: the figures move smoothly with the curve).
    if (thinned) c.clutter_u = float(double(i) / ((x1 - x0) * (y1 - y0) * sensor.clutter_density));
    statics.push_back(c);
  }
}

void Simulator::Impl::buildGrid() {
  // Point scatterers (not walls) are reordered by grid cell so that a cell is a contiguous
  // index range (cache-friendly culling); wall scatterers follow, wall by wall.
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (const auto& s : statics) {
    if (s.wall >= 0) continue;
    x0 = std::min(x0, s.x);
    y0 = std::min(y0, s.y);
    x1 = std::max(x1, s.x);
    y1 = std::max(y1, s.y);
  }
  std::vector<Scatterer> points, walls_pts;
  for (const auto& s : statics) (s.wall >= 0 ? walls_pts : points).push_back(s);
  gnx = gny = 0;
  cell_start.clear();
  if (!points.empty()) {
    // Keep the grid small for huge sparse worlds.
    cell = std::max(16.0, std::max(x1 - x0, y1 - y0) / 2048.0);
    gx0 = x0;
    gy0 = y0;
    gnx = int((x1 - x0) / cell) + 1;
    gny = int((y1 - y0) / cell) + 1;
    auto cellOf = [&](const Scatterer& s) {
      int cx = std::min(gnx - 1, int((s.x - gx0) / cell));
      int cy = std::min(gny - 1, int((s.y - gy0) / cell));
      return size_t(cy) * gnx + cx;
    };
    std::stable_sort(points.begin(), points.end(), [&](const Scatterer& a, const Scatterer& b) {
      return cellOf(a) < cellOf(b);
    });
    cell_start.assign(size_t(gnx) * gny + 1, 0);
    for (const auto& s : points) ++cell_start[cellOf(s) + 1];
    for (size_t i = 1; i < cell_start.size(); ++i) cell_start[i] += cell_start[i - 1];
  }
  statics = std::move(points);
  wall_first.assign(world.walls.size(), 0);
  wall_count.assign(world.walls.size(), 0);
  for (const auto& s : walls_pts) {
    if (wall_count[s.wall]++ == 0) wall_first[s.wall] = uint32_t(statics.size());
    statics.push_back(s);
  }
}

// ---------------------------------------------------------------------------------------------

Simulator::Simulator(World world, Trajectory trajectory, SensorConfig sensor,
                     PhysicsConfig physics, uint64_t seed)
    : impl_(std::make_unique<Impl>(std::move(world), std::move(trajectory), std::move(sensor),
                                   std::move(physics), seed)) {}

Simulator::~Simulator() = default;

PolarScan Simulator::renderScan(int k) const {
  if (k < 0) throw std::out_of_range("renderScan: negative scan index");
  double t0 = impl_->traj.startTime() + double(k) / impl_->sensor.rotation_hz;
  PolarScan scan;
  impl_->render(t0, uint64_t(k) * 2 + 1, scan);
  return scan;
}

PolarScan Simulator::renderScanAt(double t0) const {
  PolarScan scan;
  // Key by the start time in ns so that renderScanAt(start + k / f) == renderScan(k) is not
  // required, but a given t0 always gives the same noise.
  impl_->render(t0, uint64_t(std::llround(t0 * 1e9)) * 2, scan);
  return scan;
}

int Simulator::scanCount() const {
  double span = impl_->traj.endTime() - impl_->traj.startTime();
  return std::max(0, int(std::floor(span * impl_->sensor.rotation_hz + 1e-9)));
}

const World& Simulator::world() const { return impl_->world; }
const Trajectory& Simulator::trajectory() const { return impl_->traj; }
const SensorConfig& Simulator::sensor() const { return impl_->sensor; }
const PhysicsConfig& Simulator::physics() const { return impl_->physics; }

}  // namespace spinradar::sim
