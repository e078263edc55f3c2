#pragma once
// Scan folders <-> rosbags of spinradar/RadarScan messages. This header is ROS-free so the CLI
// can include it unconditionally; the implementation (library spinradar_bag) is built only
// when catkin is found, and the CLI defines SPINRADAR_HAVE_BAG when it is there. The CLI does
// not link it: it loads it with dlopen the first time a bag is read or written
// (src/tools/bag_loader.cpp), because linking ROS cost every `spinradar` process about 50 ms of
// CPU and 13 MB at start-up (1.3 ms per scan on a 40-scan drive).
#include <cstddef>
#include <functional>
#include <string>

#include "spinradar/io/scan_folder.hpp"

namespace spinradar::bag {

struct ScanBagOptions {
  std::string topic = "/radar/scan";
  std::string frame_id = "radar";
  double rotation_hz = 4.0;  ///< written into the messages (configured rotation rate)
};

/// Called after each scan: (done, total).
using BagProgress = std::function<void(size_t, size_t)>;

/// Writes every scan of `folder` as one RadarScan message on `options.topic`, stamped (bag
/// time and header) with the scan's first valid azimuth. Returns the number of messages.
/// Throws std::runtime_error naming the bag or the scan file on failure.
size_t folderToBag(const ScanFolder& folder, const std::string& bag_path,
                   const ScanBagOptions& options = {}, const BagProgress& progress = {});

/// Reads RadarScan messages from `topic` (empty: the bag's only RadarScan topic) and writes
/// them to `out_dir` in the Oxford layout: out_dir/radar/<first-azimuth stamp us>.png plus
/// out_dir/radar.timestamps. The PNG layout carries no range resolution: when the messages'
/// differs from 0.0438 m it is reported on stderr (pass --range-resolution when reading).
/// Returns the number of scans written.
size_t bagToFolder(const std::string& bag_path, const std::string& out_dir,
                   const std::string& topic = {}, const BagProgress& progress = {});

/// The functions above as the library exports them to a program that loads it at run time:
/// extern "C" spinradar_bag_api() returns this table.
struct BagApi {
  size_t (*folder_to_bag)(const ScanFolder&, const std::string&, const ScanBagOptions&, const BagProgress&);
  size_t (*bag_to_folder)(const std::string&, const std::string&, const std::string&, const BagProgress&);
};

}  // namespace spinradar::bag

extern "C" const spinradar::bag::BagApi* spinradar_bag_api();
