// `spinradar diagnose`: sim-vs-real diagnosis of a recording (docs/diagnose.md).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include "cli_checks.hpp"
#include "diagnose_args.hpp"
#include "render_seeds_option.hpp"
#include "command.hpp"
#include "spinradar/core/safe_output.hpp"
#include "spinradar/io/scan_folder.hpp"
#include "spinradar/diagnose/appearance.hpp"
#include "spinradar/diagnose/chirp_doppler.hpp"
#include "spinradar/diagnose/diagnose.hpp"
#ifdef SPINRADAR_HAVE_BAG
#include "scan_bag.hpp"
#endif

namespace {

namespace fs = std::filesystem;
using namespace spinradar;
using spinradar::tools::DiagnoseArgs;
using spinradar::tools::runAppearance;

/// The recording as a scan folder: a rosbag of RadarScan messages is first unpacked into
/// <out>/recording_from_bag (Oxford layout).
std::string recordingFolder(const DiagnoseArgs& a, const std::string& out) {
  if (!(fs::is_regular_file(a.recording) && fs::path(a.recording).extension() == ".bag"))
    return a.recording;
#ifdef SPINRADAR_HAVE_BAG
  const std::string dir = (fs::path(out) / "recording_from_bag").string();
  fs::remove_all(dir);
  const size_t n = bag::bagToFolder(a.recording, dir);
  std::cout << "read " << n << " scans from " << a.recording << "\n";
  return dir;
#else
  throw std::runtime_error(a.recording + ": reading a rosbag needs spinradar built with ROS "
                           "(catkin); or unpack it elsewhere with `spinradar bag`");
#endif
}

sim::SensorConfig sensorFor(const DiagnoseArgs& a, const std::string& dir,
                            const std::vector<PolarScan>& scans) {
  sim::SensorConfig s;
  const fs::path sj = fs::path(dir) / "sensor.json";
  if (fs::exists(sj)) {
    s = sim::SensorConfig::load(sj.string());
  } else {
    // No sensor description: take the geometry from the scans, the rest from the defaults.
    const PolarScan& p = scans.front();
    s.azimuths = p.azimuths;
    s.bins = p.bins;
    s.encoder_size = p.encoder_size;
    const double span = static_cast<double>(p.lastStamp() - p.firstStamp()) * 1e-9;
    if (span > 0) s.rotation_hz = (p.azimuths - 1) / (span * p.azimuths);
  }
  if (a.range_resolution > 0) s.range_resolution = a.range_resolution;
  s.validate();
  return s;
}

void printTiming(const diagnose::TimingReport& t) {
  std::cout << "timing: stamps " << t.stamp_model << " (" << t.scans << " scans)";
  for (const auto& f : t.findings)
    std::cout << "; " << f.name << " = " << f.value << " +- " << f.stddev << " " << f.unit
              << " (z " << f.significance << ", " << f.scans << " scans)";
  std::cout << "\n";
  for (const auto& s : t.advice) std::cout << "  timing model: " << s << "\n";
  if (!t.chirp_doppler.is_null())
    for (const auto& r : t.chirp_doppler["per_scan"])
      std::cout << "  in-scan Doppler (alternating chirps), scan " << r["scan"].get<int>() << ": "
                << r["verdict"].get<std::string>() << "\n";
}

/// Stamps the timing and catalogue stages can use: not all equal (all-zero stamps would read as
/// "uniform, interval 0").
void checkStamps(const std::vector<PolarScan>& scans, const std::string& name) {
  size_t flat = 0;
  for (const auto& s : scans) flat += s.firstStamp() == s.lastStamp();
  const bool same_scan_times =
      scans.size() > 1 && std::all_of(scans.begin(), scans.end(), [&](const PolarScan& s) {
        return s.firstStamp() == scans.front().firstStamp();
      });
  if (flat == scans.size() || same_scan_times)
    throw std::runtime_error(name + ": the azimuth stamps carry no time (" +
                             std::to_string(flat) + " of " + std::to_string(scans.size()) +
                             " scans have one stamp for every azimuth" +
                             (same_scan_times ? ", every scan starts at the same time" : "") +
                             "); the diagnosis needs the recorded stamps");
}

/// The trajectory must cover the recording (same clock); a trajectory of another drive would
/// otherwise read as "no significant mismatch".
void checkOverlap(const std::vector<PolarScan>& scans, const sim::Trajectory& traj,
                  const std::string& traj_path, const std::string& rec) {
  const double r0 = scans.front().firstStamp() * 1e-9, r1 = scans.back().lastStamp() * 1e-9;
  const double t0 = traj.startTime(), t1 = traj.endTime();
  const double overlap = std::min(r1, t1) - std::max(r0, t0);
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "%s covers %.3f .. %.3f s but the scans of %s span %.3f .. %.3f s", traj_path.c_str(),
                t0, t1, rec.c_str(), r0, r1);
  if (!(overlap > 0))
    throw std::runtime_error(std::string(buf) + ": they do not overlap (another drive, or "
                                                "another clock?)");
  if (overlap < 0.9 * (r1 - r0))
    std::cerr << "warning: " << buf << ": only " << int(100.0 * overlap / (r1 - r0))
              << " % of the recording has a trajectory\n";
}

