#pragma once
// The glint of the appearance catalogue (physics "glint", m): real returns matched between
// consecutive scans spread more across the beam than the simulator's (matched_spread.hpp); the
// per-scan shift of the scattering centres is fitted so that the re-simulated spread matches.
// Reference: consecutive scans from the middle of a built-in scene's route (moving sensor; the
// appearance stage's "recording" scene stands still), rendered with the sensor model fitted so
// far at a grid of glint values; the recording's pooled tangential spread is interpolated on it.
#include <string>
#include <vector>

#include "spinradar/core/polar_scan.hpp"
#include "spinradar/diagnose/matched_spread.hpp"
#include "spinradar/sim/physics.hpp"
#include "spinradar/sim/sensor_config.hpp"

namespace spinradar::diagnose {

struct GlintOptions {
  std::string scene = "city";  ///< built-in scene of the reference
  int scans = 8;               ///< consecutive reference scans per route segment
  int segments = 3;            ///< route segments (at 1/4, 1/2, 3/4 of the route), averaged
  /// m: scene-to-scene std of the glint-free pooled spread (16 segments of 16 scans of the city
  /// and out_and_back routes: 0.042-0.092, mean 0.065, std 0.013): the reference scene is not the
  /// recording's, so this is added to the recording's standard error.
  double scene_sd = 0.013;
  uint64_t seed = 11;
  std::vector<double> grid = {0.0, 0.05, 0.1, 0.15, 0.2, 0.3, 0.45};  ///< glint values, m
  double z_min = 4.0;          ///< significance needed to name it
  double practical_min = 0.03; ///< m: smaller glint is negligible (under a range bin)
  SpreadOptions spread;
};

struct GlintFit {
  bool measured = false;      ///< the recording has at least one pair of distinct scans
  MatchedSpread real;         ///< the recording's spread
  std::vector<double> grid, ref_spread, ref_se;  ///< reference pooled tangential spread per glint
  MatchedSpread before, after;  ///< reference at the base glint and at the fitted one
  double base = 0, value = 0, stddev = 0, z = 0;
  bool named = false;
  std::string verdict;        ///< "mismatch", "negligible", "not significant", "not identifiable"
};

/// Reference spread: `segments` runs of `scans` consecutive scans of the scene rendered with
/// sensor/physics, averaged (matches-weighted per band; standard error from the segments).
MatchedSpread referenceSpread(const sim::SensorConfig& sensor, const sim::PhysicsConfig& physics,
                              const GlintOptions& opt);

/// Fits the glint of `recording` (consecutive scans) against the model sensor/physics.
GlintFit fitGlint(const std::vector<PolarScan>& recording, const sim::SensorConfig& sensor,
                  const sim::PhysicsConfig& physics, const GlintOptions& opt = {});

/// Markdown table: pooled and per-band spread across / along the beam, recording vs model before
/// and after the fit.
std::string glintTable(const GlintFit& f);

}  // namespace spinradar::diagnose
