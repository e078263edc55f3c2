// `spinradar bench`: per-stage timings and peak memory on a full-size scan pair.
#include <dlfcn.h>
#include <sys/resource.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <tbb/global_control.h>

#include "cli_checks.hpp"
#include "command.hpp"
#include "pipeline_options.hpp"
#include "sorted_quantile.hpp"
#include "spinradar/features/feature_extractor.hpp"
#include "spinradar/features/matcher.hpp"
#include "spinradar/estimation/odometry.hpp"
#include "spinradar/io/png_gray8.hpp"
#include "spinradar/io/png_io.hpp"
#include "spinradar/io/scan_folder.hpp"
#include "spinradar/io/scan_io.hpp"
#ifdef SPINRADAR_HAVE_SIM
#include "spinradar/sim/scenes.hpp"
#include "spinradar/sim/simulator.hpp"
#define SPINRADAR_BENCH_SIM 1
#endif

namespace {

using namespace spinradar;
using Clock = std::chrono::steady_clock;

struct BenchArgs {
  std::string input, format = "auto", scene = "city";
  int first = 0, runs = 50, warmup = 3, threads = 1;
  double sim_time = 20.0;
  cli::PipelineOptions pipeline;
};

double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

/// Process CPU time, ms: unlike wall time it does not grow when other processes take the
/// cores, so it is the steadier figure on a shared machine (equal to wall time for one thread).
double cpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

struct Stats {
  double median = 0, p10 = 0, p90 = 0, mean = 0;
};

Stats stats(std::vector<double> v) {
  Stats s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  s.median = v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  s.p10 = cli::quantileOfSorted(v, 0.1);
  s.p90 = cli::quantileOfSorted(v, 0.9);
  for (double x : v) s.mean += x;
  s.mean /= v.size();
  return s;
}

/// kB from /proc/self/status ("VmHWM" = peak resident set, "VmRSS" = current).
long procStatusKb(const char* key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  const std::string k = std::string(key) + ":";
  while (std::getline(in, line))
    if (line.compare(0, k.size(), k) == 0) return std::stol(line.substr(k.size()));
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return ru.ru_maxrss;
}

std::pair<PolarScan, PolarScan> scanPair(const BenchArgs& a, std::string& source) {
  if (!a.input.empty()) {
    const ScanFolder folder(a.input, parseScanFormat(a.format));
    if (folder.size() < static_cast<size_t>(a.first) + 2)
      throw std::runtime_error(folder.folder() + ": needs at least " +
                               std::to_string(a.first + 2) + " scans for a pair from scan " +
                               std::to_string(a.first));
    source = folder.path(a.first) + " + next";
    return {folder.load(a.first), folder.load(a.first + 1)};
  }
#ifdef SPINRADAR_BENCH_SIM
  // Simulated full-size scans (sensor defaults: 400 x 3768) on a built-in scene, with motion
  // distortion and Doppler, a few seconds into the route so the sensor is moving.
  sim::Scene scene = sim::builtinScene(a.scene);
  sim::PhysicsConfig physics;
  physics.motion_distortion = true;
  physics.doppler = 0.049;
  sim::Simulator simulator(scene.world, scene.trajectory, sim::SensorConfig{}, physics, 1);
  const sim::SensorConfig sensor;
  const int k = std::min(static_cast<int>(a.sim_time * sensor.rotation_hz),
                         std::max(0, simulator.scanCount() - 2));
  source = "simulated scene '" + a.scene + "', scans " + std::to_string(k) + "-" + std::to_string(k + 1);
  return {simulator.renderScan(k), simulator.renderScan(k + 1)};
#else
  throw std::runtime_error("no simulator in this build: give --input DIR");
#endif
}

/// The pair's second scan as an Oxford-layout PNG: the file itself when --input holds PNGs, else
/// encoded in memory as saveOxfordPng writes it (zlib level 1, Sub filter).
std::vector<uint8_t> pairPng(const BenchArgs& a, const PolarScan& s2) {
  std::vector<uint8_t> bytes;
  if (!a.input.empty()) {
    const ScanFolder folder(a.input, parseScanFormat(a.format));
    const std::string& p = folder.path(a.first + 1);
    if (p.size() > 4 && p.compare(p.size() - 4, 4, ".png") == 0) {
      readFileBytes(p, bytes);
      return bytes;
    }
  }
  cv::Mat img;
  encodeOxfordImage(s2, img);
  encodePng(img, bytes, 1);
  return bytes;
}

/// OpenCV's cv::imdecode, loaded at run time (not linked: see io/png_io.hpp); null if absent.
using Imdecode = cv::Mat (*)(const cv::_InputArray&, int);
Imdecode openCvImdecode() {
  void* lib = dlopen(SPINRADAR_IMGCODECS_SO, RTLD_NOW | RTLD_LOCAL);
  return lib ? reinterpret_cast<Imdecode>(dlsym(lib, "_ZN2cv8imdecodeERKNS_11_InputArrayEi")) : nullptr;
}

/// Decode time of each PNG decoder on `png` (wall and CPU ms per image) and whether each gives
/// OpenCV's bytes.
struct DecodeTimes {
  std::vector<std::string> name;
  std::vector<std::vector<double>> ms, cpu;
  std::vector<bool> exact;
};
DecodeTimes benchDecoders(const std::vector<uint8_t>& png, int warmup, int runs) {
  DecodeTimes out;
  const Imdecode imdecode = openCvImdecode();
  const cv::Mat wrapped(1, static_cast<int>(png.size()), CV_8UC1, const_cast<uint8_t*>(png.data()));
  cv::Mat ref;
  if (imdecode) ref = imdecode(wrapped, -1 /* cv::IMREAD_UNCHANGED */);
  PngGray8Decoder spng(PngDecoder::Spng), deflate(PngDecoder::Deflate);
  const std::vector<std::pair<std::string, std::function<bool(cv::Mat&)>>> decoders = {
      {"OpenCV imdecode", [&](cv::Mat& m) { return imdecode && !(m = imdecode(wrapped, -1)).empty(); }},
      {pngDecoderName(PngDecoder::Spng), [&](cv::Mat& m) { return spng.decode(png.data(), png.size(), m); }},
      {"libdeflate (used)", [&](cv::Mat& m) { return deflate.decode(png.data(), png.size(), m); }}};
  for (const auto& [name, decode] : decoders) {
    std::vector<double> t, c;
    cv::Mat img;
    bool ok = true;
    for (int i = 0; i < warmup + runs; ++i) {
      const auto t0 = Clock::now();
      const double c0 = cpuMs();
      ok &= decode(img);
      if (i >= warmup) {
        t.push_back(msSince(t0));
        c.push_back(cpuMs() - c0);
      }
    }
    ok &= !ref.empty() && img.size() == ref.size() && img.type() == ref.type() && cv::norm(img, ref, cv::NORM_INF) == 0;
    out.name.push_back(name);
    out.ms.push_back(std::move(t));
    out.cpu.push_back(std::move(c));
    out.exact.push_back(ok);
  }
  return out;
}

void run(BenchArgs& a) {
  std::optional<tbb::global_control> limit;
  if (a.threads > 0)
    limit.emplace(tbb::global_control::max_allowed_parallelism, static_cast<size_t>(a.threads));
  const PipelineConfig cfg = a.pipeline.resolve();
  std::string source;
  const long rss0 = procStatusKb("VmRSS");
  auto [s1, s2] = scanPair(a, source);
  std::printf("bench: %s, %d x %d, %d runs (+%d warm-up), %d thread(s)\n", source.c_str(),
              s2.azimuths, s2.bins, a.runs, a.warmup, a.threads);

  FeatureExtractor fx(cfg.detector, cfg.features);
  FeatureFrame f1, f2;
  std::vector<Match> matches;
  std::vector<double> detect, cart, describe, extract, match, chain, chain_wall;
  std::vector<double> extract_cpu, match_cpu, chain_cpu;
  std::map<std::string, std::vector<double>> estimate;
  std::map<std::string, int> inliers;
  const std::vector<std::string> estimators = {"rigid", "mc", "mc_doppler"};
  std::map<std::string, std::unique_ptr<Odometry>> odos;
  for (const auto& e : estimators) {
    PipelineConfig c = cfg;
    c.estimator.estimator = e;
    odos[e] = std::make_unique<Odometry>(c);
  }
  Odometry whole(cfg);
  fx.extract(s1, f1);
  for (int i = 0; i < a.warmup + a.runs; ++i) {
    const bool keep = i >= a.warmup;
    StageTimes t;
    auto t0 = Clock::now();
    double c0 = cpuMs();
    fx.extract(s2, f2, &t);
    const double ext = msSince(t0), ext_cpu = cpuMs() - c0;
    t0 = Clock::now();
    c0 = cpuMs();
    matchDescriptors(f1.descriptors, f2.descriptors, cfg.features.nndr, matches);
    const double m = msSince(t0), m_cpu = cpuMs() - c0;
    for (const auto& e : estimators) {
      Odometry& o = *odos[e];
      o.reset();
      o.process(f1);
      const OdometryResult r = o.process(f2);
      if (keep) {
        estimate[e].push_back(r.times.estimate_ms);
        inliers[e] = static_cast<int>(r.motion.inliers.size());
      }
    }
    whole.reset();
    whole.process(s1);
    t0 = Clock::now();
    c0 = cpuMs();
    const OdometryResult r = whole.process(s2);
    const double w = msSince(t0), w_cpu = cpuMs() - c0;
    if (!keep) continue;
    detect.push_back(t.detect_ms);
    cart.push_back(t.cartesian_ms);
    describe.push_back(t.describe_ms);
    extract.push_back(ext);
    extract_cpu.push_back(ext_cpu);
    match.push_back(m);
    match_cpu.push_back(m_cpu);
    chain_cpu.push_back(w_cpu);
    chain.push_back(r.times.total());
    chain_wall.push_back(w);
  }
  const long hwm = procStatusKb("VmHWM");

  std::printf("keypoints %zu / %zu, matches %zu, inliers rigid %d, mc %d, mc_doppler %d\n",
              f1.keypoints.size(), f2.keypoints.size(), matches.size(), inliers["rigid"],
              inliers["mc"], inliers["mc_doppler"]);
  std::printf("%-34s %9s %9s %9s %9s   %s\n", "stage (per scan)", "median", "p10", "p90",
              "cpu med", "paper (4-core 3 GHz Xeon)");
  auto row = [](const std::string& name, const std::vector<double>& v,
                const std::vector<double>& cpu, const char* paper) {
    const Stats s = stats(v);
    char c[32] = "        -";
    if (!cpu.empty()) std::snprintf(c, sizeof c, "%6.2f ms", stats(cpu).median);
    std::printf("%-34s %6.2f ms %6.2f ms %6.2f ms %s   %s\n", name.c_str(), s.median, s.p10,
                s.p90, c, paper);
  };
  const std::vector<uint8_t> png = pairPng(a, s2);
  const DecodeTimes dt = benchDecoders(png, a.warmup, a.runs);
  for (size_t k = 0; k < dt.ms.size(); ++k)
    row("PNG decode, " + dt.name[k], dt.ms[k], dt.cpu[k],
        dt.exact[k] ? "bytes = OpenCV's" : "DIFFERS from OpenCV (or OpenCV not found)");
  row("detector (Cen2018)", detect, {}, "~35 ms");
  row("Cartesian image", cart, {}, "");
  row("descriptors (ORB)", describe, {}, "~5 ms");
  row("features total", extract, extract_cpu, "");
  row(std::string("matching (") + matchKernelName(matchKernelUsed()) + ")", match, match_cpu, "~15 ms");
  for (const MatchKernel k : {MatchKernel::Avx512, MatchKernel::Avx2, MatchKernel::Scalar}) {
    std::vector<double> t, c;  // each kernel alone; all give the same matches (tested)
    std::vector<Match> km;
    bool have = true, same = true;
    for (int i = 0; i < a.warmup + a.runs && have; ++i) {
      const auto t0 = Clock::now();
      const double c0 = cpuMs();
      have = matchDescriptorsWith(k, f1.descriptors, f2.descriptors, cfg.features.nndr, km);
      if (i >= a.warmup) t.push_back(msSince(t0)), c.push_back(cpuMs() - c0);
    }
    if (!have) {
      std::printf("  matching, %-23s not on this CPU\n", matchKernelName(k));
      continue;
    }
    for (size_t j = 0; j < km.size() && same; ++j)
      same = km.size() == matches.size() && km[j].i1 == matches[j].i1 && km[j].i2 == matches[j].i2;
    row(std::string("  matching, ") + matchKernelName(k), t, c,
        same && km.size() == matches.size() ? "same matches" : "DIFFERENT matches");
  }
  row("rigid RANSAC", estimate["rigid"], {}, "1-2 ms");
  row("MC-RANSAC", estimate["mc"], {}, "20-50 ms");
  row("MC-RANSAC + Doppler", estimate["mc_doppler"], {}, "");
  row("whole chain (" + cfg.estimator.estimator + ", stage sum)", chain, {}, "");
  row("whole chain (" + cfg.estimator.estimator + ")", chain_wall, chain_cpu,
      "target < 15 ms on one core (issue 21: < 5 ms CPU, real Oxford)");
  std::printf("wall-clock columns include waiting for the CPU when other processes run; "
              "'cpu med' is this process's CPU time\n");
  std::printf("peak resident memory %.1f MB (%.1f MB before loading the scans)\n", hwm / 1024.0,
              rss0 / 1024.0);
}

}  // namespace

