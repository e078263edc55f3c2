#pragma once
// Scene model from the recording itself (no world file): strong returns of the map scans are
// placed in the world with the trajectory under the base physics; locations seen in enough
// scans become point targets. Map and test scans are disjoint so the effect is not fitted
// into the map (issue 10).
#include <string>
#include <vector>

#include "spinradar/core/polar_scan.hpp"
#include "spinradar/sim/physics.hpp"
#include "spinradar/sim/scene.hpp"
#include "spinradar/sim/sensor_config.hpp"

namespace spinradar::diagnose {

struct SceneMapOptions {
  double min_contrast = 25.0;   ///< counts above the row median for a peak
  double cluster_radius = 0.5;  ///< m
  double min_fraction = 0.5;    ///< of the map scans a location must be seen in
  double min_range = 4.0;       ///< m
};

struct SceneMap {
  sim::World world;
  std::vector<int> map_scans, test_scans;  ///< indices into the recording
  std::string split;                       ///< description of the split used
  int peaks = 0;                           ///< peaks placed
};

/// Which scans build the map: "early-late" (first half maps, second half is diagnosed),
/// "late-early", or "out-back" (the half before the largest heading reversal maps).
SceneMap buildSceneMap(const std::vector<PolarScan>& scans, const sim::Trajectory& traj,
                       const sim::SensorConfig& sensor, const sim::PhysicsConfig& base,
                       const std::string& split = "early-late", const SceneMapOptions& opt = {});

}  // namespace spinradar::diagnose
