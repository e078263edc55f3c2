// `spinradar features`: how strong the descriptor registration is between scans 1..G apart on a
// simulated recording, against its trajectory.csv (diagnose/feature_repeatability.hpp).
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include "command.hpp"
#include "pipeline_options.hpp"
#include "recording_sensor.hpp"
#include "spinradar/diagnose/feature_repeatability.hpp"
#include "spinradar/io/scan_folder.hpp"

namespace {

struct FeaturesArgs {
  std::string input;
  std::string truth;  // default: <input>/trajectory.csv
  int scans = 400;
  spinradar::diagnose::RepeatabilityOptions options;
  spinradar::cli::PipelineOptions pipeline;
};

void run(const FeaturesArgs& a) {
  using namespace spinradar;
  namespace fs = std::filesystem;
  if (!fs::is_directory(a.input)) throw std::runtime_error(a.input + ": no such folder");
  const std::string truth = a.truth.empty() ? (fs::path(a.input) / "trajectory.csv").string() : a.truth;
  if (!fs::is_regular_file(truth))
    throw std::runtime_error(truth + ": no trajectory (a simulated recording's trajectory.csv; --truth)");
  const PipelineConfig cfg = a.pipeline.resolve();
  ScanFolderOptions opts;
  if (const auto recorded = cli::recordedSensor(a.input)) {
    opts.range_resolution = recorded->range_resolution;
    opts.range_offset = 0.0;  // ranges as recorded, as `odometry` reads them
  }
  const ScanFolder folder(a.input, ScanFormat::Auto, opts);
  if (folder.empty()) throw std::runtime_error(folder.folder() + ": no scans found");
  const sim::Trajectory trajectory = sim::Trajectory::loadCsv(truth);
  diagnose::RepeatabilityMeter meter(cfg, trajectory, a.options);
  PolarScan scan;
  for (size_t i = 0; i < folder.size() && static_cast<int>(i) < a.scans; ++i) {
    folder.load(i, scan);
    // The truth must cover the scan (Trajectory::at clamps: a scan outside it would count no
    // true match, silently). A tolerance of one scan period at either end.
    const double t0 = 1e-9 * static_cast<double>(scan.firstStamp()), t1 = 1e-9 * static_cast<double>(scan.lastStamp());
    if (t0 < trajectory.startTime() - 0.25 || t1 > trajectory.endTime() + 0.25)
      throw std::runtime_error(truth + ": covers " + std::to_string(trajectory.startTime()) + " .. " +
                               std::to_string(trajectory.endTime()) + " s, not scan " + std::to_string(i) + " (" +
                               folder.path(i) + ", " + std::to_string(t0) + " .. " + std::to_string(t1) +
                               " s): not this recording's truth, or a clock offset");
    meter.add(scan);
  }
  std::cout << a.input << ": " << diagnose::repeatabilityTable(meter.result(), a.options);
}

}  // namespace

SPINRADAR_COMMAND("features",
                  "Front-end strength against the truth of a simulated recording: keypoints, repeatable "
                  "keypoints, descriptor matches, true matches and RANSAC inliers between scans 1..G apart",
                  [](CLI::App& app) {
                    auto a = std::make_shared<FeaturesArgs>();
                    app.add_option("--input,-i", a->input, "Simulated recording (radar/, trajectory.csv)")
                        ->required();
                    app.add_option("--truth", a->truth, "Trajectory CSV t,x,y,yaw (default: <input>/trajectory.csv)");
                    app.add_option("--scans", a->scans, "Scans to read")->capture_default_str()->check(CLI::Range(2, 1000000));
                    app.add_option("--max-gap", a->options.max_gap, "Largest gap in scans (keyframe age)")
                        ->capture_default_str()
                        ->check(CLI::Range(1, 50));
                    app.add_option("--truth-radius", a->options.truth_radius,
                                   "Two keypoints are one return when the truth puts them this close (m)")
                        ->capture_default_str()
                        ->check(CLI::Range(0.01, 10.0));
                    app.add_option("--band-edges", a->options.band_edges,
                                   "Range band edges (m), increasing; the last band is beyond the last edge")
                        ->delimiter(',');
                    a->pipeline.add(app);
                    app.callback([a] { a->options.validate(); run(*a); });
                  });
