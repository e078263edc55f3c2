#pragma once
// The simulator as a Navtech data source: scans rendered by spinradar::sim::Simulator, encoded
// with the protocol encoder (so the same parser path as a real sensor runs), either pulled
// directly by the driver (SimRadarInput) or served on a loopback port (simScanSource +
// navtech::NavtechServer, `spinradar serve`).
#include <memory>
#include <string>

#include "spinradar/driver/navtech_server.hpp"
#include "spinradar/driver/radar_input.hpp"
#include "spinradar/sim/simulator.hpp"

namespace spinradar::sim {

struct SimInputOptions {
  double rate = 0.0;   ///< 1 = real time, 0 = as fast as the simulator renders
  int first_scan = 0;
  int n_scans = -1;    ///< -1: every whole rotation of the trajectory
  int bit_depth = 8;   ///< 16: type-31 messages with value = power * 256
  bool wall_clock = false;  ///< shift stamps so the first azimuth is "now" (like a live sensor)
};

/// Receive stamps equal the (possibly wall-clock shifted) acquisition stamps (a perfect
/// network), so runs without wall_clock are deterministic whatever the rate.
class SimRadarInput : public navtech::ByteStreamInput {
 public:
  SimRadarInput(std::shared_ptr<const Simulator> sim, SimInputOptions options = {});
  std::string describe() const override { return "simulator"; }

 protected:
  navtech::InputStatus readSome(std::vector<uint8_t>& chunk, int64_t& receive_ns,
                                std::chrono::steady_clock::time_point deadline) override;

 private:
  std::shared_ptr<const Simulator> sim_;
  SimInputOptions opt_;
  int next_scan_;
  int end_scan_;
  PolarScan scan_;
  int row_ = 0;
  bool sent_config_ = false;
  std::vector<uint16_t> bins16_;
  int64_t first_stamp_ = 0;
  int64_t offset_ns_ = 0;
  bool offset_set_ = false;
  bool started_ = false;
  std::chrono::steady_clock::time_point start_{};
};

std::unique_ptr<navtech::RadarInput> makeSimInput(std::shared_ptr<const Simulator> sim,
                                                  SimInputOptions options = {});

/// A simulator of a built-in scene (spinradar/sim/scenes.hpp: city, out_and_back,
/// tight_turns) with the default CIR204-H sensor. Throws std::invalid_argument for an unknown
/// scene, listing the valid names.
std::shared_ptr<const Simulator> makeBuiltinSimulator(const std::string& scene,
                                                      const PhysicsConfig& physics,
                                                      uint64_t seed = 1, double t0 = 0.0,
                                                      const SensorConfig& sensor = {});

/// Scans for NavtechServer, in order from `first_scan`. With `loop`, starts over at the end
/// with stamps shifted by the trajectory's duration so time keeps increasing.
navtech::ScanSource simScanSource(std::shared_ptr<const Simulator> sim, int first_scan = 0,
                                  bool loop = false);

}  // namespace spinradar::sim
