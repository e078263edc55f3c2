// `spinradar serve`: the simulator as a live Navtech sensor on a loopback TCP port, so the
// driver (nodelet or CLI) runs with no hardware. Stops on Ctrl-C or at the end of the scene
// (with --loop it starts the route over, stamps still increasing).
#include <atomic>
#include <chrono>
#include <csignal>
#include <iostream>
#include <thread>

#include "cli_checks.hpp"
#include "command.hpp"
#include "spinradar/driver/navtech_server.hpp"
#include "spinradar/sim/physics.hpp"
#include "spinradar/sim/reference_scene.hpp"
#include "spinradar/sim/scenes.hpp"
#include "spinradar/sim/sim_radar_input.hpp"

namespace {

std::atomic<bool> g_stop{false};

spinradar::sim::PhysicsConfig loadPhysics(const std::string& arg) {
  if (arg.empty()) return {};
  if (arg.front() == '{') {
    try {
      return spinradar::sim::PhysicsConfig::fromJson(nlohmann::json::parse(arg));
    } catch (const nlohmann::json::exception& e) {
      throw std::runtime_error("--physics: not valid JSON: " + std::string(e.what()));
    }
  }
  return spinradar::sim::PhysicsConfig::load(arg);
}

struct ServeOptions {
  std::string scene;  // empty: the sensor file's reference_scene, else city
  int port = 6317;
  std::string bind = "127.0.0.1";
  double rate = 1.0;
  std::string physics, sensor;
  bool loop = false;
  int bit_depth = 8;
  bool sim_clock = false;
  std::string time_order = "little";
  uint64_t seed = 1;
  int max_clients = spinradar::navtech::ServerOptions{}.max_clients;
  int encoder_phase = 0;
};

void serve(const ServeOptions& o) {
  using namespace spinradar;
  const sim::SensorConfig sensor =
      o.sensor.empty() ? sim::SensorConfig{} : sim::SensorConfig::loadNamed(o.sensor);
  // A calibrated sensor is served in the scene it was fitted in unless --scene names one.
  const std::string scene = sim::sceneOrReference(o.scene, sensor, "city");
  auto sim = sim::makeBuiltinSimulator(scene, loadPhysics(o.physics), o.seed, 0.0, sensor);
  navtech::ServerOptions so;
  so.bind = o.bind;
  so.port = o.port;
  so.rate = o.rate;
  so.rotation_hz = sim->sensor().rotation_hz;
  so.bit_depth = o.bit_depth;
  so.wall_clock = !o.sim_clock;
  so.max_clients = o.max_clients;
  so.encoder_phase = o.encoder_phase;
  const int step = sim->sensor().encoder_size / std::max(1, sim->sensor().azimuths);
  if (o.encoder_phase >= step)
    throw std::invalid_argument("--encoder-phase " + std::to_string(o.encoder_phase) +
                                ": must be below one azimuth step (" + std::to_string(step) +
                                " counts)");
  so.time_order = navtech::parseTimeByteOrder(o.time_order);
  if (so.time_order == navtech::TimeByteOrder::Auto) so.time_order = navtech::TimeByteOrder::Little;
  navtech::NavtechServer server(so, sim::simScanSource(sim, 0, o.loop));
  server.start();
  std::cerr << "serve: scene '" << scene << "' (" << sim->scanCount() << " rotations) on "
            << o.bind << ":" << server.port() << " at " << o.rate << "x real time"
            << (o.sim_clock ? ", simulator clock" : ", wall clock") << ", up to " << o.max_clients
            << " client(s) at once; Ctrl-C to stop"
            << std::endl;
  std::signal(SIGINT, [](int) { g_stop = true; });
  std::signal(SIGTERM, [](int) { g_stop = true; });
  auto next_report = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!g_stop && !server.finished()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (std::chrono::steady_clock::now() >= next_report) {
      const auto st = server.stats();
      std::cerr << "serve: " << st.scans_started << " rotations, " << st.azimuths_sent
                << " azimuths sent, " << st.clients << " client connection(s)" << std::endl;
      next_report += std::chrono::seconds(10);
    }
  }
  server.stop();
  std::cerr << "serve: " << (server.finished() ? "end of the scene" : "stopped") << std::endl;
}

}  // namespace

SPINRADAR_COMMAND("serve", "Serve a simulated scene as a live Navtech radar (TCP protocol) on a loopback port",
                  [](CLI::App& app) {
                    auto o = std::make_shared<ServeOptions>();
                    app.add_option("--scene", o->scene, "Built-in scene: city, city_elevated, city_facades, city_facades_heights, city_heights, city_open, out_and_back or tight_turns (default: the --sensor file's reference_scene, else city)");
                    app.add_option("--port", o->port, "TCP port (Navtech default 6317; 0 = any free port)")
                        ->capture_default_str()
                        ->check(spinradar::cli::inRange(0, 65535));
                    app.add_option("--bind", o->bind, "Address to listen on (keep it loopback unless you mean it)")
                        ->capture_default_str();
                    app.add_option("--rate", o->rate, "Multiple of real time (0 = as fast as the client reads)")
                        ->capture_default_str()
                        ->check(spinradar::cli::atLeast(0));
                    app.add_option("--physics", o->physics,
                                   "Physics configuration: a JSON file or an inline JSON object, e.g. "
                                   "'{\"motion_distortion\": true, \"doppler\": 0.049}'");
                    app.add_option("--sensor", o->sensor,
                                   "Sensor: a JSON file or a calibrated sensor name (oxford, mulran, "
                                   "boreas_rt, radiate; config/sensors/)");
                    app.add_flag("--loop", o->loop, "Start the route over at its end (stamps keep increasing)");
                    app.add_option("--bit-depth", o->bit_depth, "FFT data: 8 (type 30) or 16 (type 31)")
                        ->check(CLI::IsMember({8, 16}))
                        ->capture_default_str();
                    app.add_flag("--sim-clock", o->sim_clock,
                                 "Send the simulator's clock as sensor time (default: wall clock, like a real sensor)");
                    app.add_option("--time-byte-order", o->time_order, "Byte order of seconds/nanoseconds: little or big")
                        ->check(CLI::IsMember({"little", "big"}))
                        ->capture_default_str();
                    app.add_option("--seed", o->seed, "Simulator noise seed")->capture_default_str();
                    app.add_option("--max-clients", o->max_clients,
                                   "Clients streamed to at once, each with its own start/stop; one more is refused (log line)")
                        ->check(CLI::Range(1, 64))
                        ->capture_default_str();
                    app.add_option("--encoder-phase", o->encoder_phase,
                                   "Counts added to reported encoder values, below one step (a real CIR204-H: 13)")
                        ->check(CLI::NonNegativeNumber)
                        ->capture_default_str();
                    app.callback([o] { serve(*o); });
                  });
