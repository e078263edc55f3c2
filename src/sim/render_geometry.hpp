#pragma once
// Plane geometry of the renderer (render_scan.cpp) and the scenes' trajectories (scene.cpp):
// angle wrapping as the simulator has always rounded it (a recording renders bit for bit as
// before), a fast atan2 for bucketing, ray and point distances to a wall segment.
#include <algorithm>
#include <cmath>

#include "spinradar/sim/scene.hpp"

namespace spinradar::sim::detail {

constexpr double kTwoPi = 2 * M_PI;
/// a wrapped into [-pi, pi) by fmod (not se2::wrapAngle: its exact remainder rounds
/// differently in the last bit, which would change every rendered recording).
inline double wrapPi(double a) {
  a = std::fmod(a + M_PI, kTwoPi);
  if (a < 0) a += kTwoPi;
  return a - M_PI;
}
inline double wrap2Pi(double a) {
  a = std::fmod(a, kTwoPi);
  return a < 0 ? a + kTwoPi : a;
}

// atan2 to ~1e-5 rad (minimax polynomial on [0, 1] plus octant folding): plenty for
// bucketing and occlusion lookups, several times faster than libm.
inline double fastAtan2(double y, double x) {
  double ax = std::abs(x), ay = std::abs(y);
  double mx = std::max(ax, ay), mn = std::min(ax, ay);
  if (mx == 0) return 0;
  double t = mn / mx, t2 = t * t;
  double r = ((((-0.0117212 * t2 + 0.05265332) * t2 - 0.11643287) * t2 + 0.19354346) * t2 -
              0.33262347) * t2 + 0.99997726;
  r *= t;
  if (ay > ax) r = M_PI / 2 - r;
  if (x < 0) r = M_PI - r;
  return y < 0 ? -r : r;
}

// Clockwise sensor azimuth of world point (x, y) seen from pose (px, py, cos, sin yaw).
inline double bearingCw(double x, double y, double px, double py, double c, double s) {
  double dx = x - px, dy = y - py;
  double xs = c * dx + s * dy, ys = -s * dx + c * dy;
  double a = fastAtan2(-ys, xs);
  return a < 0 ? a + kTwoPi : a;
}

// Distance along a ray (o + t d, |d| = 1) to a segment, or -1.
inline double raySegment(double ox, double oy, double dx, double dy, const Wall& w) {
  double ex = w.x2 - w.x1, ey = w.y2 - w.y1;
  double den = dx * ey - dy * ex;
  if (std::abs(den) < 1e-12) return -1;
  double qx = w.x1 - ox, qy = w.y1 - oy;
  double t = (qx * ey - qy * ex) / den;
  double u = (qx * dy - qy * dx) / den;
  if (t <= 0 || u < 0 || u > 1) return -1;
  return t;
}

inline double pointSegmentDistance(double px, double py, const Wall& w) {
  double ex = w.x2 - w.x1, ey = w.y2 - w.y1;
  double l2 = ex * ex + ey * ey;
  double u = std::clamp(((px - w.x1) * ex + (py - w.y1) * ey) / l2, 0.0, 1.0);
  return std::hypot(w.x1 + u * ex - px, w.y1 + u * ey - py);
}

}  // namespace spinradar::sim::detail