SPINRADAR_COMMAND(
    "bench", "Per-stage timings and peak memory on a full-size scan pair", [](CLI::App& app) {
      auto a = std::make_shared<BenchArgs>();
      app.description(
          "Times each stage (detector, Cartesian image, ORB descriptors, matching, rigid "
          "RANSAC, MC-RANSAC, MC-RANSAC + Doppler, the whole chain) on one scan pair, repeated, "
          "and prints medians and peak memory. The pair is simulated (full-size 400 x 3768) "
          "unless --input gives a folder. Wall-clock figures: other load on the machine "
          "shows up in them.");
      app.add_option("--input,-i", a->input, "Folder of scans (default: simulate a pair)");
      app.add_option("--format", a->format, "Scan layout of --input (default: guessed)")
          ->check(CLI::IsMember({"auto", "oxford", "boreas", "mulran", "radiate"}));
      app.add_option("--first", a->first, "Index of the pair's first scan in --input")
          ->check(cli::atLeast(0));
      app.add_option("--scene", a->scene, "Built-in scene to simulate (default city)");
      app.add_option("--sim-time", a->sim_time, "Simulated pair starts this far into the route, s")
          ->check(cli::atLeast(0));
      app.add_option("--runs", a->runs, "Timed repetitions")->check(cli::atLeast(1));
      app.add_option("--warmup", a->warmup, "Untimed repetitions first")
          ->check(cli::atLeast(0));
      app.add_option("--threads", a->threads, "TBB thread limit (default 1: one core; 0 = all)")
          ->check(cli::atLeast(0));
      a->pipeline.add(app);
      app.callback([a] { run(*a); });
    });
