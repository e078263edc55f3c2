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

/// Conventions (see also physics.hpp):
/// - Azimuth a of scan k is acquired at t0 + a / (azimuths * rotation_hz) (true time) and
///   reported at that time + timestamp_offset (stamp_ns = llround(t * 1e9)); encoder =
///   a * encoder_size / azimuths; reported angle = encoder angle; true beam angle = reported -
///   azimuth_offset.
/// - motion_distortion on: each azimuth from the pose (and velocity) at its own time; off: the
///   whole rotation from the pose at MID-scan, t0 + 0.5 / rotation_hz (extra key
///   "scan_pose_time": "start" selects t0 instead).
/// - moving_objects off: targets with a velocity are left out (the static world is rendered).
/// - Doppler: apparent range r - beta * u, u = closing speed (sensor minus target velocity
///   along the beam); with "chirp_alternate" the sign flips on odd azimuths (chirp_up = 0).
/// - Noise is a function of (seed, scan) only: renderScan(k) is deterministic and const, and
///   safe to call from several threads at once (per-thread work buffers).
/// - Speed: 25-70 full 400 x 3768 rotations per second on one core for the built-in scenes.
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
