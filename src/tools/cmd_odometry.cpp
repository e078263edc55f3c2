// `spinradar odometry`: the whole chain over a folder of scans, poses to CSV.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <thread>

#include <tbb/global_control.h>

#include "cli_checks.hpp"
#include "command.hpp"
#include "huge_page_heap.hpp"
#include "output_guard.hpp"
#include "pipeline_options.hpp"
#include "progress.hpp"
#include "recording_sensor.hpp"
#include "scan_prefetcher.hpp"
#include "stage_tally.hpp"
#include "spinradar/estimation/odometry.hpp"
#include "spinradar/features/cartesian_tables.hpp"
#include "spinradar/features/feature_extractor.hpp"
#include "spinradar/io/poses_io.hpp"
#include "spinradar/io/scan_folder.hpp"

namespace {

using namespace spinradar;
using cli::ScanPrefetcher;
using cli::threadCpuMs;

struct OdometryArgs {
  std::string input, out, format = "auto", cov_out, tum_out;
  double range_resolution = 0.0;
  int threads = 1;
  bool quiet = false;
  cli::PipelineOptions pipeline;
};

void run(OdometryArgs& a) {
  namespace fs = std::filesystem;
  cli::preferHugePageHeap();  // before the scans' buffers and the loader threads
  if (!fs::exists(a.input)) throw std::runtime_error(a.input + ": no such folder");
  if (!fs::is_directory(a.input)) throw std::runtime_error(a.input + ": not a folder");
  const PipelineConfig cfg = a.pipeline.resolve();

  ScanFolderOptions opts;
  const std::optional<cli::RecordedSensor> recorded = cli::recordedSensor(a.input);
  if (a.range_resolution > 0) {
    opts.range_resolution = a.range_resolution;
  } else if (recorded) {
    opts.range_resolution = recorded->range_resolution;
    std::fprintf(stderr, "odometry: range bins of %.6g m from %s\n", recorded->range_resolution,
                 recorded->path.c_str());
  }
  // A recording with sensor.json (simulated, or replayed from a capture) holds the ranges the
  // sensor gave: no dataset range offset. Boreas' -0.31 m went onto simulated 3360- and
  // 6848-bin scans (read as the Boreas layout) and walked the keyframe heading on straights
  // (city route, MulRan / Boreas-RT sensor models: 1.67 / 3.60 % drift against 0.63 / 1.18 %).
  if (recorded) {
    opts.range_offset = 0.0;
    std::fprintf(stderr, "odometry: ranges as recorded (no dataset range offset): %s\n", recorded->path.c_str());
  }
  const ScanFolder folder(a.input, parseScanFormat(a.format), opts);
  if (folder.empty()) throw std::runtime_error(folder.folder() + ": no scans found");
  std::vector<NamedPath> inputs = cli::scanFolderInputs(folder, "--input");
  if (recorded) inputs.push_back({recorded->path, "--input"});
  inputs.push_back({a.pipeline.configPath(), "--config"});
  cli::refuseOutputsOverInputs(
      {{a.out, "--out"}, {a.tum_out, "--tum"}, {a.cov_out, "--covariance-out"}}, inputs);

  std::optional<tbb::global_control> limit;
  if (a.threads > 0)
    limit.emplace(tbb::global_control::max_allowed_parallelism, static_cast<size_t>(a.threads));
  std::fprintf(stderr, "odometry: %zu %s scans in %s, estimator %s\n", folder.size(),
               scanFormatName(folder.format()), folder.folder().c_str(),
               cfg.estimator.estimator.c_str());

  Odometry odometry(cfg);
  PoseCsvWriter writer(a.out);
  // Every output goes to a temporary file renamed when the run completes: a failed run
  // leaves nothing behind.
  std::optional<AtomicOutputFile> tum_file, cov_file;
  std::ostream* tum = nullptr;
  std::ostream* covp = nullptr;
  if (!a.tum_out.empty()) tum = &tum_file.emplace(a.tum_out).stream();
  if (!a.cov_out.empty()) covp = &cov_file.emplace(a.cov_out).stream();
  std::ostream& cov = covp ? *covp : std::cerr;
  if (covp) {
    cov.precision(17);  // full precision: `eval --covariance` matches its times to the poses'
    cov << "t,ok,pose_xx,pose_xy,pose_xyaw,pose_yy,pose_yyaw,pose_yawyaw,"
           "step_xx,step_xy,step_xyaw,step_yy,step_yyaw,step_yawyaw,"
           "vel_xx,vel_xy,vel_xw,vel_yy,vel_yw,vel_ww,"
           "key_t,key_x,key_y,key_yaw,key_xx,key_xy,key_xyaw,key_yy,key_yyaw,key_yawyaw\n";
  }
  // Upper triangle of a symmetric 3x3, row-major.
  auto writeCov = [&cov](const Eigen::Matrix3d& C) {
    cov << ',' << C(0, 0) << ',' << C(0, 1) << ',' << C(0, 2) << ',' << C(1, 1) << ','
        << C(1, 2) << ',' << C(2, 2);
  };
  cli::Progress progress("scan", folder.size());
  cli::StageTally tally(folder.size());
  double load_ms = 0;
  size_t failures = 0;
  const auto wall0 = std::chrono::steady_clock::now();
  // A scan that cannot be read is skipped with a warning naming it (a long recording is still
  // worth its other scans); the run stops when the first three all fail or none can be read.
  size_t skipped = 0, processed = 0;
  std::string first_error;
  // With more than one thread the next scans are read and their features extracted while this
  // one is matched and estimated.
  const bool prefetch = a.threads != 1;
  double wait_ms = 0;
  std::optional<ScanPrefetcher> prefetcher;
  if (prefetch) {  // the main thread (matching, estimation) and threads - 1 loaders
    const size_t threads = a.threads > 0 ? a.threads : std::max(2u, std::thread::hardware_concurrency());
    prefetcher.emplace(folder, 3, threads - 1, cfg);
  }
  ScanPrefetcher::Loaded single;  // one thread: every scan is loaded into this one, reused
  struct ReleaseSlot {  // hands the prefetcher's slot back at the end of each iteration
    ScanPrefetcher* p;
    ~ReleaseSlot() {
      if (p) p->release();
    }
  };
  OdometryResult r;  // reused: its inliers keep their buffer (no allocation per scan)
  for (size_t i = 0; i < folder.size(); ++i) {
    if (!prefetch) ScanPrefetcher::loadInto(folder, i, single);
    ScanPrefetcher::Loaded& l = prefetch ? prefetcher->take(wait_ms) : single;
    const ReleaseSlot release{prefetch ? &*prefetcher : nullptr};
    load_ms += l.load_ms;
    if (!l.error.empty()) {
      ++skipped;
      if (first_error.empty()) first_error = l.error;
      if (processed == 0 && skipped >= 3)
        throw std::runtime_error(first_error + " (and the next " + std::to_string(skipped - 1) +
                                 " scans fail too: wrong --format or not scans?)");
      if (skipped <= 10) std::fprintf(stderr, "\nwarning: %s: scan skipped\n", l.error.c_str());
      if (skipped == 10) std::fprintf(stderr, "warning: further skipped scans are only counted\n");
      continue;
    }
    ++processed;
    if (!l.extract_error.empty()) throw std::runtime_error(l.extract_error);
    if (prefetch)
      odometry.process(l.frame, l.times, r);
    else
      odometry.process(l.scan, r);
    tally.add(r.times);
    if (i > 0 && !r.ok) ++failures;
    PoseRecord p;
    p.t = r.stamp_ns * 1e-9;
    p.x = r.T_world_sensor(0, 2);
    p.y = r.T_world_sensor(1, 2);
    p.yaw = std::atan2(r.T_world_sensor(1, 0), r.T_world_sensor(0, 0));
    if (r.ok) {
      p.vx = r.motion.velocity(0);
      p.vy = r.motion.velocity(1);
      p.wz = r.motion.velocity(2);
    }
    writer.write(p);
    if (tum) writeTumRow(*tum, p);
    if (covp) {
      const Eigen::Matrix3d& K = r.T_keyframe_sensor;
      char t[64];
      std::snprintf(t, sizeof t, "%.9f", p.t);  // as the pose CSV writes its times
      cov << t << ',' << (r.ok ? 1 : 0);
      writeCov(r.pose_cov);
      writeCov(r.motion.T_12_cov);
      writeCov(r.motion.velocity_cov);
      std::snprintf(t, sizeof t, "%.9f", r.keyframe_stamp_ns * 1e-9);
      cov << ',' << t << ',' << K(0, 2) << ',' << K(1, 2) << ','
          << std::atan2(K(1, 0), K(0, 0));
      writeCov(r.keyframe_cov);
      cov << '\n';
    }
    if (!a.quiet)
      progress.update(i + 1, failures ? std::to_string(failures) + " failed estimate(s)" : "");
  }
  if (processed == 0) throw std::runtime_error(first_error + " (no scan could be read)");
  writer.close();
  if (tum_file) tum_file->commit();
  if (cov_file) cov_file->commit();
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  tally.print(load_ms, wait_ms, prefetch, folder.size(), wall);
  if (prefetch) {
    std::fprintf(stderr, "  thread CPU: main %.0f ms, loaders", threadCpuMs());
    for (double ms : prefetcher->workerCpuMs()) std::fprintf(stderr, " %.0f", ms);
    std::fprintf(stderr, " ms\n");
  }
  if (skipped)
    std::fprintf(stderr, "warning: skipped %zu of %zu scans that could not be read (first: %s)\n",
                 skipped, folder.size(), first_error.c_str());
  if (failures)
    std::fprintf(stderr, "warning: motion estimation failed on %zu of %zu scan pairs (pose held "
                         "as the odometry reported it)\n", failures, folder.size() - 1);
  std::fprintf(stderr, "wrote %s\n", a.out.c_str());
}

}  // namespace

