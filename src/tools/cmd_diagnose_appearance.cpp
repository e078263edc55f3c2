// `spinradar diagnose`, the appearance stage: options to diagnose::AppearanceOptions, the run,
// its one-paragraph summary on stdout (docs/diagnose.md).
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <stdexcept>

#include "diagnose_args.hpp"
#include "spinradar/diagnose/appearance_split.hpp"
#include "spinradar/sim/reference_scene.hpp"

namespace spinradar::tools {

namespace fs = std::filesystem;

namespace {

/// The real halves' own difference under the candidate splits (docs/diagnose_holdout.md, tenth
/// round): <out>/appearance/split_survey.md and stdout.
void splitSurvey(const std::vector<PolarScan>& scans, const std::string& dir) {
  std::vector<diagnose::HoldoutSplit> c;
  for (const char* n : {"contiguous", "scans", "blocks:2", "blocks:4", "blocks:8", "blocks:16",
                        "blocks:20", "blocks:24", "blocks:32", "blocks:40", "blocks:50", "blocks:100"})
    c.push_back(diagnose::parseHoldoutSplit(n));
  const std::string md = diagnose::splitSurveyMarkdown(diagnose::surveySplits(scans, c));
  fs::create_directories(dir);
  if (!(std::ofstream(fs::path(dir) / "split_survey.md") << md))
    throw std::runtime_error(dir + "/split_survey.md: cannot write");
  std::cout << md;
}

}  // namespace

void runAppearance(const DiagnoseArgs& a, const std::vector<PolarScan>& scans,
                   const sim::PhysicsConfig& physics) {
  if (a.split_survey) return splitSurvey(scans, (fs::path(a.out) / "appearance").string());
  sim::SensorConfig s = a.sensor.empty() ? sim::SensorConfig{} : sim::SensorConfig::loadNamed(a.sensor);
  // The re-simulation must have the recording's geometry.
  const PolarScan& p = scans.front();
  s.azimuths = p.azimuths;
  s.bins = p.bins;
  s.range_resolution = p.range_resolution;
  s.encoder_size = std::max(p.encoder_size, p.azimuths);
  s.validate();
  diagnose::AppearanceOptions opt;
  opt.scans = a.appearance_scans;
  opt.iterations = a.appearance_iterations;
  opt.render_seeds = a.render_seeds;
  opt.fit_seeds = a.fit_seeds;
  opt.curve_iterations = a.curve_iterations;
  opt.curve_starts = a.curve_starts;
  for (size_t i = 0; i < a.curve_start_offset.size() && i < 3; ++i) opt.curve_start_offset[i] = a.curve_start_offset[i];
  opt.holdout = !a.no_holdout;
  opt.fit_band_floor = a.fit_floor;
  opt.fit_band_zeros = a.fit_zeros;
  opt.fit_cen2018 = !a.no_cen2018_fit;
  // A calibrated file is re-fitted and scored in the scene it was calibrated in unless
  // --appearance-scene names another (its figures mean nothing elsewhere).
  opt.scene = sim::sceneOrReference(a.appearance_scene, s, "city");
  opt.scene_margin_db = a.scene_margin_db;
  opt.scene_clean = a.scene_clean;
  opt.scene_margin_bands_db = a.scene_margins;
  opt.scene_refine_passes = a.scene_refine;
  opt.scene_range_subbin = a.scene_subbin;
  opt.fit_spread_bands = a.fit_spread;
  opt.fit_far_slope = a.fit_far_slope;
  opt.hold_clutter = a.hold == "clutter";
  opt.holdout_split = a.holdout_split;
  if (!a.gain_chain.empty()) {
    if (opt.scene != "combined")
      throw std::invalid_argument("--appearance-gain-chain needs --appearance-scene combined");
    opt.gain_chain =
        std::make_shared<const sim::SensorConfig>(sim::SensorConfig::loadNamed(a.gain_chain));
  }
  const auto rep = diagnose::diagnoseAppearance(scans, s, physics, opt);
  const std::string dir = (fs::path(a.out) / "appearance").string();
  diagnose::writeAppearanceReport(rep, scans, diagnose::withReferenceScene(opt, scans), dir);
  std::cout << "appearance:";
  int named = 0;
  for (const auto& f : rep.findings)
    if (f.named) {
      ++named;
      std::cout << " " << f.effect << " " << f.base << " -> " << f.value << " +- " << f.stddev
                << " " << f.unit << " (z " << f.z << ");";
    }
  if (!named) std::cout << " nothing named";
  std::cout << "\nappearance: worst per-band realism gap " << 100 * rep.worst_gap_before << " % -> "
            << 100 * rep.worst_gap_after << " % (fit part, " << rep.fit_scans << " scans)";
  if (rep.holdout_scans > 0)
    std::cout << ", held out " << 100 * rep.worst_holdout_before << " % -> "
              << 100 * rep.worst_holdout_after << " % (" << rep.holdout_scans << " scans)";
  if (opt.render_seeds > 1) std::cout << "; means over " << opt.render_seeds << " noise seeds";
  std::cout << "; report and sensor_fitted.json in " << dir << "\n";
}

}  // namespace spinradar::tools
