#pragma once
// The appearance stage of the diagnosis: how returns LOOK (levels, widths, texture), not where
// they are. Works on real scans alone (no world file, no trajectory): the same figures are
// measured on the recording and on a re-simulation of a reference scene with the base sensor
// model; their differences are located (range band, intensity level, azimuth, neighbourhood of
// strong returns), named from a catalogue of sensor physics, and fitted by indirect inference
// (figure Jacobian from re-simulations with each parameter nudged). Method: docs/diagnose.md.
#include <array>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "spinradar/core/polar_scan.hpp"
#include "spinradar/diagnose/appearance_split.hpp"
#include "spinradar/sim/physics.hpp"
#include "spinradar/sim/realism.hpp"
#include "spinradar/sim/realism_seeds.hpp"
#include "spinradar/sim/scene.hpp"
#include "spinradar/sim/sensor_config.hpp"

namespace spinradar::diagnose {

constexpr int kBands = 4;  ///< sim::kBandEdges: 2.5-10, 10-25, 25-50, 50-100 m

/// Appearance figures of a set of scans; each is the mean over scans, `*_se` its standard error
/// from the scan-to-scan scatter.
struct AppearanceFigures {
  int scans = 0;
  std::array<double, kBands> floor{}, floor_se{};    ///< mean of the lower half of counts
  std::array<double, kBands> mean{}, mean_se{};      ///< mean count
  std::array<double, kBands> bright{}, bright_se{};  ///< mean of the top 1 % of counts
  std::array<double, kBands> cfar{}, cfar_se{};      ///< log10(1 + plain CA-CFAR cells/scan)
  double beam_rows = 0, beam_rows_se = 0;  ///< azimuth equivalent width of isolated peaks, rows
  double psf_bins = 0, psf_bins_se = 0;    ///< range equivalent width of isolated peaks, bins
  int peaks = 0;                           ///< isolated peaks measured (all scans)
  double az_sidelobe_db = 0;   ///< mean level 3-6 rows off strong peaks, dB below the peak
  double rng_sidelobe_db = 0;  ///< mean level 10-20 bins off strong peaks, dB below the peak
  double near_excess = 0;      ///< mean count below 2 m minus the 2.5-10 m floor (leakage)
  double near_excess_se = 0;   ///< its standard error from the scan quarters
  double top_count = 0;        ///< largest count present
  double pileup = 0;           ///< cells at top_count / mean cells at the 3 values below it
  double behind = 0, behind_se = 0;  ///< share of bright cells >= 2 m behind the first strong hit
  double row_sd = 0;           ///< std of the per-row floor (noise texture across azimuths), counts
  int distinct_low_codes = 0;  ///< distinct values among counts 1..30 (log quantisation: ~10)
  /// Per replicate (scan quarter, in scan order): floor[4], mean[4], bright[4], cfar[4], beam,
  /// range width (NaN where a quarter has too few isolated peaks). Recordings of the same route
  /// are compared replicate by replicate (paired), which removes the scene's own variation.
  std::vector<std::vector<double>> replicates;
};

AppearanceFigures measureAppearance(const std::vector<PolarScan>& scans);

/// One parameter of the appearance catalogue.
struct AppearanceFinding {
  std::string effect;     ///< catalogue name ("beam width", "noise floor", ...)
  std::string parameter;  ///< sensor/physics key it sets
  std::string unit;
  double base = 0, value = 0, stddev = 0;  ///< base model, fitted, 1-sigma of the fit
  double z = 0;                            ///< |value - base| / stddev
  double size = 0;             ///< practical size of the change in `size_unit`
  std::string size_unit;       ///< "dB", "bins", "rows", "x"
  double gap_before = 0, gap_after = 0;  ///< its figure's gap (real - sim) before/after, in units
  bool named = false;          ///< significant AND practically large
  std::string verdict;         ///< "mismatch", "negligible", "not significant", "not identifiable"
};

/// A located appearance difference: one figure in one place, real vs re-simulated.
struct AppearanceLocate {
  std::string by, where;
  double real = 0, sim = 0;  ///< in `unit`
  std::string unit;
  std::string note;
};

struct AppearanceOptions {
  /// Reference scene of the re-simulation: a built-in scene name, or "recording": the
  /// recording's own fit-part scans as scatterers (withReferenceScene, appearance_scene.cpp), or
  /// "combined": the gain chain and beam from the city scene's fit, the rest with the recording's
  /// own scene (combinedAppearance, appearance_combined.cpp).
  std::string scene = "city";
  /// "recording" scene: a return is a local maximum this far above its range bin's upper quartile
  /// (over the upper quartile; exponential speckle exceeds that in 1e-6 of the cells).
  double scene_margin_db = 10.0;
  /// "recording" scene: a margin per range band (dB; 2.5-10, 10-25, 25-50, 50 m and on), in place
  /// of scene_margin_db where given (empty: scene_margin_db everywhere). Weak returns at far
  /// range lie under a 10 dB margin (MulRan 50-100 m: the re-simulation misses 85 % of the
  /// recording's CA-CFAR runs peaking under 20 counts; docs/diagnose_scene.md, tenth round).
  std::vector<double> scene_margin_bands_db;
  /// "recording" scene (one scatterer per local maximum): passes of a joint refinement of the
  /// scatterers' strengths along azimuth, positions held (multiplicative non-negative least
  /// squares of the model's rendered blur against the recording's power over the floor, rows
  /// +-the beam's span of each scatterer's bin). 0: each row rebuilt on the blur of the ones
  /// taken before it only, so the later, weaker rows' blur came on top of the strong rows and
  /// the strong returns rendered wider than recorded (MulRan -27 dB at +-2 rows against -33).
  int scene_refine_passes = 0;
  /// "recording" scene (one scatterer per local maximum): place each return between range bins
  /// (the vertex of a parabola through the log powers of its bin and the two neighbours, exact
  /// for the model's Gaussian range spread) instead of at its bin's centre. Off: every return
  /// re-rendered centred on a bin, so its rendered shape is not the recorded one.
  bool scene_range_subbin = false;
  /// "recording" scene built by deconvolution (CLEAN, appearance_scene_clean.cpp): the strongest
  /// remaining return becomes a scatterer and the model's point response (range spread x beam)
  /// is taken off, until the residual is under the margin, so an extended return (a wall, a
  /// bush) becomes several scatterers and keeps its width. Off (default): one scatterer per local
  /// maximum along each row. Off by default: it reproduces the returns' widths (Boreas-RT 8 bins
  /// at 25-100 m, the one-point scene 7) but the fits came out worse on Oxford, Boreas-RT and
  /// RADIATE's fit part (docs/diagnose_scene.md, "CLEAN").
  bool scene_clean = false;
  /// "recording" scene: the scans it is taken from (set by withReferenceScene).
  std::shared_ptr<const std::vector<PolarScan>> scene_scans;
  /// Hold the returns' gain chain and the beam (notIdentifiableWithOwnScene, and the return
  /// level per range node of the range curves) at the start sensor's values: the second stage of
  /// scene "combined" (appearance_combined.cpp), which sets it.
  bool hold_gain_chain = false;
  /// Scene "combined": the sensor whose gain chain and beam are held. Null: from a fit with the
  /// city scene run first (the calibrated files in config/sensors are such fits).
  std::shared_ptr<const sim::SensorConfig> gain_chain;
  int scans = 4;               ///< re-simulated scans per evaluation
  uint64_t seed = 11;
  /// Noise seeds of the realism figures before / after (and the held-out part's): seed + 1 and
  /// the next render_seeds - 1 (sim::renderSeeds); each figure is the mean over them and the
  /// worst gaps are the mean of each seed's worst gap, with their range (CLI --render-seeds).
  int render_seeds = 1;
  /// Noise seeds the range-curve fit's objective is evaluated on: seed, seed + kFitSeedStride,
  /// ...; its figures are the mean over them, so the fit cannot fit one render's noise (CLI
  /// --appearance-fit-seeds; docs/diagnose_render_seeds.md). 1 = the single render of `seed`.
  int fit_seeds = 1;
  int iterations = 4;          ///< Newton steps of the indirect-inference fit
  double z_min = 4.0;          ///< significance needed to name an effect
  /// Practical thresholds: a change smaller than these is negligible (1 dB for levels, 10 %
  /// for widths, 2 dB/decade for slopes).
  double level_db_min = 1.0, width_rel_min = 0.10, slope_min = 2.0;
  double ghost_ratio_min = 1.2;  ///< behind-hit bright share real / sim to name ghosts
  bool fit_clutter = true;     ///< include the textured clutter in the fit
  /// Hold the textured clutter field (clutterFieldKeys: clutter_density, its range multipliers
  /// clutter_density_x_*, clutter_rcs_db, clutter_rcs_sd_db) at the start sensor's values and fit
  /// the sensor terms only: noise and receiver gain curves, return gain curve, noise texture,
  /// beam, range spread, leakage, glint (CLI --appearance-hold clutter). With the city scenes the
  /// full fit fills the far bands with a clutter carpet (Oxford: x20 at 35 and 71 m, the bound)
  /// that hides far matches; held, the clutter stays what the start file (or the default, off)
  /// says (docs/diagnose_hold_clutter.md).
  bool hold_clutter = false;
  bool fit_near_stc = true;    ///< include the near-range STC ramp in the fit
  bool relinearise = true;     ///< recompute the figure Jacobian at every Newton step
  bool realism = true;         ///< realism tables before/after (with detectors)
  /// Per-band calibration after the global fit: range curves fitted on the per-band realism
  /// figures (fitRangeCurves); 0 iterations = off.
  int curve_iterations = 24;
  /// Starts of the range-curve fit (1-6): the given start, flat curves, flat curves with fixed
  /// offsets of the noise level, the returns' level and the clutter density; a full run from
  /// each, the lowest misfit on the fit part wins (fitRangeCurves). 1 = the single
  /// Levenberg-Marquardt run.
  int curve_starts = 1;
  /// Move the range-curve fit's start before it runs (perturbCurveStart: noise dB, returns dB,
  /// log2 clutter density): to measure how the fit depends on where it starts.
  std::array<double, 3> curve_start_offset{};
  /// Add each band's floor (mean of the lower half of the counts) to the range-curve fit's
  /// figures, so that receiver noise and dense weak clutter are told apart. Off by default: on
  /// the Oxford sample it gives the recording's noise floor back (50-100 m: 2.1 counts, the
  /// default fit 0.0) but the reference city scene then cannot give Oxford's Cen2018 counts
  /// (docs/diagnose.md, "Oxford's Cen2018 counts").
  bool fit_band_floor = false;
  /// Also fit each band's share of zero counts (sim::RealismStats::band_zero): pins the noise
  /// level against the quantiser's first step, also where more than half the counts are zero
  /// (there the floor figure is 0 whatever the noise). Not a realism gap figure.
  bool fit_band_zeros = false;
  /// Let the Cen2018 keypoints per band drive the range-curve fit (they are still measured and
  /// in every gap figure either way). Off = they weigh nothing: with the floors fitted, the
  /// reference city scene cannot give Oxford's counts (a third at 10-25 m; scene content,
  /// docs/diagnose_cen2018.md) and they would pull every other figure off.
  bool fit_cen2018 = true;
  /// Let the per-band figures move the range spread too (a global of the range-curve fit).
  /// Off by default: on Boreas-RT's own scene it takes the fit part from 66 % to 9 % (the
  /// CA-CFAR cells follow the returns' width; held out 62 -> 77 %, the quarters' own scatter) and
  /// RADIATE's held out 23 -> 20 %, but Oxford's combined 14 -> 20 % and MulRan's 20 -> 25 %
  /// (docs/diagnose_scene.md).
  bool fit_spread_bands = false;
  /// Let the per-band figures move the returns' far slope (sensor return_far_slope_db_per_decade,
  /// a global of the range-curve fit): beyond the last curve node (71 m) the curves are flat, so
  /// without it the 71 m node sets 50-100 m and everything beyond alike (Oxford: the far band's
  /// mean and its q90 then only rise together; docs/diagnose_far_band.md). Off by default.
  bool fit_far_slope = false;
  /// Fit the glint terms (per-scan shift of the scattering centres across and along the beam,
  /// per-row azimuth jitter: physics glint_across, glint_along, azimuth_jitter, carried by the
  /// fitted sensor) to the spread of returns matched between consecutive scans
  /// (glint_terms.hpp); needs two distinct scans.
  bool fit_glint = true;
  /// Fit on part of the recording and check on the rest (splitHoldout).
  bool holdout = true;
  /// How: "contiguous", "scans" or "blocks:N" (parseHoldoutSplit, appearance_split.hpp).
  std::string holdout_split = kDefaultHoldoutSplit;
  /// Also render the fitted sensor with each part's own scene, to tell a held-out gap of the
  /// scene from one of the sensor (detail::holdoutSceneCheck; needs realism and holdout).
  bool holdout_scene_check = true;
};

/// Spacing of the fit's noise seeds (AppearanceOptions::fit_seeds): the realism figures are
/// rendered with seed + 1 ... seed + render_seeds, so fit seeds this far apart never meet them
/// (render_seeds is at most 999) and the evaluation stays on noise the fit has not seen.
constexpr uint64_t kFitSeedStride = 1000;

/// The sensor keys of the textured clutter field, the one definition of what
/// AppearanceOptions::hold_clutter holds.
const std::vector<std::string>& clutterFieldKeys();
/// Whether the fit keeps sensor key `key` at the start sensor's value under `opt`.
bool isHeldParameter(const AppearanceOptions& opt, const std::string& key);
/// `s` with every parameter `opt` holds set back to `start`'s value.
sim::SensorConfig withHeldParameters(const sim::SensorConfig& s, const sim::SensorConfig& start,
                                     const AppearanceOptions& opt);

/// A per-band realism figure that measures the reference scene's geometry rather than the
/// sensor: left out of the per-band fit (fitRangeCurves) and of the worst-gap figures, and
/// reported separately as "scene-dependent, not fitted" with its reason.
struct SceneDependentFigure {
  int band;            ///< 0..3 (sim::kBandEdges)
  std::string figure;  ///< "mean", "q90", "cacfar" or "cen2018"
  std::string reason;
};
const std::vector<SceneDependentFigure>& sceneDependentFigures();
bool isSceneDependent(int band, const std::string& figure);

/// Relative per-band gaps |sim - real| / real of the figures the fit uses (sim::bandGaps without
/// the scene-dependent ones), with their names ("25-50 m q90").
std::vector<std::pair<std::string, double>> fittedBandGaps(const sim::RealismStats& sim,
                                                           const sim::RealismStats& real);

/// How the background (mean of the lower half of the counts) of one range band moved from the
/// fit part to the held-out part, per azimuth sector: the median shift over the sectors
/// (common: a receiver change moves every sector alike) and the lowest and highest (diffuse scene
/// content moves them apart). Counts; NaN when the parts share no sector (one scan split by
/// quarters).
struct SectorShift {
  double common = NAN, lo = NAN, hi = NAN;
};
SectorShift sectorFloorShift(const std::vector<PolarScan>& fit,
                             const std::vector<PolarScan>& holdout, int band, int sectors = 8);

/// One fitted figure on the held-out part, and why it is off (classifyHeldOutFigure): the
/// fitted sensor against the held-out part with the fit's reference scene, with the fit part's
/// and the held-out part's own scenes (detail::holdoutSceneCheck), and the real halves' own
/// difference |held out - fit part| / fit part.
struct HeldOutFigure {
  std::string name;  ///< "50-100 m cen2018"
  double real_fit = NAN, real_holdout = NAN, sim = NAN, sim_fit_scene = NAN, sim_holdout_scene = NAN;
  double gap_fit = NAN, gap_holdout = NAN, halves = NAN, gap_fit_scene = NAN, gap_holdout_scene = NAN;
  /// Carry-over: (sim_holdout_scene / real_holdout) / (sim_fit_scene / real_fit) - 1, how much
  /// worse (or better) the fitted sensor does on the held-out part than on the fit part when
  /// each is rendered from its own scene (what the own scene itself misses cancels out).
  double carry = NAN;
  /// The held-out gap net of the parts' different content: |sim / real_fit x (1 + carry) - 1|.
  double gap_net = NAN;
  SectorShift floor_shift;        ///< of the figure's band
  bool background_moves = false;  ///< sectors apart by 2 dB or more, common shift under 1 dB
  std::string verdict;
};
/// "model" when the fit part is off by over 15 % too, or the fitted sensor does over 10 % worse
/// on the held-out part's own scene than on the fit part's (carry) while the band's background
/// shifts alike in every sector; "scene below the own scene's margin" when the carry-over is
/// over 10 % but the background moves sector by sector (diffuse content the own scene, made of
/// returns 10 dB over the floor, does not hold); "scene" otherwise (the parts show different
/// content); without the own-scene renders, "the real halves' own difference" when the halves
/// differ about as much as the held-out gap.
std::string classifyHeldOutFigure(const HeldOutFigure& f);

struct AppearanceReport {
  std::vector<AppearanceFinding> findings;  ///< named first (largest z), then the rest
  std::vector<AppearanceLocate> locate;
  std::vector<std::string> notes;
  sim::SensorConfig base, fitted;
  sim::PhysicsConfig base_physics, fitted_physics;
  AppearanceFigures real, before, after;
  /// Realism figures of the recording's fit part (realism_real) and held-out part, and of the
  /// reference scene re-simulated with the base and the fitted model (another noise seed).
  sim::RealismStats realism_real, realism_holdout, realism_before, realism_after;
  /// The simulated realism figures per noise seed (opt.render_seeds of them; realism_before /
  /// realism_after are their means) and the worst gaps as spreads over the seeds (worst_gap_*
  /// and worst_holdout_* below are these spreads' means).
  sim::RealismOverSeeds seeds_before, seeds_after;
  sim::SeedSpread worst_before_seeds, worst_after_seeds, worst_holdout_before_seeds,
      worst_holdout_after_seeds;
  /// Worst per-band realism gap (relative) over the fitted figures (scene-dependent ones left
  /// out), fit part and held-out part.
  double worst_gap_before = 0, worst_gap_after = 0;
  double worst_holdout_before = 0, worst_holdout_after = 0;
  int fit_scans = 0, holdout_scans = 0;  ///< scans (or masked half scans) in each part
  /// The split used (appearance_split.hpp; "auto" resolved), set by writeAppearanceReport.
  std::string holdout_split;
  /// The real halves' own difference: largest over the fitted figures of |held out - fit| / fit.
  double realHalvesDifference(std::string* figure = nullptr) const;
  /// The fitted sensor rendered with the fit part's and the held-out part's own scenes, their
  /// worst gaps against those parts, and every fitted figure of the held-out part with its verdict.
  sim::RealismStats realism_fit_scene, realism_holdout_scene;
  double worst_fit_scene = 0, worst_holdout_scene = 0, worst_net = 0;
  std::array<SectorShift, kBands> floor_shifts;  ///< per band
  std::vector<HeldOutFigure> held_out_figures;
  double runtime_s = 0;
  nlohmann::json toJson() const;
  std::string summaryMarkdown() const;
};

/// Scans of the reference scene rendered with `sensor` and `physics` (evenly over the route).
std::vector<PolarScan> renderReference(const sim::SensorConfig& sensor,
                                       const sim::PhysicsConfig& physics,
                                       const AppearanceOptions& opt, uint64_t seed);

/// Scatterers of one recorded scan in the sensor frame, strengths for `sensor`'s gain chain
/// (the "recording" reference scene; rows masked out of `scan` are never read).
sim::World recordingWorld(const PolarScan& scan, const sim::SensorConfig& sensor,
                          const AppearanceOptions& opt);
/// Catalogue parameters the recording's own scene takes up: fitted, never named with it.
bool notIdentifiableWithOwnScene(const std::string& key);
/// `opt` with scene_scans set to the fit part of `recording` when opt.scene is "recording".
AppearanceOptions withReferenceScene(const AppearanceOptions& opt,
                                     const std::vector<PolarScan>& recording);
/// Scans of the recorded scenes (opt.scans, cycled, and every scene at least once) from a
/// standing sensor.
std::vector<PolarScan> renderRecordingScene(const sim::SensorConfig& sensor,
                                            const sim::PhysicsConfig& physics,
                                            const AppearanceOptions& opt, uint64_t seed);

/// Scene "combined" (dispatched to by diagnoseAppearance): the returns' gain chain and the beam
/// (what the recording's own scene absorbs) from the city scene's fit or opt.gain_chain, then
/// everything else fitted against the recording's own scene with them held. Findings of the
/// held parameters are the city fit's (or "held" when given).
AppearanceReport combinedAppearance(const std::vector<PolarScan>& real,
                                    const sim::SensorConfig& sensor,
                                    const sim::PhysicsConfig& physics,
                                    const AppearanceOptions& opt);

/// The appearance stage on `real` against the base model `sensor` / `physics` (the geometry
/// fields of `sensor`, bins, resolution, azimuths, must be the recording's).
AppearanceReport diagnoseAppearance(const std::vector<PolarScan>& real,
                                    const sim::SensorConfig& sensor,
                                    const sim::PhysicsConfig& physics,
                                    const AppearanceOptions& opt = {});

/// The ninth round's split ("contiguous", appearance_split.hpp): several scans: the first half
/// (rounded up) to fit, the rest held out; one scan: its quarters 0 and 2 to fit, 1 and 3 held
/// out (rows masked through PolarScan::valid and zeroed; realism counts stay per full rotation).
void splitHoldout(const std::vector<PolarScan>& scans, std::vector<PolarScan>& fit,
                  std::vector<PolarScan>& holdout);

/// Realism figures of the reference scene rendered with `sensor` / `physics` for each of `seeds`.
sim::RealismOverSeeds realismOverSeedsOf(const sim::SensorConfig& sensor,
                                         const sim::PhysicsConfig& physics,
                                         const AppearanceOptions& opt,
                                         const std::vector<uint64_t>& seeds,
                                         const std::string& name);
/// The seeds the range-curve fit evaluates its objective on (AppearanceOptions::fit_seeds).
std::vector<uint64_t> fitSeeds(const AppearanceOptions& opt);
/// The seeds of the realism figures before / after (AppearanceOptions::render_seeds).
std::vector<uint64_t> reportSeeds(const AppearanceOptions& opt);

/// Realism figures of the reference scene rendered with `sensor` / `physics`.
sim::RealismStats realismOf(const sim::SensorConfig& sensor, const sim::PhysicsConfig& physics,
                            const AppearanceOptions& opt, uint64_t seed, const std::string& name);

/// Fits the range curves (stc_curve_db_*, return_gain_db_*, clutter_density_x_*) from `start`
/// so that the per-band realism figures (mean, q90, plain CA-CFAR cells, Cen2018 keypoints) of
/// the reference scene re-simulated match `real` (Levenberg-Marquardt on log figures). Steps
/// taken go to `log`.
sim::SensorConfig fitRangeCurves(const sim::RealismStats& real, const sim::SensorConfig& start,
                                 const sim::PhysicsConfig& physics, const AppearanceOptions& opt,
                                 std::vector<std::string>* log = nullptr);

/// `start` with every range node moved: noise level (receiver gain curve) by `noise_db`, the
/// returns' level by `returns_db` (dB), the clutter density by 2^`log2_density`, within the
/// nodes' bounds. The starts of the multi-start fit, and the perturbed starts of its tests.
sim::SensorConfig perturbCurveStart(const sim::SensorConfig& start, double noise_db,
                                    double returns_db, double log2_density);

/// Writes appearance.json, appearance.md, sensor_fitted.json, physics_fitted.json and PNG
/// plots (band profiles before/after, intensity histograms) into out_dir.
void writeAppearanceReport(const AppearanceReport& rep, const std::vector<PolarScan>& real,
                           const AppearanceOptions& opt, const std::string& out_dir);

}  // namespace spinradar::diagnose
