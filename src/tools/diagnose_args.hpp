#pragma once
// `spinradar diagnose`'s options (cmd_diagnose.cpp parses them) and its appearance stage
// (cmd_diagnose_appearance.cpp), private to the CLI.
#include <cstdint>
#include <string>
#include <vector>

#include "spinradar/core/polar_scan.hpp"
#include "spinradar/diagnose/appearance.hpp"
#include "spinradar/sim/physics.hpp"

namespace spinradar::tools {

struct DiagnoseArgs {
  std::string recording, trajectory, world, base, out, map_split = "auto", format = "auto";
  bool timing_only = false;
  double range_resolution = 0;  // 0: sensor.json or the default
  int first_scan = 0, max_scans = -1;
  double alpha = 0.001;
  uint64_t seed = 97;
  bool no_resimulate = false, appearance = false;
  std::string sensor;  // base sensor model of the appearance stage (file or calibrated name)
  int appearance_scans = 4;
  int render_seeds = 1;  // noise seeds of the realism figures before / after (means, ranges)
  int fit_seeds = 1;     // noise seeds of the range-curve fit's objective (mean figures)
  int appearance_iterations = 4;  // Newton steps of the catalogue fit (AppearanceOptions::iterations)
  int curve_iterations = 16, curve_starts = 3;
  std::vector<double> curve_start_offset;  // noise dB, returns dB, log2 density (measurement)
  bool no_holdout = false;
  bool fit_floor = false;
  bool fit_zeros = false;
  bool no_cen2018_fit = false;
  std::string appearance_scene;  // empty: the --sensor file's reference_scene, else city
  std::string gain_chain;  // scene "combined": held gain chain from this sensor (file or name)
  double scene_margin_db = 10.0;
  std::vector<double> scene_margins;  // per band: 2.5-10, 10-25, 25-50, 50 m and on
  int scene_refine = 0;
  bool scene_subbin = false;
  bool scene_clean = false;  // own scene by CLEAN instead of one scatterer per local maximum
  bool fit_spread = false;
  bool fit_far_slope = false;
  std::string hold;  // held parameter group of the appearance fit ("" or "clutter")
  std::string holdout_split = diagnose::kDefaultHoldoutSplit;
  bool split_survey = false;  // only measure the real halves' difference under candidate splits
};

/// The appearance stage (no world or trajectory needed): findings, fitted sensor file, plots
/// into <out>/appearance; with --appearance-split-survey only the real halves' differences.
void runAppearance(const DiagnoseArgs& a, const std::vector<PolarScan>& scans,
                   const sim::PhysicsConfig& physics);

}  // namespace spinradar::tools
