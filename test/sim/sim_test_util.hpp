#pragma once
// Helpers for the simulator tests: tiny scenes and peak measurement on rendered scans.
#include <cmath>
#include <vector>

#include "spinradar/sim/simulator.hpp"

namespace spinradar::sim::testing {

/// A sensor moving at constant body velocity (vx fwd, wz CCW) from `start` for `dur` s.
inline Trajectory constantMotion(double vx, double wz, Pose2 start = {}, double dur = 3.0) {
  return Trajectory::fromProfile({{dur, vx, wz}}, start, 0.0, 200.0);
}

/// The evaluation matrix's full physics: motion distortion, Doppler (beta 0.049 s), moving cars.
inline PhysicsConfig fullPhysics() {
  PhysicsConfig p;
  p.motion_distortion = true;
  p.doppler = 0.049;
  p.moving_objects = true;
  return p;
}

inline World oneTarget(double x, double y, double rcs = 25.0) {
  World w;
  w.targets.push_back({x, y, rcs, 0, 0});
  return w;
}

struct Peak {
  int azimuth = -1;
  int bin = -1;
  int value = 0;
  double fine_bin = 0;  ///< power centroid over the mainlobe
};

/// Brightest cell (optionally within an azimuth window) with a sub-bin power centroid.
inline Peak findPeak(const PolarScan& s, int a0 = 0, int a1 = -1, int b0 = 0, int b1 = -1) {
  if (a1 < 0) a1 = s.azimuths - 1;
  if (b1 < 0) b1 = s.bins - 1;
  Peak p;
  for (int a = a0; a <= a1; ++a)
    for (int b = b0; b <= b1; ++b)
      if (s.row(a)[b] > p.value) {
        p.value = s.row(a)[b];
        p.azimuth = a;
        p.bin = b;
      }
  double sw = 0, swb = 0;
  for (int b = std::max(0, p.bin - 3); b <= std::min(s.bins - 1, p.bin + 3); ++b) {
    double w = std::pow(10.0, s.row(p.azimuth)[b] / 10.0);
    sw += w;
    swb += w * b;
  }
  p.fine_bin = swb / sw;
  return p;
}

inline double wrapPi(double a) { return std::atan2(std::sin(a), std::cos(a)); }

}  // namespace spinradar::sim::testing
