// Oxford Radar RobotCar and Boreas polar PNGs (the "Navtech rows" layout).
#include <algorithm>
#include <cstdint>
#include <cmath>
#include <cstring>
#include <iostream>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "spinradar/io/png_io.hpp"
#include "spinradar/io/scan_io.hpp"
#include "scan_io_detail.hpp"

namespace spinradar {

namespace {

std::mutex g_warn_mutex;
ScanWarningHandler g_warn_handler;

enum class Column10 { Valid, BoreasAuto };

int64_t readI64(const uint8_t* p) {
  uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return static_cast<int64_t>(v);
}
uint16_t readU16(const uint8_t* p) { return static_cast<uint16_t>(p[0] | (p[1] << 8)); }
void writeI64(uint8_t* p, int64_t s) {
  uint64_t v = static_cast<uint64_t>(s);
  for (int i = 0; i < 8; ++i, v >>= 8) p[i] = static_cast<uint8_t>(v & 0xff);
}

/// Boreas-RT marks chirps by alternating column 10; accept it when nearly every row flips.
bool looksLikeChirpColumn(const cv::Mat& img) {
  if (img.rows < 4) return false;
  int flips = 0, mixed = 0;
  for (int a = 0; a < img.rows; ++a) {
    const uint8_t v = img.ptr<uint8_t>(a)[10];
    if (v != 0 && v != 255) ++mixed;
    if (a > 0 && v != img.ptr<uint8_t>(a - 1)[10]) ++flips;
  }
  return mixed == 0 && flips >= (img.rows - 1) * 9 / 10;
}

/// Fills `scan` from the image, reusing its buffers (no allocation once it held a scan of this size).
void decodeRows(const cv::Mat& img, const std::string& name, double resolution, double offset,
                Column10 col10, PolarScan& scan) {
  if (img.empty()) throw std::runtime_error(name + ": empty image");
  if (img.depth() != CV_8U || img.channels() != 1) {
    std::ostringstream s;
    s << name << ": " << img.channels() << " channel(s) of " << (img.elemSize1() * 8)
      << "-bit, an 8-bit single-channel image expected";
    throw std::runtime_error(s.str());
  }
  if (img.cols <= kNavtechMetaColumns) {
    std::ostringstream s;
    s << name << ": " << img.cols << " columns but " << kNavtechMetaColumns
      << " metadata columns + at least 1 bin expected";
    throw std::runtime_error(s.str());
  }
  scan.resizeForOverwrite(img.rows, img.cols - kNavtechMetaColumns);  // every row copied below
  scan.range_resolution = resolution;
  scan.range_offset = offset;
  scan.encoder_size = 5600;
  const bool chirp = col10 == Column10::BoreasAuto && looksLikeChirpColumn(img);
  if (chirp)
    scan.chirp_up.assign(img.rows, 0);
  else
    scan.chirp_up.clear();  // a reused scan may hold a previous file's
  const double two_pi = 2.0 * M_PI;
  for (int a = 0; a < img.rows; ++a) {
    const uint8_t* p = img.ptr<uint8_t>(a);
    const int64_t us = readI64(p);
    const uint16_t enc = readU16(p + 8);
    if (enc >= scan.encoder_size) {
      std::ostringstream s;
      s << name << ": row " << a << ": encoder " << enc << " >= " << scan.encoder_size;
      // On the first row this is most often another layout read as Oxford / Boreas (a RADIATE
      // image's first pixels are returns, not metadata).
      if (a == 0) s << " (not an Oxford / Boreas row: another format? --format radiate or mulran)";
      throw std::runtime_error(s.str());
    }
    if (us > INT64_MAX / 1000 || us < INT64_MIN / 1000) {  // ns would overflow int64
      std::ostringstream s;
      s << name << ": row " << a << ": stamp " << us << " us is out of range (more than 292 years)";
      throw std::runtime_error(s.str());
    }
    scan.stamp_ns[a] = us * 1000;
    scan.encoder[a] = enc;
    scan.azimuth[a] = two_pi * enc / scan.encoder_size;
    if (chirp) {
      scan.chirp_up[a] = p[10] == 255 ? 1 : 0;
      scan.valid[a] = 1;
    } else if (col10 == Column10::Valid) {
      scan.valid[a] = p[10] == 255 ? 1 : 0;  // as the Oxford SDK tests it
    } else {
      scan.valid[a] = 1;  // Boreas without chirps: column 10 carries no flag we rely on
    }
    std::memcpy(scan.row(a), p + kNavtechMetaColumns, scan.bins);
  }
  detail::markMissingAndDuplicates(scan, name);
}

/// The returned image points into this thread's decoder buffer: use it before the next call.
cv::Mat readGray(const std::string& path) { return readPngGray8(path); }

void writeScanPng(const cv::Mat& img, const std::string& path) {
  const auto dot = path.rfind('.');
  std::string ext = dot == std::string::npos ? "" : path.substr(dot);
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  if (ext != ".png")
    throw std::runtime_error(path + ": the polar layout needs a lossless .png file name");
  writePng(img, path, 1);
}

void encodeRows(const PolarScan& scan, cv::Mat& img, bool chirp_column) {
  if (scan.empty()) throw std::runtime_error("cannot encode an empty scan");
  if (scan.power.size() != static_cast<size_t>(scan.azimuths) * scan.bins)
    throw std::runtime_error("cannot encode scan: power has " + std::to_string(scan.power.size()) +
                             " values, azimuths x bins expected");
  img.create(scan.azimuths, scan.bins + kNavtechMetaColumns, CV_8UC1);
  // The layout has no field for the encoder size: it is always 5600. Other sensors' encoders are
  // rewritten from the angles so that the file still reads back with the right angles.
  const bool have_enc = scan.encoder.size() == static_cast<size_t>(scan.azimuths) && scan.encoder_size == 5600;
  for (int a = 0; a < scan.azimuths; ++a) {
    uint8_t* p = img.ptr<uint8_t>(a);
    const int64_t ns = a < static_cast<int>(scan.stamp_ns.size()) ? scan.stamp_ns[a] : 0;
    writeI64(p, ns / 1000);
    int enc = 0;
    if (have_enc) {
      enc = scan.encoder[a];
    } else if (a < static_cast<int>(scan.azimuth.size())) {
      const double turns = scan.azimuth[a] / (2.0 * M_PI);
      enc = static_cast<int>(std::lround((turns - std::floor(turns)) * 5600.0)) % 5600;
    }
    p[8] = static_cast<uint8_t>(enc & 0xff);
    p[9] = static_cast<uint8_t>((enc >> 8) & 0xff);
    const bool valid = a >= static_cast<int>(scan.valid.size()) || scan.valid[a] != 0;
    if (chirp_column && scan.chirp_up.size() == static_cast<size_t>(scan.azimuths))
      p[10] = scan.chirp_up[a] ? 255 : 0;
    else
      p[10] = valid ? 255 : 0;
    std::memcpy(p + kNavtechMetaColumns, scan.row(a), scan.bins);
  }
}

}  // namespace

void setScanWarningHandler(ScanWarningHandler handler) {
  std::lock_guard<std::mutex> lock(g_warn_mutex);
  g_warn_handler = std::move(handler);
}

void scanWarning(const std::string& message) {
  std::lock_guard<std::mutex> lock(g_warn_mutex);
  if (g_warn_handler)
    g_warn_handler(message);
  else
    std::cerr << "spinradar warning: " << message << "\n";
}

PolarScan decodeOxfordImage(const cv::Mat& image, const std::string& name,
                            double range_resolution, double range_offset) {
  PolarScan scan;
  decodeRows(image, name, range_resolution, range_offset, Column10::Valid, scan);
  return scan;
}

void encodeOxfordImage(const PolarScan& scan, cv::Mat& image) { encodeRows(scan, image, false); }

/// Rows = azimuths, columns = 11 metadata + bins: checked before decoding.
void checkRowsShape(const cv::Mat& img, const std::string& path, const char* format) {
  if (img.cols > kNavtechMetaColumns)
    detail::checkScanShape(img.rows, img.cols - kNavtechMetaColumns, path, format, "rows",
                           "columns after the 11 metadata columns");
}

PolarScan loadOxfordPng(const std::string& path, double range_resolution, double range_offset) {
  PolarScan scan;
  loadOxfordPng(path, scan, range_resolution, range_offset);
  return scan;
}

void loadOxfordPng(const std::string& path, PolarScan& scan, double range_resolution, double range_offset) {
  const cv::Mat img = readGray(path);
  checkRowsShape(img, path, "Oxford");
  decodeRows(img, path, range_resolution, range_offset, Column10::Valid, scan);
}

void saveOxfordPng(const PolarScan& scan, const std::string& path) {
  cv::Mat img;
  try {
    encodeRows(scan, img, false);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
  writeScanPng(img, path);
}

PolarScan loadBoreasPng(const std::string& path, double range_offset) {
  PolarScan scan;
  loadBoreasPng(path, scan, range_offset);
  return scan;
}

void loadBoreasPng(const std::string& path, PolarScan& scan, double range_offset) {
  const cv::Mat img = readGray(path);
  checkRowsShape(img, path, "Boreas");
  const int bins = img.cols - kNavtechMetaColumns;
  double res = 0.0;
  if (bins == 3360)
    res = 0.0596;
  else if (bins == 6848)
    res = 0.04381;
  else {
    std::ostringstream s;
    s << path << ": " << img.cols << " columns but " << kNavtechMetaColumns << " + 3360 or "
      << kNavtechMetaColumns << " + 6848 bins expected (Boreas layout)";
    throw std::runtime_error(s.str());
  }
  decodeRows(img, path, res, range_offset, Column10::BoreasAuto, scan);
  if (bins == 3360 && !scan.stamp_ns.empty() && scan.stamp_ns.front() / 1000 > kBoreasUpgradeUs)
    scan.range_resolution = 0.04381;  // same width, finer bins after the upgrade (pyboreas)
}

void saveBoreasPng(const PolarScan& scan, const std::string& path) {
  cv::Mat img;
  try {
    encodeRows(scan, img, true);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
  writeScanPng(img, path);
}

int64_t boreasFileStampUs(const PolarScan& scan) {
  if (scan.stamp_ns.empty()) return 0;
  return scan.stamp_ns[scan.stamp_ns.size() / 2] / 1000;
}

}  // namespace spinradar
