#include "spinradar/diagnose/associate.hpp"

#include <algorithm>
#include <cmath>

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

double wrapPi(double a) { return std::remainder(a, 2.0 * M_PI); }

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
  // Isolation: drop views whose gates could hold another target, a wall, or are shadowed.
  std::vector<bool> keep(views.size(), true);
  for (size_t a = 0; a < views.size(); ++a) {
    const TargetView& va = views[a];
    const sim::Target& ta = world.targets[va.target];
    for (size_t b = 0; b < views.size() && keep[a]; ++b) {
      if (a == b) continue;
      const TargetView& vb = views[b];
      if (std::fabs(va.pred.range - vb.pred.range) < 2.0 * va.gate.range &&
          std::fabs(wrapPi(va.pred.azimuth - vb.pred.azimuth)) < 2.0 * va.gate.azimuth)
        keep[a] = false;
    }
    const sim::Pose2 s = traj.at(va.pred.stamp - base.timestamp_offset);
    for (const sim::Wall& w : world.walls) {
      if (!keep[a]) break;
      if (segmentDistance(ta.x, ta.y, w) <
          va.gate.range + va.pred.range * va.gate.azimuth * 2.0 + 0.5)
        keep[a] = false;
      else if (segmentsCross(s.x, s.y, ta.x, ta.y, w))
        keep[a] = false;
    }
  }
  std::vector<TargetView> out;
  for (size_t a = 0; a < views.size(); ++a)
    if (keep[a]) out.push_back(views[a]);
  return out;
}

}  // namespace spinradar::diagnose
