#pragma once
// Scan folders <-> rosbags of spinradar/RadarScan messages. This header is ROS-free so the CLI
// can include it unconditionally; the implementation (library spinradar_bag) is built only
// when catkin is found, and the CLI defines SPINRADAR_HAVE_BAG when it links it.
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

}  // namespace spinradar::bag