void run(const DiagnoseArgs& a) {
  ScanFolderOptions fo;
  if (a.range_resolution > 0) fo.range_resolution = a.range_resolution;
  refuseOutputOverInput({a.out, "--out"}, {{a.recording, "--recording"}, {a.trajectory, "--trajectory"},
                                           {a.world, "--world"}, {a.base, "--base"}}, true);
  // The report is written aside and moved into the --out folder when complete (files of an
  // older report there are replaced, others kept).
  AtomicOutputFolder out_dir(a.out, true, "--out", false);
  const std::string out = out_dir.tempPath();
  const std::string dir = recordingFolder(a, out);
  ScanFolder folder(dir, parseScanFormat(a.format), fo);
  if (folder.empty()) throw std::runtime_error(a.recording + ": no radar scans found");
  diagnose::DiagnoseInput in;
  const size_t end = a.max_scans < 0 ? folder.size()
                                     : std::min(folder.size(), size_t(a.first_scan + a.max_scans));
  for (size_t i = a.first_scan; i < end; ++i) in.scans.push_back(folder.load(i));
  if (in.scans.empty())
    throw std::runtime_error(a.recording + ": no scans in the chosen range (--first-scan " +
                             std::to_string(a.first_scan) + " of " + std::to_string(folder.size()) +
                             " scans)");
  checkStamps(in.scans, a.recording);
  in.sensor = sensorFor(a, dir, in.scans);
  // The timing stage needs only the stamps: run it alone when asked, or when no trajectory is
  // given, or when the catalogue stage cannot run on this recording (report why).
  auto timingOnly = [&](const std::string& why) {
    diagnose::TimingReport t =
        diagnose::analyseStamps(in.scans, in.sensor.rotation_hz, diagnose::TimingOptions{});
    diagnose::adviseTiming(t, 0, 0);
    t.chirp_doppler = diagnose::chirpDopplerSummary(in.scans, diagnose::chirpOptionsFor(in.base));
    diagnose::writeTimingReport(t, out, why);
    out_dir.commit();
    std::cout << "catalogue stage not run: " << why << "\n";
    printTiming(t);
    std::cout << "report in " << a.out << "\n";
  };
  if (!a.base.empty()) in.base = sim::PhysicsConfig::load(a.base);
  if (a.appearance || (a.trajectory.empty() && !a.timing_only)) runAppearance(a, in.scans, in.base);
  if (a.timing_only || a.trajectory.empty()) {
    timingOnly(a.timing_only ? "--timing-only" : "no --trajectory given");
    return;
  }
  if (!a.world.empty()) in.world = sim::World::load(a.world);
  in.trajectory = sim::Trajectory::loadCsv(a.trajectory);
  checkOverlap(in.scans, in.trajectory, a.trajectory, a.recording);
  for (auto& s : in.scans) s.range_resolution = in.sensor.range_resolution;

  diagnose::DiagnoseOptions opt;
  opt.alpha = a.alpha;
  opt.seed = a.seed;
  opt.resimulate_after = !a.no_resimulate;
  diagnose::DiagnoseReport rep;
  try {
    rep = diagnose::diagnoseRecording(in, opt, !a.world.empty(), a.map_split);
  } catch (const std::runtime_error& e) {
    timingOnly(e.what());
    return;
  }
  diagnose::writeReport(rep, out);
  out_dir.commit();
  std::cout << (!rep.mismatch_found        ? "no significant mismatch"
                : rep.effects.empty()         ? "mismatch found (timing only, below)"
                                              : "mismatch found:");
  for (const auto& e : rep.effects)
    std::cout << " " << e.name << " = " << e.value << " +- " << e.stddev << " " << e.unit
              << " (z " << e.significance << ")";
  std::cout << "\nresidual rms " << rep.before.position_rms << " m -> " << rep.after.position_rms
            << " m; report in " << a.out << "\n";
  printTiming(rep.timing);
}

}  // namespace

