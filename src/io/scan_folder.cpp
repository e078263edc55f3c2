#include "spinradar/io/scan_folder.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "scan_io_detail.hpp"
#include "spinradar/io/png_io.hpp"
#include "spinradar/io/scan_io.hpp"

namespace fs = std::filesystem;

namespace spinradar {

namespace {

/// Width and height from a PNG's IHDR chunk, without decoding the image.
bool pngSize(const std::string& path, int& width, int& height) {
  std::ifstream f(path, std::ios::binary);
  unsigned char h[24] = {};
  if (!f.read(reinterpret_cast<char*>(h), 24)) return false;
  if (h[0] != 0x89 || h[1] != 'P' || h[2] != 'N' || h[3] != 'G') return false;
  width = (h[16] << 24) | (h[17] << 16) | (h[18] << 8) | h[19];
  height = (h[20] << 24) | (h[21] << 16) | (h[22] << 8) | h[23];
  return true;
}

/// First row's embedded microsecond stamp of a Navtech-layout PNG (columns 0-7, int64 LE), for
/// files whose name is not a stamp (e.g. Boreas-RT's test_frame.png).
bool embeddedStampNs(const std::string& path, int64_t& ns) {
  cv::Mat img;
  try {
    img = readPngGray8(path);
  } catch (const std::runtime_error&) {
    return false;
  }
  if (img.empty() || img.cols < 8) return false;
  int64_t us = 0;
  for (int k = 7; k >= 0; --k) us = (us << 8) | img.at<uint8_t>(0, k);
  ns = us * 1000;
  return true;
}

/// "1574859771.744660272" -> ns, exactly (no double rounding).
bool parseSecondsNs(const std::string& s, int64_t& ns) {
  const auto dot = s.find('.');
  try {
    const long long sec = std::stoll(s.substr(0, dot));
    long long frac = 0;
    if (dot != std::string::npos) {
      std::string f = s.substr(dot + 1, 9);
      if (!f.empty() && !std::all_of(f.begin(), f.end(), ::isdigit)) return false;
      f.resize(9, '0');
      frac = std::stoll(f);
    }
    ns = sec * 1000000000LL + frac;
    return true;
  } catch (const std::exception&) {
    return false;
  }
}

/// RADIATE Navtech_Polar.txt: "Frame: 000001 Time: 1574859771.744660272" per line.
std::vector<std::pair<long long, int64_t>> readRadiateTimes(const std::string& txt) {
  std::vector<std::pair<long long, int64_t>> out;
  std::ifstream f(txt);
  std::string line;
  int lineno = 0;
  while (std::getline(f, line)) {
    ++lineno;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream ls(line);
    std::string k1, frame, k2, time;
    int64_t ns = 0;
    if (!(ls >> k1 >> frame >> k2 >> time) || k1 != "Frame:" || k2 != "Time:" ||
        !std::all_of(frame.begin(), frame.end(), ::isdigit) || frame.empty() || !parseSecondsNs(time, ns))
      throw std::runtime_error(txt + ": line " + std::to_string(lineno) +
                               ": expected 'Frame: <n> Time: <seconds>'");
    out.emplace_back(std::stoll(frame), ns);
  }
  return out;
}

}  // namespace

ScanFormat parseScanFormat(const std::string& name) {
  if (name.empty() || name == "auto") return ScanFormat::Auto;
  if (name == "oxford") return ScanFormat::Oxford;
  if (name == "boreas") return ScanFormat::Boreas;
  if (name == "mulran") return ScanFormat::MulRan;
  if (name == "radiate") return ScanFormat::Radiate;
  throw std::invalid_argument("unknown scan format '" + name +
                              "' (expected auto, oxford, boreas, mulran or radiate)");
}

const char* scanFormatName(ScanFormat format) {
  switch (format) {
    case ScanFormat::Oxford: return "oxford";
    case ScanFormat::Boreas: return "boreas";
    case ScanFormat::MulRan: return "mulran";
    case ScanFormat::Radiate: return "radiate";
    default: return "auto";
  }
}

ScanFolder::ScanFolder(const std::string& folder, ScanFormat format, ScanFolderOptions options)
    : format_(format), options_(options) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) throw std::runtime_error(folder + ": not a folder");
  fs::path dir = fs::path(folder).lexically_normal();
  if (dir.filename().empty()) dir = dir.parent_path();  // trailing slash
  std::string radiate_txt;
  if (fs::is_directory(dir / "radar", ec)) {
    dir /= "radar";
  } else if (fs::is_directory(dir / "Navtech_Polar", ec)) {
    radiate_txt = (dir / "Navtech_Polar.txt").string();
    dir /= "Navtech_Polar";
  } else if (dir.filename() == "Navtech_Polar") {
    radiate_txt = (dir.parent_path() / "Navtech_Polar.txt").string();
  }
  dir_ = dir.string();

  std::vector<std::string> pngs, csvs;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    if (!e.is_regular_file()) continue;
    const std::string ext = e.path().extension().string();
    if (ext == ".png") pngs.push_back(e.path().string());
    else if (ext == ".csv") csvs.push_back(e.path().string());
  }
  if (ec) throw std::runtime_error(folder + ": cannot list folder (" + ec.message() + ")");

  if (format_ == ScanFormat::Auto) {
    if (pngs.empty() && !csvs.empty()) {
      format_ = ScanFormat::MulRan;
    } else if (!pngs.empty()) {
      std::sort(pngs.begin(), pngs.end());
      int w = 0, h = 0;
      if (!pngSize(pngs.front(), w, h))
        throw std::runtime_error(folder + ": cannot guess the format, " + pngs.front() + " is not a PNG");
      const int bins = w - kNavtechMetaColumns;
      if (!radiate_txt.empty())
        format_ = ScanFormat::Radiate;
      else if (bins == 3360 || bins == 6848)
        format_ = ScanFormat::Boreas;
      else if (w > kNavtechMetaColumns && h < w)
        format_ = ScanFormat::Oxford;  // rows = azimuths, many more bins than azimuths
      else if (h > w)
        format_ = ScanFormat::Radiate;  // transposed: bins down, azimuths across
      else
        throw std::runtime_error(folder + ": cannot guess the format of " + pngs.front() + " (" +
                                 std::to_string(w) + " x " + std::to_string(h) + ")");
    } else {
      throw std::runtime_error(folder + ": no scan files (.png or .csv) found");
    }
  }

  const std::vector<std::string>& names = format_ == ScanFormat::MulRan ? csvs : pngs;
  if (names.empty())
    throw std::runtime_error(folder + ": no " + (format_ == ScanFormat::MulRan ? ".csv" : ".png") +
                             " scan files for format " + scanFormatName(format_));

  std::vector<std::pair<long long, int64_t>> radiate_times;
  if (format_ == ScanFormat::Radiate && !radiate_txt.empty() && fs::exists(radiate_txt, ec))
    radiate_times = readRadiateTimes(radiate_txt);

  files_.reserve(names.size());
  for (const auto& p : names) {
    long long num = 0;
    const bool navtech_png = format_ == ScanFormat::Oxford || format_ == ScanFormat::Boreas;
    int64_t embedded_ns = 0;
    if (!detail::stemNumber(p, num) && navtech_png && embeddedStampNs(p, embedded_ns)) {
      files_.push_back({p, embedded_ns});
      continue;
    }
    if (!detail::stemNumber(p, num))
      throw std::runtime_error(folder + ": file name " + fs::path(p).filename().string() +
                               " is not a number (time stamp or frame index expected)");
    int64_t ns = 0;
    switch (format_) {
      case ScanFormat::Oxford:
      case ScanFormat::Boreas: ns = num * 1000; break;  // microseconds
      case ScanFormat::MulRan: ns = num; break;
      case ScanFormat::Radiate: {
        if (radiate_times.empty()) {
          // No Navtech_Polar.txt: synthesise scan times at the rotation rate from the frame index.
          ns = static_cast<int64_t>((num - 1) * (1e9 / options_.rotation_hz));
        } else {
          auto it = std::find_if(radiate_times.begin(), radiate_times.end(),
                                 [&](const auto& t) { return t.first == num; });
          if (it == radiate_times.end())
            throw std::runtime_error(folder + ": frame " + std::to_string(num) + " missing from " + radiate_txt);
          ns = it->second;
        }
        break;
      }
      default: break;
    }
    files_.push_back({p, ns});
  }
  std::stable_sort(files_.begin(), files_.end(),
                   [](const File& a, const File& b) { return a.stamp_ns < b.stamp_ns; });
  // Bin count of the first scan, from its header, to catch mis-sized files on load.
  int w = 0, h = 0;
  if (format_ == ScanFormat::Oxford || format_ == ScanFormat::Boreas) {
    if (pngSize(files_.front().path, w, h)) expected_bins_ = w - kNavtechMetaColumns;
  } else if (format_ == ScanFormat::Radiate) {
    if (pngSize(files_.front().path, w, h)) expected_bins_ = h;
  } else if (format_ == ScanFormat::MulRan) {
    std::ifstream f(files_.front().path);
    std::string line;
    if (std::getline(f, line)) expected_bins_ = static_cast<int>(std::count(line.begin(), line.end(), ',')) - 3;
  }
  for (size_t i = 1; i < files_.size(); ++i)
    if (files_[i].stamp_ns == files_[i - 1].stamp_ns)
      scanWarning(folder + ": " + files_[i - 1].path + " and " + files_[i].path + " have the same stamp");
}

