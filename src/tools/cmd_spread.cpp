// `spinradar spread`: spread of returns matched between consecutive scans, across and along the
// beam per range band, on the real samples, recording folders and simulated scenes (consecutive
// scans). The glint of extended objects shows here (matched_spread.hpp).
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "cli_checks.hpp"
#include "command.hpp"
#include "scene_comparison_options.hpp"
#include "spinradar/diagnose/glint_terms.hpp"
#include "spinradar/diagnose/matched_spread.hpp"
#include "spinradar/io/scan_folder.hpp"
#include "spinradar/sim/realism.hpp"
#include "spinradar/sim/scenes.hpp"
#include "spinradar/sim/simulator.hpp"

namespace {

struct SpreadCmdOptions : spinradar::cli::SceneComparisonOptions {
  SpreadCmdOptions() { scenes = {"city"}; }
  int scans = 8;
  int start = -1;  // first simulated scan (-1: middle of the route)
  uint64_t seed = 1;
  double glint = -1;  // overrides the physics' glint when >= 0
  bool fit = false;
  spinradar::diagnose::SpreadOptions spread;
};

void printRow(const std::string& name, const spinradar::diagnose::MatchedSpread& s) {
  std::printf("| %s | %d | %d |", name.c_str(), s.pairs, s.returns);
  for (const auto& b : s.band)
    std::printf(" %.3f / %.3f (%d) |", b.tangential, b.radial, b.matches);
  std::printf(" %.3f +- %.3f / %.3f |\n", s.all.tangential, s.all.tangential_se, s.all.radial);
}

void runSpread(const SpreadCmdOptions& o) {
  using namespace spinradar;
  using namespace spinradar::sim;
  PhysicsConfig physics = cli::comparisonPhysics(o);
  if (o.glint >= 0) physics.extra["glint"] = o.glint;
  physics = PhysicsConfig::fromJson(physics.toJson());  // range checks
  const SensorConfig sensor = o.sensor.empty() ? SensorConfig{} : SensorConfig::loadNamed(o.sensor);
  std::printf("| data | pairs | returns/scan | 2.5-10 m tan / rad (n) | 10-25 m | 25-50 m | "
              "50-100 m | all: tan +- se / rad |\n|---|---|---|---|---|---|---|---|\n");
  std::vector<std::pair<std::string, std::vector<PolarScan>>> fits;
  if (!o.no_real) {
    if (!std::filesystem::is_directory(o.realdata))
      throw std::runtime_error(o.realdata + ": no such folder of real samples (--realdata; "
                               "--no-real for simulations only)");
    for (auto& [name, scans] : loadRealSamples(o.realdata))
      if (scans.size() >= 2) {
        printRow(name, diagnose::measureMatchedSpread(scans, nullptr, o.spread));
        if (o.fit) fits.emplace_back(name, scans);
      }
  }
  for (const auto& dir : o.recordings) {
    ScanFolder folder(dir);
    std::vector<PolarScan> scans;
    for (size_t i = 0; i < std::min<size_t>(folder.size(), size_t(o.scans)); ++i)
      scans.push_back(folder.load(i));
    printRow(dir, diagnose::measureMatchedSpread(scans, nullptr, o.spread));
    if (o.fit) fits.emplace_back(dir, scans);
  }
  for (const auto& name : o.scenes) {
    Scene sc = builtinScene(name);
    Simulator sim(sc.world, sc.trajectory, sensor, physics, o.seed);
    const int first = o.start >= 0 ? o.start : std::max(0, sim.scanCount() / 2 - o.scans / 2);
    std::vector<PolarScan> scans;
    for (int i = first; i < std::min(sim.scanCount(), first + o.scans); ++i)
      scans.push_back(sim.renderScan(i));
    printRow(name + " (sim" + (o.sensor.empty() ? "" : ", " + o.sensor) + ")",
             diagnose::measureMatchedSpread(scans, nullptr, o.spread));
  }
  for (const auto& [name, scans] : fits) {
    // The glint terms against the sensor model without its own (the glint of --physics/--glint
    // is kept as the base).
    diagnose::GlintTermsOptions go;
    go.ref.spread = o.spread;
    const auto g = diagnose::fitGlintTerms(scans, sensor, physics, go);
    std::printf("\n%s: glint terms against the sensor model%s\n%s", name.c_str(),
                o.sensor.empty() ? "" : (" " + o.sensor).c_str(), diagnose::glintTermsTable(g).c_str());
  }
  std::cout << "\nRobust std (1.4826 MAD) of the difference of mutually nearest returns of "
               "consecutive scans after alignment, m: across the beam / along it (matches).\n";
}

}  // namespace

SPINRADAR_COMMAND("spread", "Spread of returns matched between consecutive scans, across and along the beam per range band",
                  [](CLI::App& app) {
                    auto o = std::make_shared<SpreadCmdOptions>();
                    spinradar::cli::addSceneComparisonOptions(app, *o);
                    app.add_option("--glint", o->glint, "Physics glint (m) of the simulated scenes")
                        ->check(spinradar::cli::atLeast(0));
                    app.add_option("--scans", o->scans, "Consecutive scans per scene or recording")
                        ->capture_default_str()
                        ->check(spinradar::cli::atLeast(2));
                    app.add_option("--start", o->start, "First simulated scan (default: mid-route)");
                    app.add_option("--seed", o->seed, "Noise seed")->capture_default_str();
                    app.add_option("--keep", o->spread.keep_fraction,
                                   "Strongest share of each band's cells that may be a return")
                        ->capture_default_str()
                        ->check(CLI::Range(1e-5, 0.2));
                    app.add_option("--gate", o->spread.gate, "Matching gate, m")
                        ->capture_default_str()
                        ->check(CLI::Range(0.1, 5.0));
                    app.add_flag("--fit", o->fit,
                                 "Fit the glint terms (glint_across, glint_along, azimuth_jitter) of "
                                 "the real samples and --recording folders (reference: the city "
                                 "route with --sensor)");
                    app.callback([o] { runSpread(*o); });
                  });
