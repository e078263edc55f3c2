#include "spinradar_ros/polar_scan_conversions.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/core/mat.hpp>

#include "spinradar/io/scan_io.hpp"

namespace spinradar_ros {

namespace {

ros::Time stampOf(const spinradar::PolarScan& scan) {
  int64_t ns = scan.firstStamp();
  for (int a = 0; a < scan.azimuths && a < int(scan.valid.size()); ++a)
    if (scan.valid[a]) {
      ns = scan.stamp_ns[a];
      break;
    }
  ros::Time t;
  t.fromNSec(uint64_t(std::max<int64_t>(ns, 0)));
  return t;
}

void fillCommon(const spinradar::PolarScan& scan, const std::string& frame_id, float rotation_hz,
                spinradar::RadarScan& msg) {
  msg.header.frame_id = frame_id;
  msg.header.stamp = stampOf(scan);
  msg.range_resolution = scan.range_resolution;
  msg.range_offset = scan.range_offset;
  msg.azimuths = uint32_t(scan.azimuths);
  msg.bins = uint32_t(scan.bins);
  msg.encoder_size = uint16_t(scan.encoder_size);
  msg.rotation_hz = rotation_hz;
  msg.azimuth = scan.azimuth;
  msg.stamp_ns = scan.stamp_ns;
  msg.encoder = scan.encoder;
  msg.valid = scan.valid;
}

void check(size_t have, size_t want, const char* field) {
  if (have != want)
    throw std::runtime_error(std::string("RadarScan message: field '") + field + "' has " +
                             std::to_string(have) + " values, " + std::to_string(want) +
                             " expected");
}

}  // namespace

void toMsg(const spinradar::PolarScan& scan, const std::string& frame_id, float rotation_hz,
           spinradar::RadarScan& msg) {
  fillCommon(scan, frame_id, rotation_hz, msg);
  msg.bit_depth = 8;
  msg.data8 = scan.power;
  msg.data16.clear();
  int missing = 0;
  for (uint8_t v : scan.valid) missing += v == 0;
  msg.missing_azimuths = uint32_t(missing);
  msg.duplicated_azimuths = 0;
  msg.partial = false;
  msg.sequence = 0;
  msg.fft16_divisor = 0;
}

void toMsg(const spinradar::navtech::AssembledScan& s, const std::string& frame_id,
           float fft16_divisor, spinradar::RadarScan& msg) {
  fillCommon(s.scan, frame_id, float(s.config.rotationHz()), msg);
  if (s.bit_depth == 16 && s.power16.size() == s.scan.power.size()) {
    msg.bit_depth = 16;
    msg.data16 = s.power16;
    msg.data8.clear();
  } else {
    msg.bit_depth = 8;
    msg.data8 = s.scan.power;
    msg.data16.clear();
  }
  msg.missing_azimuths = uint32_t(s.missing);
  msg.duplicated_azimuths = uint32_t(s.duplicated);
  msg.partial = s.partial;
  msg.sequence = s.sequence;
  msg.fft16_divisor = fft16_divisor;
}

void fromMsg(const spinradar::RadarScan& msg, spinradar::PolarScan& scan) {
  const size_t n = msg.azimuths, cells = size_t(msg.azimuths) * msg.bins;
  check(msg.azimuth.size(), n, "azimuth");
  check(msg.stamp_ns.size(), n, "stamp_ns");
  check(msg.encoder.size(), n, "encoder");
  check(msg.valid.size(), n, "valid");
  scan.azimuths = int(msg.azimuths);
  scan.bins = int(msg.bins);
  scan.range_resolution = msg.range_resolution;
  scan.range_offset = msg.range_offset;
  scan.encoder_size = msg.encoder_size;
  scan.azimuth = msg.azimuth;
  scan.stamp_ns = msg.stamp_ns;
  scan.encoder = msg.encoder;
  scan.valid = msg.valid;
  scan.chirp_up.clear();
  if (msg.bit_depth == 16) {
    check(msg.data16.size(), cells, "data16");
    const double k = 1.0 / (msg.fft16_divisor > 0 ? msg.fft16_divisor : 256.0);
    scan.power.resize(cells);
    for (size_t i = 0; i < cells; ++i)
      scan.power[i] = uint8_t(std::min(255.0, std::floor(msg.data16[i] * k + 0.5)));
  } else {
    check(msg.data8.size(), cells, "data8");
    scan.power = msg.data8;
  }
}

void toOxfordImage(const spinradar::PolarScan& scan, const std_msgs::Header& header,
                   sensor_msgs::Image& image) {
  image.header = header;
  image.height = uint32_t(scan.azimuths);
  image.width = uint32_t(scan.bins + spinradar::kNavtechMetaColumns);
  image.encoding = "mono8";
  image.is_bigendian = 0;
  image.step = image.width;
  image.data.resize(size_t(image.height) * image.step);
  // Encode in place: the Mat wraps the message's buffer, so create() inside keeps it.
  cv::Mat view(int(image.height), int(image.width), CV_8UC1, image.data.data(), image.step);
  spinradar::encodeOxfordImage(scan, view);
}

void fromOxfordImage(const sensor_msgs::Image& image, spinradar::PolarScan& scan,
                     double range_resolution, double range_offset) {
  if (image.encoding != "mono8" && image.encoding != "8UC1")
    throw std::runtime_error("Oxford polar image: encoding '" + image.encoding +
                             "', mono8 expected");
  if (image.width <= uint32_t(spinradar::kNavtechMetaColumns) || image.height == 0 ||
      image.step < image.width || image.data.size() < size_t(image.step) * image.height)
    throw std::runtime_error("Oxford polar image: " + std::to_string(image.width) + " x " +
                             std::to_string(image.height) + " with " +
                             std::to_string(image.data.size()) + " bytes is not a valid layout");
  const cv::Mat view(int(image.height), int(image.width), CV_8UC1,
                     const_cast<uint8_t*>(image.data.data()), image.step);
  scan = spinradar::decodeOxfordImage(view, "Oxford polar image", range_resolution, range_offset);
}

}  // namespace spinradar_ros
