#include "spinradar/diagnose/predict.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace spinradar::diagnose {
namespace {
constexpr double kTwoPi = 2.0 * M_PI;
}

ScanGeometry ScanGeometry::fromScan(const PolarScan& scan) {
  ScanGeometry g;
  double prev = 0;
  for (int a = 0; a < scan.azimuths; ++a) {
    if (!scan.valid.empty() && !scan.valid[a]) continue;
    double az = scan.azimuth[a];
    if (!g.azimuth.empty()) {
      while (az <= prev) az += kTwoPi;  // unwrap: strictly increasing
      while (az - prev > M_PI) az -= kTwoPi;
      if (az <= prev) continue;         // duplicated row
    }
    g.azimuth.push_back(az);
    g.stamp.push_back(static_cast<double>(scan.stamp_ns[a]) * 1e-9);
    g.row.push_back(a);
    prev = az;
  }
  if (g.azimuth.size() < 4) throw std::runtime_error("scan has fewer than 4 valid rows");
  const size_t n = g.azimuth.size();
  const double span = g.azimuth.back() - g.azimuth.front();
  const double dt = g.stamp.back() - g.stamp.front();
  g.sweep = span > 0 && dt > 0 ? dt * kTwoPi / span : 0.25;
  (void)n;
  return g;
}

double ScanGeometry::positionOf(double az) const {
  const double a0 = azimuth.front();
  az = a0 + std::fmod(std::fmod(az - a0, kTwoPi) + kTwoPi, kTwoPi);
  const size_t n = azimuth.size();
  if (az >= azimuth.back()) {  // between the last row and the wrap: extrapolate
    const double step = azimuth[n - 1] - azimuth[n - 2];
    return static_cast<double>(n - 1) + (az - azimuth.back()) / step;
  }
  const auto it = std::upper_bound(azimuth.begin(), azimuth.end(), az);
  const size_t i = static_cast<size_t>(it - azimuth.begin()) - 1;
  return static_cast<double>(i) + (az - azimuth[i]) / (azimuth[i + 1] - azimuth[i]);
}

namespace {
double interp(const std::vector<double>& v, double pos) {
  const int n = static_cast<int>(v.size());
  int i = static_cast<int>(std::floor(pos));
  i = std::clamp(i, 0, n - 2);
  const double f = pos - i;
  return v[i] + f * (v[i + 1] - v[i]);
}
}  // namespace

double ScanGeometry::stampAt(double pos) const { return interp(stamp, pos); }
double ScanGeometry::azimuthAt(double pos) const { return interp(azimuth, pos); }

Prediction predictTarget(const sim::Target& target, const ScanGeometry& geo,
                         const sim::Trajectory& traj, const sim::PhysicsConfig& ph,
                         const ModelConventions& conv, const PoseDelta& delta) {
  Prediction p;
  const double dts = ph.timestamp_offset;
  // The simulator's "scan_pose_time": "start" extra moves the instant pose to the first azimuth.
  const auto it = ph.extra.find("scan_pose_time");
  const bool at_start = it != ph.extra.end() && it->is_string() && *it == "start";
  const double frac = at_start ? 0.0 : conv.instant_fraction;
  const double t_instant = geo.firstStamp() - dts + frac * geo.sweep;
  double pos = 0.5 * static_cast<double>(geo.azimuth.size());
  for (int iter = 0; iter < 4; ++iter) {
    const double t_true = geo.stampAt(pos) - dts;
    const double t_pose = ph.motion_distortion ? t_true : t_instant;
    const sim::Pose2 s = traj.at(t_pose);
    const double yaw = s.yaw + delta.dyaw;
    const double c = std::cos(yaw), sn = std::sin(yaw);
    const double sx = s.x + c * delta.dx - sn * delta.dy;
    const double sy = s.y + sn * delta.dx + c * delta.dy;
    const double wx = target.x - sx, wy = target.y - sy;
    const double xs = c * wx + sn * wy, ys = -sn * wx + c * wy;  // sensor frame
    const double rho = std::hypot(xs, ys);
    if (rho < 1e-6) return p;
    const double bearing_cw = std::atan2(-ys, xs);
    const double az_rep = bearing_cw + ph.azimuth_offset;
    const double new_pos = geo.positionOf(az_rep);
    double range = rho + ph.range_offset;
    if (ph.doppler != 0.0) {
      // Apparent range r - beta * u, u = sensor velocity along the ray to the target.
      const Eigen::Vector3d v = traj.bodyVelocity(t_pose);  // as the simulator: at the pose
      range -= ph.doppler * (v.x() * xs + v.y() * ys) / rho;
    }
    p.range = range;
    p.true_range = rho;
    p.position = new_pos;
    p.azimuth = geo.azimuth.front() + std::fmod(std::fmod(az_rep - geo.azimuth.front(), kTwoPi) +
                                                    kTwoPi, kTwoPi);
    p.stamp = geo.stampAt(new_pos);
    if (std::fabs(new_pos - pos) < 1e-6) break;
    pos = new_pos;
  }
  p.ok = true;
  return p;
}

