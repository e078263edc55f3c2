#pragma once
// Where a static point target appears in a scan under a given physics configuration:
// reported range, reported azimuth and recorded stamp. The forward model of the simulator's
// catalogue in closed form (used for association gates and for the effect regressors, which
// are finite differences of this prediction with respect to each effect's parameter).
#include <string>
#include <vector>

#include "spinradar/core/polar_scan.hpp"
#include "spinradar/sim/physics.hpp"
#include "spinradar/sim/scene.hpp"

namespace spinradar::diagnose {

/// Row timing of one scan as recorded: unwrapped reported azimuths and stamps per valid row.
struct ScanGeometry {
  std::vector<double> azimuth;  ///< rad, clockwise, unwrapped and increasing from row 0
  std::vector<double> stamp;    ///< s, recorded stamps
  std::vector<int> row;         ///< source row index in the PolarScan
  double sweep = 0.25;          ///< s, duration of one rotation
  static ScanGeometry fromScan(const PolarScan& scan);
  /// Fractional row position (into `azimuth`) of an azimuth, wrapped into [az0, az0 + 2 pi).
  double positionOf(double azimuth_cw) const;
  double stampAt(double position) const;
  double azimuthAt(double position) const;
  double firstStamp() const { return stamp.front(); }
};

/// Conventions of the simulator that the closed form needs (read from its implementation).
struct ModelConventions {
  /// Without motion distortion the whole scan is rendered from the pose at
  /// (true time of the first azimuth) + instant_fraction * sweep.
  double instant_fraction = 0.5;
};

struct Prediction {
  double range = 0;     ///< m, reported
  double azimuth = 0;   ///< rad, reported, clockwise, unwrapped like ScanGeometry::azimuth
  double stamp = 0;     ///< s, recorded stamp of the row that sees the target
  double position = 0;  ///< fractional row position in ScanGeometry
  double true_range = 0;
  bool ok = false;
};

/// A small rigid perturbation of the sensor pose (sensor frame), for nuisance Jacobians.
struct PoseDelta {
  double dx = 0, dy = 0, dyaw = 0;
};

Prediction predictTarget(const sim::Target& target, const ScanGeometry& geo,
                         const sim::Trajectory& traj, const sim::PhysicsConfig& physics,
                         const ModelConventions& conv = {}, const PoseDelta& delta = {});

/// The candidate effects of the catalogue that the diagnosis tests.
enum class Effect { MotionDistortion, Doppler, TimestampOffset, AzimuthOffset, RangeOffset };
const std::vector<Effect>& allEffects();
std::string effectName(Effect e);
/// Name of the fitted quantity and its unit ("scale", "" for motion distortion).
std::string effectParameter(Effect e);
std::string effectUnit(Effect e);
/// Physics with the effect's parameter moved by `delta` (motion distortion: switched on when
/// delta != 0; its parameter is the fraction of the full effect, 1 = on).
sim::PhysicsConfig withEffect(const sim::PhysicsConfig& base, Effect e, double delta);
/// Current value of the effect's parameter in a configuration.
double effectValue(const sim::PhysicsConfig& p, Effect e);
/// Finite-difference step used for the regressor.
double effectStep(Effect e);

}  // namespace spinradar::diagnose
