#pragma once
// Renders polar scans of a world seen by a spinning FMCW radar moving along a trajectory.
#include <cstdint>
#include <memory>
#include <string>

#include "spinradar/core/polar_scan.hpp"
#include "spinradar/sim/physics.hpp"
#include "spinradar/sim/scene.hpp"
#include "spinradar/sim/sensor_config.hpp"

namespace spinradar::sim {

class Simulator {
 public:
  Simulator(World world, Trajectory trajectory, SensorConfig sensor, PhysicsConfig physics,
            uint64_t seed = 1);
  ~Simulator();

  /// Scan k starts (true acquisition time of its first azimuth) at
  /// trajectory.startTime() + k / rotation_hz. Stamps carry timestamp_offset.
  PolarScan renderScan(int k) const;
  /// Scan whose first azimuth is acquired at true time t0 (s).
  PolarScan renderScanAt(double t0) const;
  /// How many whole rotations fit in the trajectory.
  int scanCount() const;

  const World& world() const;
  const Trajectory& trajectory() const;
  const SensorConfig& sensor() const;
  const PhysicsConfig& physics() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Writes a recording folder: radar/<first stamp us>.png (Oxford layout), radar.timestamps,
/// trajectory.csv, world.json, physics.json, sensor.json. Returns the number of scans.
int writeRecording(const Simulator& sim, const std::string& dir, int first_scan = 0,
                   int n_scans = -1, bool progress = false);

}  // namespace spinradar::sim
