// `spinradar realism`: realism figures of simulated scans next to the real samples.
#include <filesystem>
#include <iostream>

#include "cli_checks.hpp"
#include "render_seeds_option.hpp"
#include "command.hpp"
#include "scene_comparison_options.hpp"
#include "spinradar/io/scan_folder.hpp"
#include "spinradar/sim/realism.hpp"
#include "spinradar/sim/realism_seeds.hpp"
#include "spinradar/sim/reference_scene.hpp"
#include "spinradar/sim/scenes.hpp"
#include "spinradar/sim/simulator.hpp"

namespace {

struct RealismCmdOptions : spinradar::cli::SceneComparisonOptions {
  // No default scene list here: without --scene, runRealism takes the sensor file's
  // reference_scene, else kDefaultScenes (the list before the key existed).
  static inline const std::vector<std::string> kDefaultScenes = {"city", "out_and_back", "tight_turns"};
  int scans = 8;
  uint64_t seed = 1;
  int render_seeds = 1;  // noise seeds per scene: seed, seed + 1, ... (figures: mean [range])
  double min_range = 2.5, max_range = 100.0;
  bool no_detect = false;
};

void runRealism(const RealismCmdOptions& o) {
  using namespace spinradar;
  using namespace spinradar::sim;
  RealismOptions ro;
  if (!(o.min_range < o.max_range))
    throw std::runtime_error("--min-range " + readableNumber(o.min_range) +
                             " m is not below --max-range " + readableNumber(o.max_range) +
                             " m: no cell would be compared");
  // The real columns are the point of the table: a missing or empty folder is an error, not a
  // table without them (--no-real compares simulations only).
  if (!o.no_real && !std::filesystem::is_directory(o.realdata))
    throw std::runtime_error(o.realdata + ": no such folder of real samples (--realdata; "
                             "--no-real compares simulations only)");
  ro.min_range = o.min_range;
  ro.max_range = o.max_range;
  ro.detect = !o.no_detect;
  std::vector<RealismStats> cols;
  std::vector<RealismOverSeeds> spreads;  // per simulated scene
  const std::vector<uint64_t> seeds = renderSeeds(o.seed, o.render_seeds);
  PhysicsConfig physics = cli::comparisonPhysics(o);
  SensorConfig sensor = o.sensor.empty() ? SensorConfig{} : SensorConfig::loadNamed(o.sensor);
  // The real samples are read first: a missing or corrupt one stops the command before the
  // (slow) simulations.
  std::vector<std::pair<std::string, std::vector<PolarScan>>> real_cols;
  if (!o.no_real) {
    // A corrupt sample stops the command with its name (loaders name the file).
    auto real = loadRealSamples(o.realdata);
    if (real.empty())
      throw std::runtime_error(o.realdata + ": no real samples found (expected "
                               "oxford_2019-01-10-14-36-48/radar/*.png, mulran/*.csv, "
                               "boreas_rt/test_frame.png or radiate_fog_6_0/Navtech_Polar/*.png)");
    real_cols = std::move(real);
  }
  // A calibrated sensor is compared in the scene it was fitted in unless --scene names scenes.
  std::vector<std::string> scenes = o.scenes;
  if (scenes.empty())
    scenes = sensor.reference_scene.empty() ? RealismCmdOptions::kDefaultScenes
                                            : std::vector<std::string>{sensor.reference_scene};
  for (const auto& name : scenes) {
    const Scene sc = builtinScene(name);
    auto render = [&](uint64_t seed) {
      Simulator sim(sc.world, sc.trajectory, sensor, physics, seed);
      std::vector<PolarScan> scans;
      const int total = sim.scanCount();
      for (int i = 0; i < o.scans; ++i) scans.push_back(sim.renderScan(int((i + 0.5) * total / o.scans)));
      return scans;
    };
    const std::string label =
        o.render_seeds == 1 ? name + " (sim)"
                            : name + " (sim, mean of " + std::to_string(o.render_seeds) + " seeds)";
    spreads.push_back(realismOverSeeds(render, seeds, label, ro));
    cols.push_back(spreads.back().mean);
  }
  for (const auto& dir : o.recordings) {
    ScanFolder folder(dir);
    std::vector<PolarScan> scans;
    size_t n = std::min<size_t>(folder.size(), size_t(o.scans));
    for (size_t i = 0; i < n; ++i) scans.push_back(folder.load(i * folder.size() / n));
    cols.push_back(computeRealism(scans, dir, ro));
  }
  for (auto& [name, scans] : real_cols) cols.push_back(computeRealism(scans, name, ro));
  std::vector<const RealismOverSeeds*> ranges(cols.size(), nullptr);
  for (size_t i = 0; i < spreads.size(); ++i) ranges[i] = &spreads[i];
  std::cout << formatRealismTable(cols, ranges);
  if (o.render_seeds > 1)
    std::cout << "\nSimulated columns: mean over noise seeds " << o.seed << "-"
              << o.seed + uint64_t(o.render_seeds - 1) << " [lowest-highest seed].";
  std::cout << "\nCells " << o.min_range << "-" << o.max_range
            << " m. * RADIATE is rescaled (not native ~1 dB/count): compare its texture only.\n";
}

}  // namespace

SPINRADAR_COMMAND("realism", "Compare simulated scans with the real samples (histogram, texture, detections)",
                  [](CLI::App& app) {
                    auto o = std::make_shared<RealismCmdOptions>();
                    spinradar::cli::addSceneComparisonOptions(app, *o);
                    app.get_option("--scene")->description(
                        "Built-in scenes to simulate (default: the --sensor file's "
                        "reference_scene, else city out_and_back tight_turns)");
                    app.add_option("--scans", o->scans, "Scans per simulated scene")
                        ->capture_default_str()
                        ->check(spinradar::cli::atLeast(1));
                    app.add_option("--seed", o->seed, "Noise seed (the first, with --render-seeds)")->capture_default_str();
                    spinradar::cli::addRenderSeedsOption(app, o->render_seeds, "--seed");
                    app.add_option("--min-range", o->min_range, "m")
                        ->capture_default_str()
                        ->check(spinradar::cli::atLeast(0));
                    app.add_option("--max-range", o->max_range, "m")
                        ->capture_default_str()
                        ->check(spinradar::cli::positive());
                    app.add_flag("--no-detect", o->no_detect, "Skip the detectors");
                    app.callback([o] { runRealism(*o); });
                  });
