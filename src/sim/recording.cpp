// writeRecording: an Oxford-layout recording folder of simulated scans plus the truth.
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <stdexcept>
#include <vector>

#include <tbb/parallel_for.h>

#include "spinradar/io/scan_io.hpp"
#include "spinradar/sim/simulator.hpp"

namespace spinradar::sim {

int writeRecording(const Simulator& sim, const std::string& dir, int first_scan, int n_scans,
                   bool progress) {
  namespace fs = std::filesystem;
  int total = sim.scanCount();
  if (first_scan < 0 || first_scan > total)
    throw std::out_of_range("writeRecording: first scan " + std::to_string(first_scan) +
                            " outside 0.." + std::to_string(total));
  int n = n_scans < 0 ? total - first_scan : std::min(n_scans, total - first_scan);
  std::error_code ec;
  fs::create_directories(fs::path(dir) / "radar", ec);
  if (ec) throw std::runtime_error(dir + ": cannot create folder: " + ec.message());

  std::vector<int64_t> stamps_us(size_t(std::max(n, 0)));
  std::atomic<int> done{0};
  std::mutex print_mutex;
  // Scans are independent: render and encode them in parallel, name files by first stamp.
  tbb::parallel_for(0, n, [&](int i) {
    PolarScan scan = sim.renderScan(first_scan + i);
    int64_t ns = scan.firstStamp();
    // Floor division so negative stamps (timestamp_offset) still name files consistently.
    int64_t us = ns >= 0 ? ns / 1000 : -((-ns + 999) / 1000);
    stamps_us[size_t(i)] = us;
    saveOxfordPng(scan, (fs::path(dir) / "radar" / (std::to_string(us) + ".png")).string());
    int d = ++done;
    if (progress && (d % 20 == 0 || d == n)) {
      std::lock_guard<std::mutex> lock(print_mutex);
      std::fprintf(stderr, "\rsimulate: %d / %d scans", d, n);
      if (d == n) std::fprintf(stderr, "\n");
    }
  });

  std::ofstream ts((fs::path(dir) / "radar.timestamps").string());
  if (!ts) throw std::runtime_error(dir + "/radar.timestamps: cannot write");
  for (int64_t us : stamps_us) ts << us << " 1\n";
  if (!ts) throw std::runtime_error(dir + "/radar.timestamps: write failed");
  sim.trajectory().saveCsv((fs::path(dir) / "trajectory.csv").string());
  sim.world().save((fs::path(dir) / "world.json").string());
  sim.physics().save((fs::path(dir) / "physics.json").string());
  sim.sensor().save((fs::path(dir) / "sensor.json").string());
  return n;
}

}  // namespace spinradar::sim