const std::vector<Effect>& allEffects() {
  static const std::vector<Effect> e = {Effect::MotionDistortion, Effect::Doppler,
                                        Effect::TimestampOffset, Effect::AzimuthOffset,
                                        Effect::RangeOffset};
  return e;
}

std::string effectName(Effect e) {
  switch (e) {
    case Effect::MotionDistortion: return "motion_distortion";
    case Effect::Doppler: return "doppler";
    case Effect::TimestampOffset: return "timestamp_offset";
    case Effect::AzimuthOffset: return "azimuth_offset";
    case Effect::RangeOffset: return "range_offset";
  }
  return "?";
}

std::string effectParameter(Effect e) {
  switch (e) {
    case Effect::MotionDistortion: return "fraction";
    case Effect::Doppler: return "beta";
    case Effect::TimestampOffset: return "offset";
    case Effect::AzimuthOffset: return "offset";
    case Effect::RangeOffset: return "offset";
  }
  return "?";
}

std::string effectUnit(Effect e) {
  switch (e) {
    case Effect::MotionDistortion: return "";
    case Effect::Doppler: return "s";
    case Effect::TimestampOffset: return "s";
    case Effect::AzimuthOffset: return "rad";
    case Effect::RangeOffset: return "m";
  }
  return "";
}

sim::PhysicsConfig withEffect(const sim::PhysicsConfig& base, Effect e, double d) {
  sim::PhysicsConfig p = base;
  switch (e) {
    case Effect::MotionDistortion: p.motion_distortion = base.motion_distortion || d > 0.5; break;
    case Effect::Doppler: p.doppler += d; break;
    case Effect::TimestampOffset: p.timestamp_offset += d; break;
    case Effect::AzimuthOffset: p.azimuth_offset += d; break;
    case Effect::RangeOffset: p.range_offset += d; break;
  }
  return p;
}

double effectValue(const sim::PhysicsConfig& p, Effect e) {
  switch (e) {
    case Effect::MotionDistortion: return p.motion_distortion ? 1.0 : 0.0;
    case Effect::Doppler: return p.doppler;
    case Effect::TimestampOffset: return p.timestamp_offset;
    case Effect::AzimuthOffset: return p.azimuth_offset;
    case Effect::RangeOffset: return p.range_offset;
  }
  return 0;
}

double effectStep(Effect e) {
  switch (e) {
    case Effect::MotionDistortion: return 1.0;
    case Effect::Doppler: return 0.01;
    case Effect::TimestampOffset: return 0.005;
    case Effect::AzimuthOffset: return 0.002;
    case Effect::RangeOffset: return 0.05;
  }
  return 1.0;
}

}  // namespace spinradar::diagnose
