#pragma once
// The steps of diagnose() (private to src/diagnose): associate and re-simulate with the base
// physics (observations.cpp), name and fit the effects (name_fit.cpp), re-simulate with the
// fitted effects and compare before/after (resimulate.cpp).
#include <cmath>
#include <vector>

#include "spinradar/diagnose/diagnose.hpp"
#include "spinradar/sim/simulator.hpp"

namespace spinradar::diagnose::detail {

inline double wrapPi(double a) { return std::remainder(a, 2.0 * M_PI); }

// Precision a parabolic peak fit can claim: 1/50 of a bin, 1/50 of a row.
inline double rangeNoiseFloor(const sim::SensorConfig& s) { return 0.02 * s.range_resolution; }
inline double azimuthNoiseFloor(const sim::SensorConfig& s) {
  return 0.02 * 2.0 * M_PI / s.azimuths;
}

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
                                       const DiagnoseOptions& opt);

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
Association associateObservations(const DiagnoseInput& in, const DiagnoseOptions& opt,
                                  const std::vector<Effect>& cands, DiagnoseReport& rep);

/// Steps 2-4: robust scales and outliers (two passes), stepwise selection, candidate table,
/// joint fit of the selected effects, confounding and identifiability notes. Fills rep.sigma_*,
/// outliers, candidate_corr, candidates, effects, notes, fitted, mismatch_found.
void nameAndFitEffects(const DiagnoseInput& in, const DiagnoseOptions& opt,
                       const std::vector<Effect>& cands, DiagnoseReport& rep);

/// Step 5: residual figures before, then re-simulation with the effects added one at a time
/// (ablation: an effect that does not lower the re-simulated residual is dropped to the notes).
void resimulateWithEffects(const DiagnoseInput& in, const DiagnoseOptions& opt,
                           const Association& as, DiagnoseReport& rep);

}  // namespace spinradar::diagnose::detail
