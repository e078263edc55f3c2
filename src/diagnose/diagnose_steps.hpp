#pragma once
// The steps of diagnose() (private to src/diagnose): associate and re-simulate with the base
// physics (observations.cpp), name and fit the effects (name_fit.cpp), re-simulate with the
// fitted effects and compare before/after (resimulate.cpp).
#include <array>
#include <cmath>
#include <functional>
#include <vector>

#include "spinradar/core/lie.hpp"
#include "spinradar/diagnose/diagnose.hpp"
#include "spinradar/sim/simulator.hpp"

namespace spinradar::diagnose::detail {

// Precision a parabolic peak fit can claim: 1/50 of a bin, 1/50 of a row.
inline double rangeNoiseFloor(const sim::SensorConfig& s) { return 0.02 * s.range_resolution; }
inline double azimuthNoiseFloor(const sim::SensorConfig& s) {
  return 0.02 * 2.0 * M_PI / s.azimuths;
}

/// Scene mapped from the recording (no world file, scene_map.hpp): how each mapped target's
/// position moves with every effect parameter (the map is placed under the physics being
/// tested), the covariance of each mapped position (map noise), and the map re-placed under
/// another physics (for the re-simulation with the fitted effects).
struct MapModel {
  std::vector<std::array<Eigen::Vector2d, kNumEffects>> dpos;  ///< m per parameter unit
  std::vector<Eigen::Matrix2d> cov;                             ///< m^2
  std::function<sim::World(const sim::PhysicsConfig&)> remap;
};

struct Measured {
  bool ok = false;
  double range = 0, azimuth = 0;
};

/// Renders the scan whose recorded first stamp is that of `real` under the simulator's physics
/// and measures every view's peak in it.
std::vector<Measured> measureSimulated(const sim::Simulator& sim, const PolarScan& real,
                                       const ScanGeometry& geo_real,
                                       const std::vector<const Observation*>& views,
                                       const std::vector<Gate>& gates, const DiagnoseInput& in,
                                       const DiagnoseOptions& opt,
                                       const sim::World* world = nullptr);

/// Noise scale of one residual type (robust, floored).
double noiseScale(const std::vector<double>& v, double floor);

/// Residual RMS figures over the used observations; with `demean` (target positions as
/// nuisance) after removing each target's mean residual.
ResidualStats residualStats(bool demean, const std::vector<Observation>& obs,
                            std::vector<double> er, std::vector<double> eaz,
                            const std::vector<bool>& use, double sweep);

/// What step 1 leaves for the re-simulation in step 5.
struct Association {
  std::vector<ScanGeometry> geos;            ///< per recorded scan
  std::vector<std::vector<int>> obs_of_scan; ///< indices into rep.obs
  std::vector<Gate> gate_of_obs;             ///< per observation
  double sweep = 0;                          ///< mean sweep duration, s
};

/// Step 1: predicts every world target into each scan, measures it in the recording and in the
/// base re-simulation, computes the regressors; fills rep.obs and rep.targets_used. Throws when
/// fewer than 10 target returns are associated.
/// With a MapModel the regressors include the map's own dependence on each parameter.
Association associateObservations(const DiagnoseInput& in, const DiagnoseOptions& opt,
                                  const std::vector<Effect>& cands, DiagnoseReport& rep,
                                  const MapModel* map = nullptr);

/// Steps 2-4: robust scales and outliers (two passes), stepwise selection, candidate table,
/// joint fit of the selected effects, confounding and identifiability notes. Fills rep.sigma_*,
/// outliers, candidate_corr, candidates, effects, notes, fitted, mismatch_found.
/// With a MapModel the residuals of each target are whitened jointly (generalised least
/// squares): its map noise is common to all of its test views.
void nameAndFitEffects(const DiagnoseInput& in, const DiagnoseOptions& opt,
                       const std::vector<Effect>& cands, DiagnoseReport& rep,
                       const MapModel* map = nullptr);

/// Step 5: residual figures before, then re-simulation with the effects added one at a time
/// (ablation: an effect that does not lower the re-simulated residual is dropped to the notes).
/// With a MapModel every trial physics re-places the map before rendering.
void resimulateWithEffects(const DiagnoseInput& in, const DiagnoseOptions& opt,
                           const Association& as, DiagnoseReport& rep,
                           const MapModel* map = nullptr);

}  // namespace spinradar::diagnose::detail