SPINRADAR_COMMAND(
    "odometry", "Radar odometry over a folder of scans (Oxford, Boreas, MulRan, RADIATE)",
    [](CLI::App& app) {
      auto a = std::make_shared<OdometryArgs>();
      app.description(
          "Runs detector, descriptors, matching and the motion estimator over every scan of a "
          "folder and writes t,x,y,yaw,vx,vy,wz: the sensor pose at each scan's first-azimuth "
          "time t (s, scan clock) relative to the first scan, REP 103 (x forward, y left, yaw "
          "CCW), and the body velocity estimated to reach it.");
      app.add_option("--input,-i", a->input,
                     "Folder of scans, or a dataset root holding radar/ or Navtech_Polar/")
          ->required();
      app.add_option("--out,-o", a->out, "Output CSV")->required();
      app.add_option("--format", a->format, "Scan layout (default: guessed from the folder)")
          ->check(CLI::IsMember({"auto", "oxford", "boreas", "mulran", "radiate"}));
      app.add_option("--range-resolution", a->range_resolution,
                     "Metres per range bin (default: the recording's sensor.json if it has one, "
                     "else the format's own; Oxford 0.0438, the Oxford SDK uses 0.0432)")
          ->check(cli::positive());
      app.add_option("--threads", a->threads,
                     "Worker threads (TBB limit; N > 1: N - 1 threads read the next scans and "
                     "extract their features in the background while the main thread matches "
                     "and estimates, and extracts too when it would wait); 0 = all cores")
          ->check(cli::atLeast(0));
      app.add_flag("--quiet,-q", a->quiet, "No progress line");
      app.add_option("--tum", a->tum_out,
                     "Also write the poses in the TUM format (t x y z qx qy qz qw) that evo "
                     "(evo_ape, evo_rpe) and the TUM tools read");
      app.add_option("--covariance-out", a->cov_out,
                     "Also write each scan's covariances over [x, y, yaw] / [vx, vy, wz] (upper "
                     "triangles) to this CSV: accumulated pose (as published on ROS), the "
                     "frame-to-frame step (for keyframe: the refined pair's, its prior), body "
                     "velocity, and for --estimator keyframe the pose relative to its keyframe "
                     "(key_t: the keyframe's stamp, 0 for other estimators) with its covariance");
      a->pipeline.add(app);
      app.callback([a] { run(*a); });
    });
