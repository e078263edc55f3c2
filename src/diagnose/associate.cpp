#include "spinradar/diagnose/associate.hpp"

#include <algorithm>
#include <cmath>

#include "spinradar/core/lie.hpp"

namespace spinradar::diagnose {
namespace {

double parabolaVertex(double m, double c, double p) {
  const double den = m - 2.0 * c + p;
  if (den >= 0) return 0.0;  // not a maximum
  return std::clamp(0.5 * (m - p) / den, -0.5, 0.5);
}

double segmentDistance(double px, double py, const sim::Wall& w) {
  const double dx = w.x2 - w.x1, dy = w.y2 - w.y1;
  const double l2 = dx * dx + dy * dy;
  double t = l2 > 0 ? ((px - w.x1) * dx + (py - w.y1) * dy) / l2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(px - (w.x1 + t * dx), py - (w.y1 + t * dy));
}

double cross(double ax, double ay, double bx, double by) { return ax * by - ay * bx; }

bool segmentsCross(double ax, double ay, double bx, double by, const sim::Wall& w) {
  const double d1 = cross(bx - ax, by - ay, w.x1 - ax, w.y1 - ay);
  const double d2 = cross(bx - ax, by - ay, w.x2 - ax, w.y2 - ay);
  const double d3 = cross(w.x2 - w.x1, w.y2 - w.y1, ax - w.x1, ay - w.y1);
  const double d4 = cross(w.x2 - w.x1, w.y2 - w.y1, bx - w.x1, by - w.y1);
  return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0));
}

}  // namespace

std::optional<Peak> measurePeak(const PolarScan& scan, const ScanGeometry& geo, double range,
                                double azimuth, const Gate& gate, const PeakOptions& opt) {
  const int n = static_cast<int>(geo.azimuth.size());
  const double p_lo = geo.positionOf(azimuth - gate.azimuth);
  double p_hi = geo.positionOf(azimuth + gate.azimuth);
  if (p_hi < p_lo) return std::nullopt;  // gate straddles the scan seam
  const int i0 = static_cast<int>(std::ceil(p_lo)), i1 = static_cast<int>(std::floor(p_hi));
  if (i0 < 1 || i1 > n - 2 || i1 - i0 < 2) return std::nullopt;
  const int b0 = static_cast<int>(std::ceil(scan.binOfRange(range - gate.range)));
  const int b1 = static_cast<int>(std::floor(scan.binOfRange(range + gate.range)));
  if (b0 < 2 || b1 > scan.bins - 3 || b1 - b0 < 2) return std::nullopt;

  int bi = i0, bb = b0;
  int best = -1;
  thread_local std::vector<uint8_t> cells;
  cells.clear();
  for (int i = i0; i <= i1; ++i) {
    const uint8_t* row = scan.row(geo.row[i]);
    for (int b = b0; b <= b1; ++b) {
      cells.push_back(row[b]);
      if (row[b] > best) {
        best = row[b];
        bi = i;
        bb = b;
      }
    }
  }
  if (bi == i0 || bi == i1 || bb == b0 || bb == b1) return std::nullopt;
  std::nth_element(cells.begin(), cells.begin() + cells.size() / 2, cells.end());
  const double median = cells[cells.size() / 2];
  Peak pk;
  pk.power = best;
  pk.contrast = best - median;
  if (pk.contrast < opt.min_contrast) return std::nullopt;

  const uint8_t* row = scan.row(geo.row[bi]);
  const double db = parabolaVertex(row[bb - 1], row[bb], row[bb + 1]);
  pk.range = scan.rangeOfBin(bb + db);
  auto rowMax = [&](int i) {
    const uint8_t* r = scan.row(geo.row[i]);
    return static_cast<double>(*std::max_element(r + bb - 2, r + bb + 3));
  };
  const double da = parabolaVertex(rowMax(bi - 1), rowMax(bi), rowMax(bi + 1));
  pk.azimuth = geo.azimuthAt(bi + da);
  return pk;
}

