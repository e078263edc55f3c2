#include "spinradar/diagnose/scene_map.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

#include "spinradar/diagnose/predict.hpp"

namespace spinradar::diagnose {
namespace {

struct Cluster {
  double sx = 0, sy = 0;
  int n = 0, last_scan = -1, scans = 0;
  std::vector<MapPeak> peaks;
  double x() const { return sx / n; }
  double y() const { return sy / n; }
};

int64_t cellKey(int cx, int cy) { return (int64_t(cx) << 32) ^ (int64_t(cy) & 0xffffffff); }

double parabola(double m, double c, double p) {
  const double den = m - 2.0 * c + p;
  return den < 0 ? std::clamp(0.5 * (m - p) / den, -0.5, 0.5) : 0.0;
}

}  // namespace

Eigen::Vector2d placePeak(const MapPeak& pk, const sim::Trajectory& traj,
                          const sim::PhysicsConfig& ph) {
  // Mirrors predictTarget: pose per azimuth with motion distortion, otherwise at the scan's
  // instant (mid-sweep, or the first azimuth with the "scan_pose_time": "start" extra).
  const auto it = ph.extra.find("scan_pose_time");
  const bool at_start = it != ph.extra.end() && it->is_string() && *it == "start";
  const double t_row = pk.stamp - ph.timestamp_offset;
  const double t_pose = ph.motion_distortion
                            ? t_row
                            : pk.first_stamp - ph.timestamp_offset + (at_start ? 0.0 : 0.5) * pk.sweep;
  const sim::Pose2 p = traj.at(t_pose);
  const double phi = pk.azimuth - ph.azimuth_offset;
  double range = pk.range - ph.range_offset;
  if (ph.doppler != 0) {
    const Eigen::Vector3d vb = traj.bodyVelocity(t_pose);
    range += ph.doppler * (vb.x() * std::cos(phi) - vb.y() * std::sin(phi));
  }
  const double xs = range * std::cos(phi), ys = -range * std::sin(phi);
  return {p.x + std::cos(p.yaw) * xs - std::sin(p.yaw) * ys,
          p.y + std::sin(p.yaw) * xs + std::cos(p.yaw) * ys};
}

sim::World replaceMap(const SceneMap& map, const sim::Trajectory& traj,
                      const sim::PhysicsConfig& physics) {
  sim::World w = map.world;
  for (size_t j = 0; j < w.targets.size(); ++j) {
    Eigen::Vector2d s = Eigen::Vector2d::Zero();
    for (const MapPeak& pk : map.members[j]) s += placePeak(pk, traj, physics);
    s /= static_cast<double>(map.members[j].size());
    w.targets[j].x = s.x();
    w.targets[j].y = s.y();
  }
  return w;
}

SceneMap buildSceneMap(const std::vector<PolarScan>& scans, const sim::Trajectory& traj,
                       const sim::SensorConfig& sensor, const sim::PhysicsConfig& base,
                       const std::string& split, const SceneMapOptions& opt,
                       const sim::PhysicsConfig* cluster_physics) {
  SceneMap m;
  const sim::PhysicsConfig& cph = cluster_physics ? *cluster_physics : base;
  const int n = static_cast<int>(scans.size());
  if (n < 4) throw std::runtime_error("scene map: need at least 4 scans (2 to map, 2 to test)");
  int cut = n / 2;
  const bool map_first = split != "late-early";
  if (split == "out-back" || split == "auto") {
    // The return leg starts where the heading has turned by 90 degrees from the start (the
    // middle of the U-turn); both legs need at least 2 scans.
    const double yaw0 = traj.at(scans.front().firstStamp() * 1e-9).yaw;
    int rev = -1;
    for (int k = 0; k < n && rev < 0; ++k)
      if (std::fabs(std::remainder(traj.at(scans[k].firstStamp() * 1e-9).yaw - yaw0,
                                   2 * M_PI)) > 0.5 * M_PI)
        rev = k;
    bool reversal = false;
    if (rev >= 2 && rev <= n - 2)
      for (int k = rev; k < n && !reversal; ++k)
        reversal = std::fabs(std::remainder(traj.at(scans[k].firstStamp() * 1e-9).yaw - yaw0,
                                            2 * M_PI)) > 2.6;
    const std::string how = split == "auto" ? "auto: " : "";
    if (reversal) {
      cut = rev;
      m.split = how + "out-back (scans before the heading has turned by 90 deg map, the return "
                      "leg is diagnosed)";
    } else {
      m.split = how + "early-late (" + (split == "auto" ? "no" : "out-back asked, but no") +
                " heading reversal in the drive; first half maps, second half is diagnosed)";
    }
  } else if (split == "early-late") {
    m.split = "early-late (first half maps, second half is diagnosed)";
  } else if (split == "late-early") {
    m.split = "late-early (second half maps, first half is diagnosed)";
  } else {
    throw std::invalid_argument("scene map: unknown split '" + split +
                                "' (auto, early-late, late-early, out-back)");
  }
  for (int k = 0; k < n; ++k) ((k < cut) == map_first ? m.map_scans : m.test_scans).push_back(k);

  std::unordered_map<int64_t, std::vector<int>> grid;
  std::vector<Cluster> clusters;
  std::vector<std::vector<MapPeak>> scan_peaks(n);  // every peak of each map scan
  const double cell = opt.cluster_radius;
  for (int k : m.map_scans) {
    const PolarScan& s = scans[k];
    const ScanGeometry geo = ScanGeometry::fromScan(s);
    for (size_t gi = 1; gi + 1 < geo.row.size(); ++gi) {
      const uint8_t* row = s.row(geo.row[gi]);
      const uint8_t* up = s.row(geo.row[gi - 1]);
      const uint8_t* dn = s.row(geo.row[gi + 1]);
      std::vector<uint8_t> tmp(row, row + s.bins);
      std::nth_element(tmp.begin(), tmp.begin() + tmp.size() / 2, tmp.end());
      const int thr = tmp[tmp.size() / 2] + static_cast<int>(opt.min_contrast);
      for (int b = 3; b < s.bins - 3; ++b) {
        const int v = row[b];
        if (v < thr || v < row[b - 1] || v < row[b + 1] || v < row[b - 2] || v < row[b + 2] ||
            v < up[b] || v < dn[b])
          continue;
        const double r = s.rangeOfBin(b + parabola(row[b - 1], v, row[b + 1]));
        if (r < opt.min_range) continue;
        const double az = geo.azimuthAt(gi + parabola(up[b], v, dn[b]));
        MapPeak pk;
        pk.scan = k;
        pk.range = r;
        pk.azimuth = az;
        pk.stamp = geo.stamp[gi];
        pk.first_stamp = geo.firstStamp();
        pk.sweep = geo.sweep;
        pk.power = v;
        scan_peaks[k].push_back(pk);
        const Eigen::Vector2d wp = placePeak(pk, traj, cph);
        const double wx = wp.x(), wy = wp.y();
        ++m.peaks;
        const int cx = static_cast<int>(std::floor(wx / cell)),
                  cy = static_cast<int>(std::floor(wy / cell));
        int best = -1;
        double bd = opt.cluster_radius;
        for (int dx = -1; dx <= 1; ++dx)
          for (int dy = -1; dy <= 1; ++dy) {
            auto it = grid.find(cellKey(cx + dx, cy + dy));
            if (it == grid.end()) continue;
            for (int ci : it->second) {
              const double d = std::hypot(clusters[ci].x() - wx, clusters[ci].y() - wy);
              if (d < bd) {
                bd = d;
                best = ci;
              }
            }
          }
        if (best < 0) {
          best = static_cast<int>(clusters.size());
          clusters.emplace_back();
          grid[cellKey(cx, cy)].push_back(best);
        }
        Cluster& c = clusters[best];
        c.peaks.push_back(pk);
        c.sx += wx;
        c.sy += wy;
        ++c.n;
        if (c.last_scan != k) {
          c.last_scan = k;
          ++c.scans;
        }
      }
    }
  }
  const int need = std::max(2, static_cast<int>(std::ceil(opt.min_fraction * m.map_scans.size())));
  for (const Cluster& c : clusters) {
    if (c.scans < need) continue;
    // One peak per scan, the strongest: weaker local maxima in the same cluster are sidelobes
    // of the main return (or a weaker neighbour) and would pull the mean aside.
    std::vector<MapPeak> kept;
    for (const MapPeak& pk : c.peaks) {
      auto it = std::find_if(kept.begin(), kept.end(),
                             [&](const MapPeak& q) { return q.scan == pk.scan; });
      if (it == kept.end())
        kept.push_back(pk);
      else if (pk.power > it->power)
        *it = pk;
    }
    // A point target must dominate its surroundings (as the association requires): in most
    // of its scans no other peak within the window is less than dominance_db weaker. Wall and
    // vegetation speckle fails this and would make the association jump between scatterers.
    int crowded = 0;
    for (const MapPeak& pk : kept) {
      for (const MapPeak& q : scan_peaks[pk.scan]) {
        const double dr = std::fabs(q.range - pk.range);
        const double da = std::fabs(std::remainder(q.azimuth - pk.azimuth, 2 * M_PI));
        // Other local maxima inside the point spread are the same return.
        if (dr < opt.spread_range && da < opt.spread_azimuth) continue;
        if (dr < opt.isolation_range && da < opt.isolation_azimuth &&
            q.power > pk.power - opt.dominance_db * sensor.power_scale) {
          ++crowded;
          break;
        }
      }
    }
    if (crowded > opt.max_crowded_fraction * kept.size()) continue;
    sim::Target t;
    double sdb = 0;
    for (const MapPeak& pk : kept) {
      const Eigen::Vector2d wp = placePeak(pk, traj, base);
      t.x += wp.x() / kept.size();
      t.y += wp.y() / kept.size();
      sdb += pk.power / sensor.power_scale - sensor.radar_constant_db +
             (40.0 - sensor.range_gain_db_per_decade) * std::log10(std::max(pk.range, 1.0));
    }
    t.rcs = sdb / kept.size();
    m.world.targets.push_back(t);
    m.members.push_back(kept);
  }
  return m;
}

}  // namespace spinradar::diagnose
