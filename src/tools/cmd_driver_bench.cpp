// `spinradar driver-bench`: CPU cost and latency of the Navtech driver against the sensor
// emulator on loopback, at real rate and multiples. Full-size CIR204-H rotations (400 x 3768,
// 1600 azimuth messages a second at 1x). Driver CPU is the poll thread's own CPU time
// (CLOCK_THREAD_CPUTIME_ID); latency is from the receipt of the bytes completing a rotation's
// last azimuth to the assembled scan being handed to the caller.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <iostream>
#include <sstream>

#include "cli_checks.hpp"
#include "command.hpp"
#include "spinradar/driver/navtech_driver.hpp"
#include "spinradar/driver/navtech_server.hpp"

namespace {

using namespace spinradar;
using namespace spinradar::navtech;

double threadCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + ts.tv_nsec * 1e-9;
}
double processCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/// Four pre-made rotations with speckle-like content, cycled with increasing stamps, so the
/// emulator costs little and the figures are the driver's.
ScanSource benchSource(int azimuths, int bins) {
  auto scans = std::make_shared<std::vector<PolarScan>>(4);
  uint64_t rng = 12345;
  for (auto& s : *scans) {
    s.resize(azimuths, bins);
    for (int a = 0; a < azimuths; ++a) s.encoder[a] = uint16_t(int64_t(a) * 5600 / azimuths);
    for (auto& p : s.power) {
      rng = rng * 6364136223846793005ull + 1442695040888963407ull;
      p = uint8_t((rng >> 59) + ((rng >> 40) % 97 == 0 ? 80 : 0));
    }
  }
  auto k = std::make_shared<int64_t>(0);
  return [=](PolarScan& out) {
    out = (*scans)[size_t(*k % 4)];
    for (int a = 0; a < azimuths; ++a)
      out.stamp_ns[a] = (*k * azimuths + a) * 250'000'000 / azimuths;
    ++*k;
    return true;
  };
}

void bench(const std::vector<double>& rates, double seconds, int azimuths, int bins, int depth) {
  std::printf("%d-bit FFT data, %d x %d\n\n", depth, azimuths, bins);
  std::printf("| rate | azimuths/s | scans | driver CPU (%% of a core) | process CPU (%%) | latency median / p99 / max (ms) | missing azimuths |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  for (double rate : rates) {
    ServerOptions so;
    so.rate = rate;
    so.bit_depth = depth;
    so.log = [](LogLevel, const std::string&) {};
    NavtechServer server(so, benchSource(azimuths, bins));
    server.start();
    DriverConfig c;
    c.port = server.port();
    NavtechDriver d(c);
    d.setLog([](LogLevel, const std::string&) {});
    AssembledScan s;
    // Warm up: connect and get the first scan so buffers exist.
    for (int i = 0; i < 50 && d.poll(s, std::chrono::milliseconds(200)) != InputStatus::Ok; ++i) {
    }
    const uint64_t az0 = d.stats().azimuths, missing0 = d.stats().missing_azimuths;
    std::vector<double> latency_ms;
    const double cpu0 = threadCpuSeconds(), pcpu0 = processCpuSeconds();
    const auto t0 = std::chrono::steady_clock::now();
    const auto end = t0 + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      if (d.poll(s, std::chrono::milliseconds(200)) == InputStatus::Ok)
        latency_ms.push_back((wallClockNs() - s.last_receive_ns) * 1e-6);
    }
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double cpu = threadCpuSeconds() - cpu0, pcpu = processCpuSeconds() - pcpu0;
    const DriverStats st = d.stats();
    server.stop();
    std::sort(latency_ms.begin(), latency_ms.end());
    auto pct = [&](double q) {
      return latency_ms.empty() ? 0.0 : latency_ms[size_t(q * (latency_ms.size() - 1))];
    };
    std::printf("| %gx | %.0f | %zu | %.1f | %.1f | %.3f / %.3f / %.3f | %llu |\n", rate,
                double(st.azimuths - az0) / wall, latency_ms.size(), 100 * cpu / wall,
                100 * pcpu / wall, pct(0.5), pct(0.99), latency_ms.empty() ? 0.0 : latency_ms.back(),
                (unsigned long long)(st.missing_azimuths - missing0));
    std::fflush(stdout);
  }
}

}  // namespace

SPINRADAR_COMMAND("driver-bench", "Measure the Navtech driver's CPU use and latency against the emulator on loopback",
                  [](CLI::App& app) {
                    auto rates = std::make_shared<std::vector<double>>(std::vector<double>{1.0, 10.0});
                    auto seconds = std::make_shared<double>(5.0);
                    auto azimuths = std::make_shared<int>(400);
                    auto bins = std::make_shared<int>(3768);
                    auto depth = std::make_shared<int>(8);
                    app.add_option("--rates", *rates, "Multiples of real time to measure")->capture_default_str()->check(spinradar::cli::positive());
                    app.add_option("--seconds", *seconds, "Measurement time per rate")->capture_default_str()->check(spinradar::cli::positive());
                    app.add_option("--azimuths", *azimuths, "Azimuths per rotation")->capture_default_str()->check(spinradar::cli::inRange(16, 20000));
                    app.add_option("--bins", *bins, "Range bins per azimuth")->capture_default_str()->check(spinradar::cli::inRange(16, 65536));
                    app.add_option("--bit-depth", *depth, "FFT data: 8 (type 30) or 16 (type 31)")
                        ->check(CLI::IsMember({8, 16}))
                        ->capture_default_str();
                    app.callback([=] { bench(*rates, *seconds, *azimuths, *bins, *depth); });
                  });