std::vector<TargetView> targetViews(int scan_index, const PolarScan& scan,
                                    const ScanGeometry& geo, const sim::World& world,
                                    const sim::Trajectory& traj, const sim::PhysicsConfig& base,
                                    const ModelConventions& conv, const ViewOptions& opt) {
  std::vector<TargetView> views;
  const double max_range = scan.rangeOfBin(scan.bins - 1) - opt.max_range_margin;
  for (int k = 0; k < static_cast<int>(world.targets.size()); ++k) {
    const sim::Target& t = world.targets[k];
    if (t.vx != 0.0 || t.vy != 0.0) continue;  // moving objects are not static references
    TargetView v;
    v.scan = scan_index;
    v.target = k;
    v.pred = predictTarget(t, geo, traj, base, conv);
    if (!v.pred.ok || v.pred.range < opt.min_range || v.pred.range > max_range) continue;
    const Eigen::Vector3d vel = traj.bodyVelocity(v.pred.stamp - base.timestamp_offset);
    const double speed = std::hypot(vel.x(), vel.y()), w = std::fabs(vel.z());
    v.gate.range = std::max(opt.gate_range_min, 0.6 + 0.3 * speed);
    v.gate.azimuth = std::max(opt.gate_azimuth_min,
                              0.03 + 0.2 * w + 0.3 * speed / std::max(v.pred.range, 1.0));
    views.push_back(v);
  }
  // Isolation: a view is kept when it dominates its gate: every other return that could fall
  // inside (targets, wall scatterers) is at least opt.dominance_db weaker, so the recorded and
  // re-simulated peaks are the same scatterer (weaker neighbours shift both alike). Views are
  // sorted by range so that only neighbours in range are compared.
  std::vector<size_t> order(views.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](size_t x, size_t y) { return views[x].pred.range < views[y].pred.range; });
  std::vector<bool> keep(views.size(), true);
  for (size_t oi = 0; oi < order.size(); ++oi) {
    const size_t a = order[oi];
    const TargetView& va = views[a];
    const sim::Target& ta = world.targets[va.target];
    const double win = 2.0 * va.gate.range + 0.5;
    for (int dir = -1; dir <= 1 && keep[a]; dir += 2) {
      for (long oj = static_cast<long>(oi) + dir; oj >= 0 && oj < static_cast<long>(order.size());
           oj += dir) {
        const TargetView& vb = views[order[oj]];
        if (std::fabs(va.pred.range - vb.pred.range) >= win) break;
        if (std::fabs(se2::wrapAngle(va.pred.azimuth - vb.pred.azimuth)) < 2.0 * va.gate.azimuth &&
            world.targets[vb.target].rcs > ta.rcs - opt.dominance_db) {
          keep[a] = false;
          break;
        }
      }
    }
    if (!keep[a]) continue;
    const sim::Pose2 s = traj.at(va.pred.stamp - base.timestamp_offset);
    const double c = std::cos(s.yaw), sn = std::sin(s.yaw);
    // Polar footprint of the gate, widened by the point spread (~0.5 m, ~1.5 deg).
    const double half_r = 1.5 * va.gate.range + 0.5, half_a = 1.5 * va.gate.azimuth + 0.025;
    const double reach = half_r + va.pred.true_range * half_a + 1.0;
    const double bearing = va.pred.azimuth - base.azimuth_offset;
    for (const sim::Wall& w : world.walls) {
      if (!keep[a]) break;
      // A wall scatterer every ~0.25 m: rcs_per_m - 6 dB, texture up to ~+20 dB.
      const bool wall_weak = w.rcs_per_m - 6.0 + 20.0 + opt.dominance_db <= ta.rcs;
      if (segmentsCross(s.x, s.y, ta.x, ta.y, w)) {
        keep[a] = false;  // shadowed
        continue;
      }
      if (wall_weak || segmentDistance(ta.x, ta.y, w) > reach) continue;
      // Walk the wall in 0.2 m steps; any point inside the footprint spoils the gate.
      const double len = std::hypot(w.x2 - w.x1, w.y2 - w.y1);
      const int n = std::max(2, static_cast<int>(len / 0.2) + 1);
      for (int i = 0; i <= n && keep[a]; ++i) {
        const double u = static_cast<double>(i) / n;
        const double dx = w.x1 + u * (w.x2 - w.x1) - s.x, dy = w.y1 + u * (w.y2 - w.y1) - s.y;
        const double xs = c * dx + sn * dy, ys = -sn * dx + c * dy;
        if (std::fabs(std::hypot(xs, ys) - va.pred.true_range) < half_r &&
            std::fabs(se2::wrapAngle(std::atan2(-ys, xs) - bearing)) < half_a)
          keep[a] = false;
      }
    }
  }
  std::vector<TargetView> out;
  for (size_t a = 0; a < views.size(); ++a)
    if (keep[a]) out.push_back(views[a]);
  return out;
}

}  // namespace spinradar::diagnose
