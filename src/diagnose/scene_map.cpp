#include "spinradar/diagnose/scene_map.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

#include "spinradar/diagnose/predict.hpp"

namespace spinradar::diagnose {
namespace {

struct Cluster {
  double sx = 0, sy = 0, sdb = 0;
  int n = 0, last_scan = -1, scans = 0;
  double x() const { return sx / n; }
  double y() const { return sy / n; }
};

int64_t cellKey(int cx, int cy) { return (int64_t(cx) << 32) ^ (int64_t(cy) & 0xffffffff); }

double parabola(double m, double c, double p) {
  const double den = m - 2.0 * c + p;
  return den < 0 ? std::clamp(0.5 * (m - p) / den, -0.5, 0.5) : 0.0;
}

}  // namespace

SceneMap buildSceneMap(const std::vector<PolarScan>& scans, const sim::Trajectory& traj,
                       const sim::SensorConfig& sensor, const sim::PhysicsConfig& base,
                       const std::string& split, const SceneMapOptions& opt) {
  SceneMap m;
  const int n = static_cast<int>(scans.size());
  if (n < 4) throw std::runtime_error("scene map: need at least 4 scans (2 to map, 2 to test)");
  int cut = n / 2;
  m.split = split;
  bool map_first = split != "late-early";
  if (split == "out-back") {
    const double yaw0 = traj.at(scans.front().firstStamp() * 1e-9).yaw;
    cut = -1;
    for (int k = 0; k < n && cut < 0; ++k)
      if (std::fabs(std::remainder(traj.at(scans[k].firstStamp() * 1e-9).yaw - yaw0,
                                   2 * M_PI)) > 2.6)
        cut = k;
    if (cut < 2 || cut > n - 2) {
      cut = n / 2;
      m.split = "early-late (no heading reversal found for out-back)";
    } else {
      m.split = "out-back (outbound leg maps, return leg is diagnosed)";
    }
  } else if (split == "early-late") {
    m.split = "early-late (first half maps, second half is diagnosed)";
  } else if (split == "late-early") {
    m.split = "late-early (second half maps, first half is diagnosed)";
  } else {
    throw std::invalid_argument("scene map: unknown split '" + split +
                                "' (early-late, late-early, out-back)");
  }
  for (int k = 0; k < n; ++k) ((k < cut) == map_first ? m.map_scans : m.test_scans).push_back(k);

  std::unordered_map<int64_t, std::vector<int>> grid;
  std::vector<Cluster> clusters;
  const double cell = opt.cluster_radius;
  for (int k : m.map_scans) {
    const PolarScan& s = scans[k];
    const ScanGeometry geo = ScanGeometry::fromScan(s);
    const double t_mid = geo.firstStamp() - base.timestamp_offset + 0.5 * geo.sweep;
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
        const double t = geo.stamp[gi] - base.timestamp_offset;
        const sim::Pose2 p = traj.at(base.motion_distortion ? t : t_mid);
        // Undo the base model's reported-range and azimuth conventions.
        double range = r - base.range_offset;
        const double phi = az - base.azimuth_offset;
        if (base.doppler != 0) {
          const Eigen::Vector3d vb = traj.bodyVelocity(base.motion_distortion ? t : t_mid);
          range += base.doppler * (vb.x() * std::cos(phi) - vb.y() * std::sin(phi));
        }
        const double xs = range * std::cos(phi), ys = -range * std::sin(phi);
        const double wx = p.x + std::cos(p.yaw) * xs - std::sin(p.yaw) * ys;
        const double wy = p.y + std::sin(p.yaw) * xs + std::cos(p.yaw) * ys;
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
        c.sx += wx;
        c.sy += wy;
        c.sdb += v / sensor.power_scale - sensor.radar_constant_db +
                 (40.0 - sensor.range_gain_db_per_decade) * std::log10(std::max(r, 1.0));
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
    sim::Target t;
    t.x = c.x();
    t.y = c.y();
    t.rcs = c.sdb / c.n;
    m.world.targets.push_back(t);
  }
  return m;
}

}  // namespace spinradar::diagnose

// ---- diagnosis without a world file ----
#include "spinradar/diagnose/diagnose.hpp"

namespace spinradar::diagnose {

DiagnoseReport diagnoseWithoutWorld(const DiagnoseInput& in, const DiagnoseOptions& opt,
                                    const std::string& split) {
  const SceneMap map = buildSceneMap(in.scans, in.trajectory, in.sensor, in.base, split);
  if (map.world.targets.empty())
    throw std::runtime_error("diagnose: no static returns were stable across the map scans");
  DiagnoseInput test;
  test.world = map.world;
  test.trajectory = in.trajectory;
  test.sensor = in.sensor;
  test.base = in.base;
  for (int k : map.test_scans) test.scans.push_back(in.scans[k]);
  DiagnoseOptions o = opt;
  o.target_nuisance = true;  // the mapped positions carry the effect's average: refit them
  DiagnoseReport rep = diagnose(test, o);
  rep.scene_model = "built from the recording: " + map.split + "; " +
                    std::to_string(map.map_scans.size()) + " map scans, " +
                    std::to_string(map.test_scans.size()) + " test scans, " +
                    std::to_string(map.world.targets.size()) +
                    " stable point returns; their positions are refitted as nuisance";
  rep.notes.push_back(
      "No world file: the scene was mapped under the base physics from the map scans. An "
      "effect that displaces returns the same way in the map and the test scans (same speed, "
      "same direction) is absorbed by the map; an out-and-back split exposes Doppler, latency "
      "and motion distortion because they flip sign with the driving direction.");
  return rep;
}

}  // namespace spinradar::diagnose
