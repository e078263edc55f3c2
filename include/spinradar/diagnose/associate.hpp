#pragma once
// Known-correspondence association: every isolated static point target of the world is
// predicted into each scan (base physics); its peak is measured in the recorded scan and in
// the re-simulated scan inside the same gate, giving range / azimuth / time residuals.
#include <optional>
#include <vector>

#include "spinradar/core/polar_scan.hpp"
#include "spinradar/diagnose/predict.hpp"
#include "spinradar/sim/scene.hpp"

namespace spinradar::diagnose {

struct Peak {
  double range = 0;    ///< m (sub-bin, parabolic)
  double azimuth = 0;  ///< rad (sub-row, parabolic over the beam), unwrapped like the geometry
  double power = 0;    ///< counts at the peak
  double contrast = 0; ///< peak minus median of the gate
};

struct Gate {
  double range = 1.0;    ///< m, half width
  double azimuth = 0.05; ///< rad, half width
};

struct PeakOptions {
  double min_contrast = 12.0;  ///< counts above the gate median
};

/// Strongest return inside the gate around (range, azimuth); nullopt when none stands out,
/// when it sits on the gate's edge, or the gate leaves the scan.
std::optional<Peak> measurePeak(const PolarScan& scan, const ScanGeometry& geo, double range,
                                double azimuth, const Gate& gate, const PeakOptions& opt = {});

/// A target's prediction in one scan, kept when the target is isolated (no other target or
/// wall within the gate), static, inside the range limits and away from the scan seam.
struct TargetView {
  int scan = 0;
  int target = 0;
  Prediction pred;  ///< under the base physics
  Gate gate;
};

struct ViewOptions {
  double min_range = 4.0;       ///< m
  double max_range_margin = 2;  ///< m below the last bin
  double gate_range_min = 0.8;  ///< m
  double gate_azimuth_min = 0.045;  ///< rad (~2.6 deg)
  double dominance_db = 8.0;    ///< other returns in the gate must be this much weaker (RCS)
};

/// Views of all usable targets in one scan; gates widen with speed and yaw rate so that the
/// largest catalogue effects still fall inside.
std::vector<TargetView> targetViews(int scan_index, const PolarScan& scan,
                                    const ScanGeometry& geo, const sim::World& world,
                                    const sim::Trajectory& traj,
                                    const sim::PhysicsConfig& base,
                                    const ModelConventions& conv, const ViewOptions& opt = {});

}  // namespace spinradar::diagnose
