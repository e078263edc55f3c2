// `spinradar bag`: scan folder -> rosbag of spinradar/RadarScan messages, and back.
#include <cstdio>
#include <filesystem>
#include <memory>

#include "cli_checks.hpp"
#include "command.hpp"
#include "output_guard.hpp"
#include "progress.hpp"
#include "scan_bag.hpp"

namespace {

using namespace spinradar;

struct BagArgs {
  std::string input, out, topic, frame_id = "radar", format = "auto";
  double range_resolution = 0.0, rotation_hz = 4.0;
  bool force = false;
};

void run(const BagArgs& a) {
  namespace fs = std::filesystem;
  if (!fs::exists(a.input)) throw std::runtime_error(a.input + ": no such file or folder");
#ifdef SPINRADAR_HAVE_BAG
  std::unique_ptr<cli::Progress> progress;
  auto report = [&progress](size_t done, size_t total) {
    if (!progress) progress = std::make_unique<cli::Progress>("scan", total);
    progress->update(done);
  };
  if (fs::is_directory(a.input)) {
    ScanFolderOptions opts;
    if (a.range_resolution > 0) opts.range_resolution = a.range_resolution;
    const ScanFolder folder(a.input, parseScanFormat(a.format), opts);
    cli::refuseOutputsOverInputs({{a.out, "--out"}}, cli::scanFolderInputs(folder, "--input"));
    bag::ScanBagOptions o;
    if (!a.topic.empty()) o.topic = a.topic;
    o.frame_id = a.frame_id;
    o.rotation_hz = a.rotation_hz;
    AtomicOutputFile file(a.out);  // renamed onto --out when complete
    const size_t n = bag::folderToBag(folder, file.tempPath(), o, report);
    file.commit();
    std::fprintf(stderr, "wrote %zu %s scans from %s to %s on %s\n", n,
                 scanFormatName(folder.format()), folder.folder().c_str(), a.out.c_str(),
                 o.topic.c_str());
  } else {
    refuseOutputOverInput({a.out, "--out"}, {{a.input, "--input"}}, true);
    AtomicOutputFolder folder(a.out, a.force);  // moved into place when complete
    const size_t n = bag::bagToFolder(a.input, folder.tempPath(), a.topic, report);
    if (n == 0) throw std::runtime_error(a.input + ": no RadarScan messages; nothing written");
    folder.commit();
    std::fprintf(stderr, "wrote %zu scans to %s/radar (Oxford layout)\n", n, a.out.c_str());
  }
#else
  throw std::runtime_error("this spinradar was built without ROS (catkin/rosbag not found): "
                           "`spinradar bag` is unavailable");
#endif
}

}  // namespace

SPINRADAR_COMMAND("bag", "Convert a scan folder to a rosbag of RadarScan messages, and back",
                  [](CLI::App& app) {
                    auto a = std::make_shared<BagArgs>();
                    app.description(
                        "--input FOLDER --out scans.bag writes one spinradar/RadarScan message "
                        "per scan (stamped with its first valid azimuth); --input scans.bag "
                        "--out FOLDER writes the messages as Oxford-layout PNGs "
                        "(FOLDER/radar/<stamp us>.png + radar.timestamps).");
                    app.add_option("--input,-i", a->input, "Scan folder or bag")->required();
                    app.add_option("--out,-o", a->out, "Bag or folder to write")->required();
                    app.add_option("--topic", a->topic,
                                   "Topic (writing: default /radar/scan; reading: default the "
                                   "bag's only RadarScan topic)");
                    app.add_option("--frame-id", a->frame_id, "header.frame_id when writing");
                    app.add_option("--format", a->format, "Layout of an input folder")
                        ->check(CLI::IsMember({"auto", "oxford", "boreas", "mulran", "radiate"}));
                    app.add_option("--range-resolution", a->range_resolution,
                                   "Metres per bin of an input folder (default: the format's)")
                        ->check(cli::positive());
                    app.add_option("--rotation-hz", a->rotation_hz,
                                   "Rotation rate written into the messages")
                        ->check(cli::positive());
                    app.add_flag("--force", a->force,
                                 "Bag to folder: write into a non-empty --out folder (its old "
                                 "scans are removed first)");
                    app.callback([a] { run(*a); });
                  });
