// `spinradar simulate`: renders a recording folder (Oxford polar PNGs + truth) from a built-in
// scene or from world/trajectory files.
#include <chrono>
#include <iostream>
#include <optional>

#include <nlohmann/json.hpp>

#include "cli_checks.hpp"
#include "command.hpp"
#include "spinradar/core/safe_output.hpp"
#include "spinradar/sim/reference_scene.hpp"
#include "spinradar/sim/scenes.hpp"
#include "spinradar/sim/simulator.hpp"
#ifdef SPINRADAR_HAVE_BAG
#include "scan_bag.hpp"
#endif

namespace {

struct SimulateOptions {
  std::string scene, world, trajectory, physics, sensor, out, bag;
  uint64_t seed = 1;
  uint64_t variant = 0;
  int scans = -1;
  int first = 0;
  double t0 = 0.0;
  bool list = false;
  bool force = false;
};

void runSimulate(const SimulateOptions& o) {
  using namespace spinradar::sim;
  if (o.list) {
    for (const auto& n : builtinSceneNames()) {
      Scene s = builtinScene(n);
      std::cout << n << ": " << s.description << " (" << s.world.targets.size() << " targets, "
                << s.world.walls.size() << " walls, "
                << s.trajectory.endTime() - s.trajectory.startTime() << " s)\n";
    }
    return;
  }
  if (o.out.empty()) throw std::runtime_error("--out is required");
  const std::vector<spinradar::NamedPath> inputs{{o.world, "--world"}, {o.trajectory, "--trajectory"},
                                                 {o.physics, "--physics"}, {o.sensor, "--sensor"}};
  spinradar::refuseOutputOverInput({o.out, "--out"}, inputs, true);
  if (!o.bag.empty()) {
    spinradar::refuseOutputOverInput({o.bag, "--bag"}, inputs);
    spinradar::refuseOutputOverInput({o.bag, "--bag"}, {{o.out, "--out"}}, false);
  }
  // The recording is written aside and moved into place when complete (--force: over the old
  // scans of a non-empty folder).
  spinradar::AtomicOutputFolder out_dir(o.out, o.force);
  SensorConfig sensor = o.sensor.empty() ? SensorConfig{} : SensorConfig::loadNamed(o.sensor);
  // Without --scene, --world or --trajectory a calibrated sensor renders in its reference scene
  // (the scene it was fitted in); with --world it renders there, as before.
  const bool own_world = !o.world.empty() || !o.trajectory.empty();
  const std::string scene = own_world ? o.scene : sceneOrReference(o.scene, sensor, "");
  World world;
  Trajectory traj;
  if (!scene.empty()) {
    if (own_world)
      throw std::runtime_error("give either --scene or --world and --trajectory, not both");
    if (o.scene.empty()) std::cerr << "simulate: scene '" << scene << "' (the sensor file's reference_scene)\n";
    Scene s = builtinScene(scene, o.variant, o.t0);
    world = std::move(s.world);
    traj = std::move(s.trajectory);
  } else {
    if (o.world.empty() || o.trajectory.empty())
      throw std::runtime_error("give --scene NAME (or a --sensor file with a reference_scene), or "
                               "both --world JSON and --trajectory CSV");
    world = World::load(o.world);
    traj = Trajectory::loadCsv(o.trajectory);
  }
  PhysicsConfig physics = o.physics.empty() ? PhysicsConfig{} : PhysicsConfig::load(o.physics);
  Simulator sim(std::move(world), std::move(traj), sensor, physics, o.seed);
  int total = sim.scanCount();
  std::cerr << "simulate: " << total << " rotations available, physics "
            << sim.physics().toJson().dump() << ", seed " << o.seed << "\n";
  auto start = std::chrono::steady_clock::now();
  if (o.first >= total)
    throw std::runtime_error("--first " + std::to_string(o.first) + ": the scene has only " +
                             std::to_string(total) + " rotations");
  int n = writeRecording(sim, out_dir.tempPath(), o.first, o.scans, true);
  double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cerr << "simulate: wrote " << n << " scans to " << o.out << " in " << secs << " s ("
            << (secs > 0 ? n / secs : 0.0) << " scans/s including PNG encoding)\n";
  if (!o.bag.empty()) {
#ifdef SPINRADAR_HAVE_BAG
    spinradar::bag::ScanBagOptions bo;
    bo.rotation_hz = sensor.rotation_hz;
    spinradar::ScanFolderOptions fo;
    fo.range_resolution = sensor.range_resolution;
    spinradar::AtomicOutputFile bag_file(o.bag);
    const size_t m = spinradar::bag::folderToBag(
        spinradar::ScanFolder(out_dir.tempPath(), spinradar::ScanFormat::Oxford, fo),
        bag_file.tempPath(), bo);
    bag_file.commit();
    std::cerr << "simulate: wrote " << m << " RadarScan messages to " << o.bag << "\n";
#else
    throw std::runtime_error("--bag needs spinradar built with ROS (catkin)");
#endif
  }
  out_dir.commit();
}

}  // namespace

SPINRADAR_COMMAND("simulate", "Simulate a recording (Oxford polar PNGs + true trajectory)",
                  [](CLI::App& app) {
                    auto o = std::make_shared<SimulateOptions>();
                    app.add_option("--scene", o->scene,
                                   "Built-in scene: city, city_elevated, city_facades, city_facades_heights, city_heights, city_open, out_and_back, tight_turns (default: the --sensor file's reference_scene, if it has one)");
                    app.add_option("--world", o->world, "World JSON file");
                    app.add_option("--trajectory", o->trajectory, "Trajectory CSV (t,x,y,yaw)");
                    app.add_option("--physics", o->physics,
                                   "Physics configuration JSON (absent effects are off)");
                    app.add_option("--sensor", o->sensor, "Sensor: JSON file (subset) or calibrated name (oxford, mulran, boreas_rt, radiate)");
                    app.add_option("--seed", o->seed, "Noise seed")->capture_default_str();
                    app.add_option("--variant", o->variant, "Built-in scene layout variant")
                        ->capture_default_str();
                    app.add_option("--t0", o->t0, "Built-in scene start time (s)")
                        ->capture_default_str();
                    app.add_option("--scans", o->scans, "Number of scans (default: all)")
                        ->check(spinradar::cli::atLeast(1));
                    app.add_option("--first", o->first, "First scan index")
                        ->capture_default_str()
                        ->check(spinradar::cli::atLeast(0));
                    app.add_option("--out", o->out,
                                   "Output recording folder (new or empty; written aside and "
                                   "moved into place when complete)");
                    app.add_flag("--force", o->force,
                                 "Write into a non-empty --out folder: its old scans (radar/, "
                                 "radar.timestamps) are removed first");
                    app.add_option("--bag", o->bag,
                                   "Also write the scans as a rosbag of spinradar/RadarScan");
                    app.add_flag("--list-scenes", o->list, "List the built-in scenes and exit");
                    app.callback([o] { runSimulate(*o); });
                  });