SPINRADAR_COMMAND(
    "diagnose",
    "Compare a recording with its re-simulation: locate, name and fit the physics left out",
    [](CLI::App& app) {
      auto a = std::make_shared<DiagnoseArgs>();
      app.add_option("--recording", a->recording, "Oxford polar PNG folder (radar/<stamp>.png) or a rosbag (.bag) of spinradar/RadarScan")
          ->required();
      app.add_option("--trajectory", a->trajectory,
                     "Sensor trajectory CSV t,x,y,yaw (without it only the timing stage runs)");
      app.add_option("--format", a->format,
                     "Scan format of the recording (default: guessed from the folder)")
          ->check(CLI::IsMember({"auto", "oxford", "boreas", "mulran", "radiate"}));
      app.add_flag("--timing-only", a->timing_only,
                   "Only the timing stage (stamps: bursts, period per scan); no world or "
                   "trajectory needed");
      app.add_option("--world", a->world,
                     "World JSON (targets, walls); without it the scene is mapped from part of "
                     "the recording (--map-split)");
      app.add_option("--map-split", a->map_split,
                     "Without --world, which scans map the scene: auto (out-back when the drive reverses "
                     "heading, otherwise early-late; default), out-back, early-late, late-early");
      app.add_option("--base", a->base,
                     "Physics JSON the simulation uses (default: no effects)");
      app.add_option("--range-resolution", a->range_resolution,
                     "Range bin size in m (default: sensor.json of the recording, else 0.0438)");
      app.add_option("--out", a->out, "Output folder (report.json, summary.md, PNG plots)")
          ->required();
      app.add_option("--first-scan", a->first_scan, "First scan of the recording to use")
          ->check(cli::atLeast(0));
      app.add_option("--max-scans", a->max_scans, "Use at most this many scans (-1: all)")
          ->check(CLI::Validator(
              [](std::string& v) -> std::string {
                return v == "-1" || (std::atoi(v.c_str()) >= 1 && v.find_first_not_of("0123456789") == std::string::npos)
                           ? std::string()
                           : v + " is not a count of scans (1 or more, or -1 for all)";
              },
              "", "COUNT"));
      app.add_option("--alpha", a->alpha, "Family-wise significance level (Holm)")
          ->check(cli::inRange(1e-12, 0.5));
      app.add_option("--seed", a->seed, "Noise seed of the re-simulation");
      app.add_flag("--no-resimulate", a->no_resimulate,
                   "Skip re-rendering with the fitted effects (use the linear model's residuals)");
      app.add_flag("--appearance", a->appearance,
                   "Run the appearance stage (levels, widths, texture; fitted sensor file) also "
                   "with a trajectory; without --trajectory it always runs");
      app.add_option("--sensor", a->sensor,
                     "Base sensor model of the appearance stage: JSON file or calibrated name "
                     "(oxford, mulran, boreas_rt, radiate); default: the CIR204-H defaults");
      app.add_option("--appearance-curve-iterations", a->curve_iterations,
                     "Steps of the per-band calibration (range curves; 0 = off)");
      app.add_option("--appearance-curve-starts", a->curve_starts, "Starts of the per-band "
                     "calibration (1-6; a full run from each, the best fit-part misfit wins; default 3)")->check(CLI::Range(1, 6));
      app.add_option("--appearance-curve-start-offset", a->curve_start_offset, "Move its start: "
                     "noise dB, returns dB, log2 clutter density")->expected(3)->check(CLI::Range(-20.0, 20.0));
      app.add_flag("--appearance-no-holdout", a->no_holdout,
                   "Fit the appearance on the whole recording (default: fit on the first half of "
                   "the scans, or quarters 0 and 2 of a single scan, check on the rest)");
      app.add_option("--appearance-split", a->holdout_split,
                     "How the appearance fit splits the recording: blocks:N (azimuth blocks of N "
                     "rows, N even, alternate fit / held out in every scan), scans (every other "
                     "scan) or contiguous (first half of the scans, or quarters 0+2 of one scan; "
                     "the ninth round's); default by the rule in docs/diagnose_holdout.md")
          ->check(CLI::Validator([](std::string& v) -> std::string {
            try { return diagnose::parseHoldoutSplit(v), std::string(); } catch (const std::invalid_argument& e) { return e.what(); }
          }, "", "SPLIT"))
          ->capture_default_str();
      app.add_flag("--appearance-split-survey", a->split_survey,
                   "Only measure the real halves' own difference under candidate splits (the "
                   "held-out check's noise floor) into <out>/appearance/split_survey.md");
      app.add_flag("--appearance-fit-floor", a->fit_floor,
                   "Also fit each band's noise floor (lower half of the counts) in the per-band "
                   "calibration: tells receiver noise from weak clutter (docs/diagnose.md)");
      app.add_flag("--appearance-fit-zeros", a->fit_zeros,
                   "Also fit each band's share of zero counts in the per-band calibration: the "
                   "noise level against the first quantiser step, also where over half the "
                   "counts are zero (MulRan; docs/diagnose_chirps.md)");
      app.add_flag("--appearance-no-cen2018-fit", a->no_cen2018_fit,
                   "Leave the Cen2018 keypoints out of the per-band calibration (still reported): "
                   "with --appearance-fit-floor on Oxford they measure the scene (docs/diagnose_cen2018.md)");
      app.add_option("--appearance-scene", a->appearance_scene,
                     "Reference scene of the appearance re-simulation: a built-in scene name, or "
                     "'recording' (the recording's own fit-part returns as scatterers; issue 20), "
                     "or 'combined' (gain chain and beam from the city scene's fit, the rest "
                     "against the recording's own scene; docs/diagnose_scene.md). Default: the "
                     "--sensor file's reference_scene, else city. A built-in scene is written "
                     "into sensor_fitted.json as its reference_scene");
      app.add_option("--appearance-scene-margin", a->scene_margin_db,
                     "With the recording's own scene: a return stands this far (dB) over its "
                     "range bin's upper quartile")
          ->check(CLI::Range(0.5, 59.0))
          ->capture_default_str();
      app.add_option("--appearance-scene-margins", a->scene_margins,
                     "With the recording's own scene: the margin per range band (dB; 2.5-10, "
                     "10-25, 25-50, 50 m and on), in place of --appearance-scene-margin")
          ->expected(4)
          ->delimiter(',')
          ->check(CLI::Range(0.5, 59.0));
      app.add_option("--appearance-scene-refine", a->scene_refine,
                     "With the recording's own scene: passes of the joint refinement of the "
                     "scatterers' strengths along azimuth (0: off; docs/diagnose_scene.md)")
          ->check(CLI::Range(0, 1000))
          ->capture_default_str();
      app.add_flag("--appearance-scene-subbin", a->scene_subbin,
                   "With the recording's own scene: place each return between range bins "
                   "(parabola through its bin's and its neighbours' log powers) instead of at "
                   "its bin's centre (docs/diagnose_scene.md, tenth round)");
      app.add_flag("--appearance-scene-clean", a->scene_clean,
                   "With the recording's own scene: build it by CLEAN deconvolution (extended "
                   "returns become several scatterers and keep their width) instead of one "
                   "scatterer per local maximum along each row (docs/diagnose_scene.md)");
      app.add_flag("--appearance-fit-spread", a->fit_spread,
                   "Let the per-band figures move the range spread too (CA-CFAR cells follow the "
                   "returns' width; docs/diagnose_scene.md)");
      app.add_flag("--appearance-fit-far-slope", a->fit_far_slope,
                   "Let the per-band figures move the returns' slope beyond the last curve node "
                   "(71 m; sensor return_far_slope_db_per_decade; docs/diagnose_far_band.md)");
      app.add_option("--appearance-hold", a->hold,
                     "Hold a parameter group at the --sensor file's values and fit the rest: "
                     "clutter (clutter_density, clutter_density_x_*, clutter_rcs_db, "
                     "clutter_rcs_sd_db; docs/diagnose_hold_clutter.md)")
          ->check(CLI::IsMember({"clutter"}));
      app.add_option("--appearance-gain-chain", a->gain_chain,
                     "With --appearance-scene combined: hold the gain chain and beam of this "
                     "sensor (file or calibrated name, e.g. the city fit in config/sensors) "
                     "instead of fitting them with the city scene first");
      app.add_option("--appearance-iterations", a->appearance_iterations,
                     "Newton steps of the catalogue fit (0: the --sensor file's global terms "
                     "are kept and only the range curves, leakage and glint are fitted)")
          ->check(CLI::Range(0, 20))
          ->capture_default_str();
      cli::addRenderSeedsOption(app, a->render_seeds, "the appearance stage's seed 12");
      app.add_option("--appearance-fit-seeds", a->fit_seeds,
                     "Noise seeds the per-band calibration's objective is averaged over (11, "
                     "1011, ...; apart from the --render-seeds ones): a fit to one render's "
                     "noise does not carry over (docs/diagnose_render_seeds.md)")
          ->check(cli::inRange(1, 64))
          ->capture_default_str();
      app.add_option("--appearance-scans", a->appearance_scans,
                     "Re-simulated scans per evaluation in the appearance fit")
          ->capture_default_str();
      app.callback([a] { run(*a); });
    });
