#pragma once
// Scene model from the recording itself (no world file): strong returns of the map scans are
// placed in the world with the trajectory under the base physics; locations seen in enough
// scans become point targets. Map and test scans are disjoint so the effect is not fitted
// into the map (issue 10). The map keeps its peaks, so it can be re-placed under any physics:
// the mapped positions are themselves a function of the effect parameters (map-aware
// regressors, re-simulation with the fitted effects; docs/diagnose.md).
#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "spinradar/core/polar_scan.hpp"
#include "spinradar/sim/physics.hpp"
#include "spinradar/sim/scene.hpp"
#include "spinradar/sim/sensor_config.hpp"

namespace spinradar::diagnose {

struct SceneMapOptions {
  double min_contrast = 25.0;   ///< counts above the row median for a peak
  double cluster_radius = 1.0;  ///< m (wide: a wrong physics scatters a target's placements)
  double min_fraction = 0.5;    ///< of the map scans a location must be seen in
  double min_range = 4.0;       ///< m
  /// Isolation: another peak of the same scan within this window and less than dominance_db
  /// weaker makes the target's peak crowded; targets crowded in more than
  /// max_crowded_fraction of their scans are not mapped.
  double isolation_range = 2.0;      ///< m
  double isolation_azimuth = 0.1;    ///< rad
  double spread_range = 0.3;         ///< m: peaks closer than this and
  double spread_azimuth = 0.04;      ///< rad: this are the same return (point spread)
  double dominance_db = 8.0;
  double max_crowded_fraction = 0.25;
};

/// One peak of a map scan as recorded (reported range and azimuth, recorded stamps).
struct MapPeak {
  int scan = 0;
  double range = 0, azimuth = 0;  ///< m, rad clockwise (reported)
  double stamp = 0;               ///< s, recorded stamp of the row
  double first_stamp = 0, sweep = 0.25;  ///< of the scan
  double power = 0;               ///< counts at the peak
};

struct SceneMap {
  sim::World world;                        ///< one point target per stable cluster
  std::vector<std::vector<MapPeak>> members;  ///< peaks of each target
  std::vector<int> map_scans, test_scans;  ///< indices into the recording
  std::string split;                       ///< description of the split used
  int peaks = 0;                           ///< peaks placed
};

/// World position of a map peak when the recording is read under `physics` (the inverse of
/// predictTarget for that one return).
Eigen::Vector2d placePeak(const MapPeak& p, const sim::Trajectory& traj,
                          const sim::PhysicsConfig& physics);

/// The map's targets re-placed under `physics` (same peaks, same clusters, same order).
sim::World replaceMap(const SceneMap& map, const sim::Trajectory& traj,
                      const sim::PhysicsConfig& physics);

/// Which scans build the map: "early-late" (first half maps, second half is diagnosed),
/// "late-early", "out-back" (the scans before the heading has turned by 90 degrees map, when
/// the drive reverses its heading), or "auto" (out-back when the drive reverses, otherwise
/// early-late). Peaks are grouped into targets as placed under `cluster_physics` (default: the
/// base; a fitted physics groups them more tightly), the targets are placed under `base`.
SceneMap buildSceneMap(const std::vector<PolarScan>& scans, const sim::Trajectory& traj,
                       const sim::SensorConfig& sensor, const sim::PhysicsConfig& base,
                       const std::string& split = "early-late", const SceneMapOptions& opt = {},
                       const sim::PhysicsConfig* cluster_physics = nullptr);

}  // namespace spinradar::diagnose
