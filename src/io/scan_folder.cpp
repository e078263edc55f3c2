#include "spinradar/io/scan_folder.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "scan_io_detail.hpp"
#include "spinradar/io/png_io.hpp"
#include "spinradar/core/checked_int.hpp"
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

/// Decodes a PNG only when its size is plausible for a scan (a 200000 x 400 image is not).
/// The image lives in readPngGray8's per-thread buffer, valid until this thread reads the next
/// PNG: the callers only look at it at once. (No copy: a 1.5 MB copy was ~5 ms of every
/// odometry run's start, mostly first-touch page faults.)
cv::Mat readSmallGray(const std::string& path, int width, int height) {
  if (width > detail::kMaxBins + kNavtechMetaColumns || height > detail::kMaxBins) return {};
  try {
    return readPngGray8(path);
  } catch (const std::exception&) {
    return {};
  }
}

/// First row's embedded microsecond stamp of a Navtech-layout PNG (columns 0-7, int64 LE), for
/// files whose name is not a stamp (e.g. Boreas-RT's test_frame.png).
bool embeddedStampNs(const std::string& path, int64_t& ns) {
  int w = 0, h = 0;
  if (!pngSize(path, w, h)) return false;
  const cv::Mat img = readSmallGray(path, w, h);
  if (img.empty() || img.cols < 8) return false;
  uint64_t us = 0;
  for (int k = 7; k >= 0; --k) us = (us << 8) | img.at<uint8_t>(0, k);
  ns = mulChecked(static_cast<int64_t>(us), 1000, path + ": row 0: stamp (us)");
  return true;
}

/// Does the PNG carry the Oxford/Boreas row metadata (a stamp and an encoder per row)? When not,
/// `why` says what was seen, for the error that asks for --format.
bool looksLikeNavtechRows(const std::string& path, std::string& why) {
  int w = 0, h = 0;
  if (!pngSize(path, w, h)) {
    why = path + " is not a PNG";
    return false;
  }
  const std::string size = path + " is " + std::to_string(w) + " x " + std::to_string(h) +
                           " (columns x rows)";
  if (w <= kNavtechMetaColumns) {
    why = size + ": too narrow for the 11 metadata columns of Oxford/Boreas rows";
    return false;
  }
  const cv::Mat img = readSmallGray(path, w, h);
  if (img.empty()) {
    why = size + ": not an 8-bit grey image of a plausible scan size";
    return false;
  }
  int64_t prev_us = 0;
  int backwards = 0, encoders_changed = 0, prev_enc = -1;
  for (int r = 0; r < img.rows; ++r) {
    const uint8_t* p = img.ptr<uint8_t>(r);
    uint64_t us = 0;
    for (int k = 7; k >= 0; --k) us = (us << 8) | p[k];
    const int enc = p[8] | (p[9] << 8);
    if (us == 0 && enc == 0) continue;  // a missing row
    if (enc >= 5600) {
      why = size + ": row " + std::to_string(r) + " columns 8-9 hold " + std::to_string(enc) +
            ", not an encoder reading (< 5600) of Oxford/Boreas rows";
      return false;
    }
    if (static_cast<int64_t>(us) < prev_us) ++backwards;
    if (prev_enc >= 0 && enc != prev_enc) ++encoders_changed;
    prev_us = static_cast<int64_t>(us);
    prev_enc = enc;
  }
  if (encoders_changed == 0) {
    why = size + ": the encoder (columns 8-9) never changes from row to row";
    return false;
  }
  if (backwards > img.rows / 10) {
    why = size + ": the stamps (columns 0-7) go backwards on " + std::to_string(backwards) +
          " rows";
    return false;
  }
  return true;
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
    int64_t number = 0;
    if (!(ls >> k1 >> frame >> k2 >> time) || k1 != "Frame:" || k2 != "Time:")
      throw std::runtime_error(txt + ": line " + std::to_string(lineno) +
                               ": expected 'Frame: <n> Time: <seconds>'");
    if (!parseInt64(frame, number) || number < 0)
      throw std::runtime_error(txt + ": line " + std::to_string(lineno) + ": frame '" + frame +
                               "' is not a frame number (digits, at most 9223372036854775807)");
    if (!parseSecondsToNs(time, ns))
      throw std::runtime_error(txt + ": line " + std::to_string(lineno) + ": time '" + time +
                               "' is not seconds within the 64-bit nanosecond range");
    out.emplace_back(number, ns);
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
  size_t dangling = 0;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    std::error_code lec;
    if (e.is_symlink(lec) && !fs::exists(e.path(), lec)) {
      // A link to a missing file: say so (and count) rather than silently read fewer scans.
      if (++dangling <= 5) scanWarning(e.path().string() + ": dangling link skipped");
      continue;
    }
    if (!e.is_regular_file()) continue;
    const std::string ext = e.path().extension().string();
    if (ext == ".png") pngs.push_back(e.path().string());
    else if (ext == ".csv") csvs.push_back(e.path().string());
  }
  if (ec) throw std::runtime_error(folder + ": cannot list folder (" + ec.message() + ")");
  if (dangling > 5) scanWarning(folder + ": " + std::to_string(dangling) + " dangling links skipped in all");

  if (format_ == ScanFormat::Auto) {
    // Guess only when the evidence is unambiguous; otherwise name what was seen.
    const std::string ask = "; give --format oxford, boreas, mulran or radiate";
    std::sort(pngs.begin(), pngs.end());
    std::sort(csvs.begin(), csvs.end());
    if (!pngs.empty() && !csvs.empty())
      throw std::runtime_error(folder + ": cannot tell the scan format: it holds both .png (" +
                               fs::path(pngs.front()).filename().string() + ", ...) and .csv (" +
                               fs::path(csvs.front()).filename().string() + ", ...) files" + ask);
    if (!csvs.empty()) {
      format_ = ScanFormat::MulRan;
    } else if (!pngs.empty()) {
      std::string why;
      int w = 0, h = 0;
      if (!radiate_txt.empty() && fs::exists(radiate_txt, ec)) {
        format_ = ScanFormat::Radiate;  // the dataset's own layout: Navtech_Polar + its times
      } else if (looksLikeNavtechRows(pngs.front(), why)) {
        pngSize(pngs.front(), w, h);
        const int bins = w - kNavtechMetaColumns;
        format_ = bins == 3360 || bins == 6848 ? ScanFormat::Boreas : ScanFormat::Oxford;
      } else {
        throw std::runtime_error(folder + ": cannot tell the scan format: " + why +
                                 ", and there is no Navtech_Polar.txt (RADIATE)" + ask);
      }
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
      case ScanFormat::Boreas:  // microseconds
        ns = mulChecked(num, 1000, p + ": stamp in the file name (us)");
        break;
      case ScanFormat::MulRan: ns = num; break;
      case ScanFormat::Radiate: {
        if (radiate_times.empty()) {
          // No Navtech_Polar.txt: synthesise scan times at the rotation rate from the frame index.
          ns = roundToInt64Checked((double(num) - 1.0) * (1e9 / options_.rotation_hz),
                                   p + ": frame number x rotation period (ns)");
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
  PolarScan s;
  load(i, s);
  return s;
}

void ScanFolder::load(size_t i, PolarScan& s) const {
  const File& f = files_.at(i);
  switch (format_) {
    case ScanFormat::Oxford:
      loadOxfordPng(f.path, s, options_.range_resolution.value_or(0.0438), options_.range_offset.value_or(0.0));
      break;
    case ScanFormat::Boreas:
      loadBoreasPng(f.path, s, options_.range_offset.value_or(kBoreasRangeOffset));
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
}

}  // namespace spinradar
