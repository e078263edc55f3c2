#pragma once
// Generated scenes and drives for the diagnosis tests: random point-target fields (with a few
// walls), motion profiles, and recordings rendered by the simulator with one effect hidden.
#include <random>
#include <vector>

#include "spinradar/diagnose/diagnose.hpp"
#include "spinradar/sim/simulator.hpp"

namespace spinradar::diagnose::testing {

/// Point targets scattered around the drive (uniform in a box), plus optional walls.
inline sim::World randomWorld(uint64_t seed, int n_targets, double half_extent, bool walls) {
  std::mt19937 rng(static_cast<uint32_t>(seed));
  std::uniform_real_distribution<double> u(-half_extent, half_extent), rcs(12.0, 25.0);
  sim::World w;
  for (int i = 0; i < n_targets; ++i) {
    sim::Target t;
    t.x = u(rng);
    t.y = u(rng);
    if (std::hypot(t.x, t.y) < 6.0) continue;
    t.rcs = rcs(rng);
    w.targets.push_back(t);
  }
  if (walls) {
    w.walls.push_back({-half_extent, half_extent + 8, half_extent, half_extent + 8, 0.0});
    w.walls.push_back({half_extent + 8, -half_extent, half_extent + 8, 10.0, 0.0});
  }
  return w;
}

/// Small sensor: fewer bins keep the renders quick (range 1800 x 0.0438 = 79 m).
inline sim::SensorConfig smallSensor() {
  sim::SensorConfig s;
  s.bins = 1800;
  return s;
}

struct Drive {
  std::vector<sim::Trajectory::Segment> segments;
  sim::Pose2 start;
};

/// Renders n scans of a recording with the hidden physics.
inline DiagnoseInput makeInput(const sim::World& world, const Drive& drive,
                               const sim::PhysicsConfig& hidden, int n_scans, uint64_t seed,
                               const sim::SensorConfig& sensor = smallSensor()) {
  DiagnoseInput in;
  in.world = world;
  in.trajectory = sim::Trajectory::fromProfile(drive.segments, drive.start, 100.0, 100.0);
  in.sensor = sensor;
  sim::Simulator s(world, in.trajectory, sensor, hidden, seed);
  const int first = 2;  // leave room for negative latencies before the first scan
  for (int k = 0; k < n_scans; ++k) in.scans.push_back(s.renderScan(first + k));
  return in;
}

}  // namespace spinradar::diagnose::testing