PolarScan ScanFolder::load(size_t i) const {
  const File& f = files_.at(i);
  PolarScan s;
  switch (format_) {
    case ScanFormat::Oxford:
      s = loadOxfordPng(f.path, options_.range_resolution.value_or(0.0438), options_.range_offset.value_or(0.0));
      break;
    case ScanFormat::Boreas:
      s = loadBoreasPng(f.path, options_.range_offset.value_or(kBoreasRangeOffset));
      if (options_.range_resolution) s.range_resolution = *options_.range_resolution;
      break;
    case ScanFormat::MulRan:
      s = loadMulranCsv(f.path, options_.range_resolution.value_or(0.0595238), options_.range_offset.value_or(0.0));
      break;
    case ScanFormat::Radiate:
      s = loadRadiatePng(f.path, f.stamp_ns, options_.rotation_hz, options_.range_resolution.value_or(0.17361),
                         options_.range_offset.value_or(0.0));
      break;
    default:
      throw std::runtime_error(dir_ + ": no format");
  }
  if (expected_bins_ > 0 && s.bins != expected_bins_) {
    std::ostringstream m;
    if (format_ == ScanFormat::Oxford || format_ == ScanFormat::Boreas)
      m << f.path << ": " << s.bins + kNavtechMetaColumns << " columns but " << kNavtechMetaColumns << " + "
        << expected_bins_ << " bins expected (as in " << files_.front().path << ")";
    else
      m << f.path << ": " << s.bins << " bins but " << expected_bins_ << " expected (as in " << files_.front().path
        << ")";
    throw std::runtime_error(m.str());
  }
  return s;
}

}  // namespace spinradar
