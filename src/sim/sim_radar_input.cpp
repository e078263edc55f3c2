#include "spinradar/sim/sim_radar_input.hpp"

#include <algorithm>
#include <cmath>
#include <thread>

#include "spinradar/sim/scenes.hpp"

namespace spinradar::sim {

using navtech::InputStatus;

namespace {
navtech::Configuration configOf(const Simulator& sim) {
  const SensorConfig& s = sim.sensor();
  navtech::Configuration c;
  c.azimuth_samples = uint16_t(s.azimuths);
  c.bin_size = uint16_t(std::lround(s.range_resolution * 1e4));
  c.range_in_bins = uint16_t(s.bins);
  c.encoder_size = uint16_t(s.encoder_size);
  c.rotation_mhz = uint16_t(std::lround(s.rotation_hz * 1e3));
  c.packet_rate = uint16_t(std::lround(s.rotation_hz * s.azimuths));
  return c;
}
}  // namespace

SimRadarInput::SimRadarInput(std::shared_ptr<const Simulator> sim, SimInputOptions options)
    : sim_(std::move(sim)), opt_(options), next_scan_(options.first_scan) {
  const int count = sim_->scanCount();
  end_scan_ = opt_.n_scans < 0 ? count : std::min(count, opt_.first_scan + opt_.n_scans);
}

InputStatus SimRadarInput::readSome(std::vector<uint8_t>& chunk, int64_t& receive_ns,
                                    std::chrono::steady_clock::time_point deadline) {
  if (!sent_config_) {
    navtech::encodeConfiguration(chunk, configOf(*sim_));
    sent_config_ = true;
    receive_ns = 0;
    return InputStatus::Ok;
  }
  if (row_ >= scan_.azimuths) {
    if (next_scan_ >= end_scan_) return InputStatus::End;
    scan_ = sim_->renderScan(next_scan_++);
    row_ = 0;
  }
  if (opt_.wall_clock && !offset_set_) {
    offset_ns_ = navtech::wallClockNs() - scan_.stamp_ns[row_];
    offset_set_ = true;
  }
  const int64_t stamp = scan_.stamp_ns[row_] + offset_ns_;
  if (opt_.rate > 0) {
    if (!started_) {
      first_stamp_ = stamp;
      start_ = std::chrono::steady_clock::now();
      started_ = true;
    }
    const auto due = start_ + std::chrono::nanoseconds(int64_t(double(stamp - first_stamp_) / opt_.rate));
    if (due > deadline) {
      std::this_thread::sleep_until(deadline);
      return InputStatus::Timeout;
    }
    std::this_thread::sleep_until(due);
  }
  const uint8_t* bins = scan_.row(row_);
  if (opt_.bit_depth == 16) {
    bins16_.resize(size_t(scan_.bins));
    for (int b = 0; b < scan_.bins; ++b) bins16_[b] = uint16_t(bins[b] << 8);
    navtech::encodeFft16(chunk, uint16_t(row_), scan_.encoder[row_], stamp, bins16_.data(),
                         bins16_.size());
  } else {
    navtech::encodeFft8(chunk, uint16_t(row_), scan_.encoder[row_], stamp, bins,
                        size_t(scan_.bins));
  }
  receive_ns = stamp;
  ++row_;
  return InputStatus::Ok;
}

std::shared_ptr<const Simulator> makeBuiltinSimulator(const std::string& scene,
                                                      const PhysicsConfig& physics, uint64_t seed,
                                                      double t0, const SensorConfig& sensor) {
  Scene s = builtinScene(scene, 0, t0);
  return std::make_shared<const Simulator>(std::move(s.world), std::move(s.trajectory), sensor,
                                           physics, seed);
}

std::unique_ptr<navtech::RadarInput> makeSimInput(std::shared_ptr<const Simulator> sim,
                                                  SimInputOptions options) {
  return std::make_unique<SimRadarInput>(std::move(sim), options);
}

navtech::ScanSource simScanSource(std::shared_ptr<const Simulator> sim, int first_scan, bool loop) {
  auto k = std::make_shared<int>(first_scan);
  auto lap = std::make_shared<int>(0);
  return [sim, k, lap, loop](PolarScan& out) {
    const int count = sim->scanCount();
    if (*k >= count) {
      if (!loop || count == 0) return false;
      *k = 0;
      ++*lap;
    }
    out = sim->renderScan((*k)++);
    if (*lap > 0) {
      const int64_t shift =
          int64_t(std::llround(double(count) / sim->sensor().rotation_hz * 1e9)) * *lap;
      for (auto& t : out.stamp_ns) t += shift;
    }
    return true;
  };
}

}  // namespace spinradar::sim
