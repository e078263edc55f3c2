#pragma once
// Sim-vs-real diagnosis: re-simulate a recording with the base physics, associate returns with
// known correspondences (world targets), locate the residuals, name the omitted effects of the
// catalogue by stepwise grey-box regression, fit them, re-simulate with them on.
// Method: docs/diagnose.md.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "spinradar/core/polar_scan.hpp"
#include "spinradar/diagnose/associate.hpp"
#include "spinradar/diagnose/predict.hpp"
#include "spinradar/diagnose/stats.hpp"
#include "spinradar/diagnose/timing.hpp"
#include "spinradar/sim/physics.hpp"
#include "spinradar/sim/scene.hpp"
#include "spinradar/sim/sensor_config.hpp"

namespace spinradar::diagnose {

constexpr int kNumEffects = 5;  // allEffects()

struct DiagnoseInput {
  std::vector<PolarScan> scans;  ///< the recording, in time order
  sim::World world;
  sim::Trajectory trajectory;
  sim::SensorConfig sensor;
  sim::PhysicsConfig base;       ///< the simulation's physics (default: no effects)
};

struct DiagnoseOptions {
  double alpha = 0.001;           ///< family-wise level over the candidates (Holm)
  double outlier_sigma = 5.0;     ///< residuals beyond this many robust sigmas are dropped
  uint64_t seed = 97;             ///< re-simulation noise seed
  bool resimulate_after = true;   ///< re-render with the fitted effects (before/after)
  /// Treat every target's world position as a nuisance parameter (2 per target). Off for maps
  /// built from the recording too: their dependence on each effect is in the regressors.
  bool target_nuisance = false;
  /// Timing stage (timing.hpp): stamp analysis first (bursty stamps are replaced by the fitted
  /// uniform firing times before the catalogue stage), rotation jitter from the residuals after.
  bool timing = true;
  TimingOptions timing_options;
  ModelConventions conventions;
  ViewOptions views;
  PeakOptions peaks;
};

/// One associated target in one scan.
struct Observation {
  int scan = 0, target = 0;
  double range = 0, azimuth = 0;  ///< base prediction (m, rad clockwise)
  double tau = 0;                 ///< s since the scan's first row
  double stamp = 0;               ///< s, recorded
  double vx = 0, vy = 0, yaw_rate = 0, yaw = 0;  ///< sensor motion at the observation
  double real_r = 0, real_az = 0; ///< measured in the recording (m, rad)
  double e_r = 0, e_az = 0;       ///< real minus re-simulated (m, rad)
  std::array<double, kNumEffects> dr{}, daz{};  ///< d(range, azimuth)/d(parameter)
  std::array<double, 3> nr{}, naz{};            ///< d(range, azimuth)/d(sensor dx, dy, dyaw)
  std::array<double, 2> tr{}, taz{};            ///< d(range, azimuth)/d(target x, y)
  double fit_r = 0, fit_az = 0;   ///< residual after the fitted linear model
  bool inlier = true;
  double radialVelocity() const;  ///< sensor velocity along the ray (m/s)
};

struct EffectResult {
  Effect effect;
  std::string name, parameter, unit;
  double value = 0, stddev = 0;   ///< fitted parameter (base + change) and its 1-sigma
  double change = 0;              ///< fitted minus base
  double significance = 0;        ///< |z| of the change in the joint fit
  double lr = 0, lm = 0, p = 1, delta_bic = 0, holm_threshold = 0;
  double absorbed = 0;            ///< by nuisance + effects selected before it
  double absorbed_by_alignment = 0;  ///< by a per-scan rigid alignment (scan matching)
  double vif = 1;                 ///< in the joint fit
  std::vector<std::string> confounded_with;
  double residual_rms_before = 0, residual_rms_after = 0;  ///< position (m), re-simulated
  double range_rms_before = 0, range_rms_after = 0;        ///< m
  double azimuth_rms_before = 0, azimuth_rms_after = 0;    ///< rad
};

/// Step-1 test of every candidate against the base model (for the table of all effects).
struct CandidateRow {
  Effect effect;
  double estimate = 0, stddev = 0, z = 0, lr = 0, lm = 0, p = 1, delta_bic = 0;
  double absorbed = 0, absorbed_by_alignment = 0, vif = 1;
};

struct LocateRow {
  std::string by, label;
  int n = 0;
  double mean_r = 0, rms_r = 0;   ///< m
  double mean_t = 0, rms_t = 0;   ///< tangential m (range * azimuth residual)
  double z = 0;                   ///< largest |mean| / standard error of the two
};

struct ResidualStats {
  int n = 0;
  double position_rms = 0, range_rms = 0, azimuth_rms = 0, time_rms = 0;
};

struct DiagnoseReport {
  bool mismatch_found = false;
  std::vector<EffectResult> effects;     ///< most significant first
  std::vector<CandidateRow> candidates;  ///< every tested effect at step 1
  std::vector<std::string> notes;        ///< confounding, identifiability, warnings
  std::vector<LocateRow> locate;
  std::vector<std::string> effect_names_tested;
  ResidualStats before, after;           ///< re-simulated with base / with all fitted effects
  std::vector<ResidualStats> after_step; ///< after each effect added (re-simulated)
  sim::PhysicsConfig base, fitted;
  std::vector<Observation> obs;
  std::vector<std::vector<double>> after_e_r, after_e_az;  ///< per step, per observation
  Eigen::MatrixXd candidate_corr;        ///< correlation of orthogonalised candidates
  int scans = 0, targets_used = 0, outliers = 0;
  double sigma_r = 0, sigma_az = 0;      ///< robust noise of one residual
  double runtime_s = 0;
  std::string scene_model = "world file";  ///< or how the map was built from the recording
  TimingReport timing;                   ///< stamps, rotation jitter, timing model to use
  nlohmann::json toJson() const;
  std::string summaryMarkdown() const;
};

DiagnoseReport diagnose(const DiagnoseInput& in, const DiagnoseOptions& opt = {});

/// Without a world file (in.world ignored): builds the static scene from part of the recording
/// (`split`: "auto", "early-late", "late-early", "out-back"; see scene_map.hpp) and diagnoses the rest.
DiagnoseReport diagnoseWithoutWorld(const DiagnoseInput& in, const DiagnoseOptions& opt = {},
                                    const std::string& split = "early-late");

/// The whole diagnosis of a recording: timing stage on every scan (bursty stamps corrected),
/// then diagnose() (`with_world`) or diagnoseWithoutWorld(split), then rotation jitter from the
/// residuals and the timing advice. diagnose() with opt.timing does the same with a world.
DiagnoseReport diagnoseRecording(const DiagnoseInput& in, const DiagnoseOptions& opt,
                                 bool with_world, const std::string& split = "early-late");

/// Writes report.json, summary.md, summary.txt and PNG plots into out_dir (created).
void writeReport(const DiagnoseReport& report, const std::string& out_dir);

/// report.json and summary.md of the timing stage alone (no world/trajectory diagnosis), with
/// the reason the catalogue stage did not run.
void writeTimingReport(const TimingReport& timing, const std::string& out_dir,
                       const std::string& why_no_catalogue);

/// Residual figures grouped by scan, azimuth sector, range band, speed, turning and heading.
std::vector<LocateRow> locateResiduals(const std::vector<Observation>& obs, bool use_fit);

}  // namespace spinradar::diagnose
