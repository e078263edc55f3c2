#pragma once
// Internals of Simulator: the scene turned into scatterers, a spatial grid over them, the
// parsed effect settings and the per-scan rendering.
#include <cstdint>
#include <memory>
#include <vector>

#include "render_model.hpp"
#include "spinradar/sim/simulator.hpp"

namespace spinradar::sim {

namespace detail {

/// A point scatterer in the world. Walls become rows of these (facade texture).
struct Scatterer {
  double x = 0, y = 0;    ///< world position (movers: at the reference time)
  float rcs_db = 0;       ///< dBsm
  float rcs_lin = 1;      ///< m^2
  float nx = 0, ny = 0;   ///< unit wall normal; 0,0 = isotropic
  float vx = 0, vy = 0;   ///< m/s (movers only)
  int32_t wall = -1;      ///< wall it belongs to (occlusion exemption), -1 = none
  int32_t mirror = -1;    ///< multipath ghost: wall it is mirrored in, -1 = direct
  float clutter_u = -1;   ///< textured clutter: shown where clutterDensityX(r) > this
  bool elevated = false;  ///< Target::elevated: not occluded by walls (seen over them)
  /// m above the ground, for the height rule (Impl::heights only): Target::height (unset 0),
  /// a wall scatterer its wall's height (unset = infinity: the wall is hidden only by walls
  /// that are infinitely tall too, as in the plain depth map).
  float height = 0;
};

/// Effects beyond the named ones, read from PhysicsConfig::extra.
struct ExtraEffects {
  bool bursts = false;
  int burst_size = 16;
  double burst_spacing = 135e-6;  ///< s between stamps inside a burst
  double burst_delay = 0.0;       ///< s after the packet's last azimuth is acquired
  double rotation_jitter = 0.0;   ///< relative std of the rotation period, per scan
  double encoder_wobble = 0.0;    ///< rad, amplitude of sin(azimuth) encoder error
  bool chirp_alternate = false;   ///< Boreas-RT: Doppler sign flips on alternate azimuths
  double attenuation_db_per_km = 0.0;  ///< two-way path loss (rain, fog)
  bool multipath = false;
  double multipath_db = -15.0;    ///< ghost power relative to the direct return
  bool pose_at_start = false;     ///< motion_distortion off: pose of scan start, not middle
  double glint = 0.0;             ///< m, per-scan std of the scattering-centre shift
  double glint_across = 0.0;      ///< m, the same across the line of sight only
  double glint_along = 0.0;       ///< m, the same along the line of sight only
  double azimuth_jitter = 0.0;    ///< rad, per-row std of the true beam angle

  static ExtraEffects from(const PhysicsConfig& p);
};

/// Per-scan geometry, reused between scans by each thread.
struct ScanWork {
  std::vector<double> t_render, px, py, cyaw, syaw, vx, vy, psi, dop_sign;
  std::vector<double> depth;
  std::vector<int32_t> depth_wall;
  std::vector<uint8_t> wall_seen;  // wall is the first hit of at least one angle bin
  // Height rule (worlds with heights, height_rule.hpp): every wall hit per occlusion angle bin,
  // then per bin the skyline of the walls' tops as seen from the sensor (CSR, reused).
  struct Hit {
    uint32_t j;
    int32_t wall;
    double t, slope;
  };
  std::vector<Hit> hits, hits_sorted;
  std::vector<uint32_t> hit_start;
  std::vector<uint32_t> sky_start;
  struct Step {
    double t;      ///< distance of the wall that raises the skyline
    double top;    ///< largest (H - h_s) / d of the walls up to and including it
    double below;  ///< the same without it (the scatterers of that wall itself)
    int32_t wall;
  };
  std::vector<Step> sky;
  std::vector<uint64_t> pairs;  // (azimuth << 32) | scatterer index (movers: | 1 << 31)
  std::vector<uint32_t> bucket_start, bucket_items;
  std::vector<float> row;
  std::vector<int16_t> level;
  std::vector<uint32_t> candidates;
};

}  // namespace detail

struct Simulator::Impl {
  World world;
  Trajectory traj;
  SensorConfig sensor;
  PhysicsConfig physics;
  uint64_t seed;
  bool heights = false;  ///< world.hasHeights(): the height rule instead of the plain depth map
  detail::ExtraEffects fx;
  detail::RenderModel model;
  /// Odd azimuths' range response when range_psf_odd_ratio != 1 (alternating chirps of unequal
  /// resolution): its point spread and speckle; everything else comes from `model`.
  std::unique_ptr<detail::RenderModel> model_odd;

  std::vector<detail::Scatterer> statics;
  std::vector<detail::Scatterer> movers;
  double t_ref = 0;  ///< movers are at (x, y) at this time

  /// Scatterers of wall w: statics[wall_first[w] .. wall_first[w] + wall_count[w]).
  std::vector<uint32_t> wall_first, wall_count;

  // Uniform grid over the statics that are not wall scatterers (CSR).
  double gx0 = 0, gy0 = 0, cell = 16.0;
  int gnx = 0, gny = 0;
  std::vector<uint32_t> cell_start;  ///< cell c holds statics[cell_start[c] .. cell_start[c+1])
  std::vector<double> depth_cos, depth_sin;  ///< per occlusion angle bin

  Impl(World w, Trajectory t, SensorConfig s, PhysicsConfig p, uint64_t sd);
  void buildScatterers();
  void addTexturedClutter();
  void buildGrid();
  void render(double t0, uint64_t scan_key, PolarScan& out) const;
};

}  // namespace spinradar::sim
