#include "scan_bag.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <stdexcept>

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <spinradar/RadarScan.h>

#include "spinradar/io/scan_io.hpp"
#include "spinradar_ros/polar_scan_conversions.hpp"

namespace spinradar::bag {

namespace {

constexpr const char* kScanType = "spinradar/RadarScan";

int64_t firstValidStamp(const PolarScan& s) {
  for (int a = 0; a < s.azimuths; ++a)
    if (s.valid.empty() || s.valid[a]) return s.stamp_ns[a];
  return s.firstStamp();
}

ros::Time rosTime(int64_t ns, const std::string& what) {
  if (ns <= 0) throw std::runtime_error(what + ": scan stamp " + std::to_string(ns) +
                                        " ns is not a valid ROS time");
  ros::Time t;
  t.fromNSec(static_cast<uint64_t>(ns));
  return t;
}

}  // namespace

size_t folderToBag(const ScanFolder& folder, const std::string& bag_path,
                   const ScanBagOptions& options, const BagProgress& progress) {
  if (folder.empty()) throw std::runtime_error(folder.folder() + ": no scans found");
  rosbag::Bag bag;
  try {
    bag.open(bag_path, rosbag::bagmode::Write);
  } catch (const rosbag::BagException& e) {
    throw std::runtime_error(bag_path + ": cannot create the bag: " + e.what());
  }
  spinradar::RadarScan msg;
  size_t n = 0;
  for (size_t i = 0; i < folder.size(); ++i) {
    const PolarScan scan = folder.load(i);
    spinradar_ros::toMsg(scan, options.frame_id, static_cast<float>(options.rotation_hz), msg);
    msg.header.seq = static_cast<uint32_t>(i);
    msg.sequence = i;
    const ros::Time t = rosTime(firstValidStamp(scan), folder.path(i));
    msg.header.stamp = t;
    try {
      bag.write(options.topic, t, msg);
    } catch (const rosbag::BagException& e) {
      throw std::runtime_error(bag_path + ": write failed at " + folder.path(i) + ": " + e.what());
    }
    ++n;
    if (progress) progress(n, folder.size());
  }
  bag.close();
  return n;
}

size_t bagToFolder(const std::string& bag_path, const std::string& out_dir,
                   const std::string& topic, const BagProgress& progress) {
  namespace fs = std::filesystem;
  rosbag::Bag bag;
  try {
    bag.open(bag_path, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    throw std::runtime_error(bag_path + ": cannot open the bag: " + e.what());
  }
  std::string chosen = topic;
  {
    rosbag::View all(bag);
    std::set<std::string> scan_topics;
    bool topic_seen = false;
    std::string topic_type;
    for (const rosbag::ConnectionInfo* c : all.getConnections()) {
      if (c->datatype == kScanType) scan_topics.insert(c->topic);
      if (c->topic == topic) {
        topic_seen = true;
        topic_type = c->datatype;
      }
    }
    std::string list;
    for (const auto& t : scan_topics) list += (list.empty() ? "" : ", ") + t;
    if (topic.empty()) {
      if (scan_topics.empty())
        throw std::runtime_error(bag_path + ": no " + std::string(kScanType) + " topic in the bag");
      if (scan_topics.size() > 1)
        throw std::runtime_error(bag_path + ": several " + std::string(kScanType) +
                                 " topics (" + list + "): choose one with --topic");
      chosen = *scan_topics.begin();
    } else if (!topic_seen) {
      throw std::runtime_error(bag_path + ": no topic '" + topic + "' (" + kScanType +
                               " topics: " + (list.empty() ? "none" : list) + ")");
    } else if (topic_type != kScanType) {
      throw std::runtime_error(bag_path + ": topic '" + topic + "' holds " + topic_type +
                               ", not " + kScanType);
    }
  }
  const fs::path radar_dir = fs::path(out_dir) / "radar";
  std::error_code ec;
  fs::create_directories(radar_dir, ec);
  if (ec) throw std::runtime_error(radar_dir.string() + ": cannot create: " + ec.message());
  const std::string ts_path = (fs::path(out_dir) / "radar.timestamps").string();
  std::ofstream stamps(ts_path);
  if (!stamps) throw std::runtime_error(ts_path + ": cannot open for writing");

  rosbag::View view(bag, rosbag::TopicQuery(std::vector<std::string>{chosen}));
  const size_t total = view.size();
  size_t n = 0;
  PolarScan scan;
  std::set<double> resolutions;
  for (const rosbag::MessageInstance& m : view) {
    auto msg = m.instantiate<spinradar::RadarScan>();
    if (!msg) continue;  // checked above: every message on the topic has the type
    const std::string where = bag_path + ": message " + std::to_string(n) + " on " + chosen;
    try {
      spinradar_ros::fromMsg(*msg, scan);
    } catch (const std::exception& e) {
      throw std::runtime_error(where + ": " + e.what());
    }
    resolutions.insert(scan.range_resolution);
    const long long us = scan.firstStamp() / 1000;
    const std::string png = (radar_dir / (std::to_string(us) + ".png")).string();
    saveOxfordPng(scan, png);
    stamps << us << " 1\n";
    ++n;
    if (progress) progress(n, total);
  }
  stamps.close();
  if (!stamps) throw std::runtime_error(ts_path + ": write failed");
  for (double r : resolutions)
    if (std::fabs(r - 0.0438) > 1e-9)
      std::fprintf(stderr,
                   "note: the scans have %.6g m range bins; the Oxford PNG layout does not store "
                   "it: read the folder with --range-resolution %.6g\n", r, r);
  return n;
}

}  // namespace spinradar::bag

extern "C" const spinradar::bag::BagApi* spinradar_bag_api() {
  static const spinradar::bag::BagApi api{&spinradar::bag::folderToBag, &spinradar::bag::bagToFolder};
  return &api;
}
