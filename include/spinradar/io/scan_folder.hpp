#pragma once
// A dataset folder of polar scans: lists its scan files sorted by time, guesses the format.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "spinradar/core/polar_scan.hpp"

namespace spinradar {

enum class ScanFormat { Auto, Oxford, Boreas, MulRan, Radiate };

/// "auto" (or ""), "oxford", "boreas", "mulran", "radiate"; throws std::invalid_argument otherwise.
ScanFormat parseScanFormat(const std::string& name);
const char* scanFormatName(ScanFormat format);

struct ScanFolderOptions {
  std::optional<double> range_resolution;  ///< m per bin; default: the format's own
  std::optional<double> range_offset;      ///< m; default: the format's own (Boreas -0.31)
  double rotation_hz = 4.0;                ///< RADIATE: used to synthesise stamps
};

/// Accepts the folder holding the scans or a dataset root above it: `<root>/radar/` (Oxford,
/// Boreas), `<root>/Navtech_Polar/` + `Navtech_Polar.txt` (RADIATE). MulRan: a folder of ray
/// CSVs named by their stamp in ns. Errors (std::runtime_error) name the folder.
class ScanFolder {
 public:
  explicit ScanFolder(const std::string& folder, ScanFormat format = ScanFormat::Auto,
                      ScanFolderOptions options = {});

  ScanFormat format() const { return format_; }
  const std::string& folder() const { return dir_; }  ///< the folder holding the scan files
  size_t size() const { return files_.size(); }
  bool empty() const { return files_.empty(); }
  const std::string& path(size_t i) const { return files_.at(i).path; }
  /// Time of the scan from its file name (Oxford: first azimuth, Boreas: middle azimuth,
  /// a Navtech PNG not named by a stamp: its first row's embedded stamp,
  /// MulRan: last azimuth) or Navtech_Polar.txt (RADIATE), in ns.
  int64_t fileStampNs(size_t i) const { return files_.at(i).stamp_ns; }
  /// Loads scan i with the folder's format and options. Throws std::runtime_error naming the
  /// file when it cannot be read or its bin count differs from the folder's first scan.
  PolarScan load(size_t i) const;
  /// Loads scan i into `scan`, reusing its buffers: Oxford and Boreas PNGs allocate nothing once
  /// `scan` has held a scan of the same size (MulRan CSVs and RADIATE PNGs are read into a new
  /// scan, moved in). Same checks and errors as load(i); after an error `scan` holds unspecified
  /// contents (still fine to load into again).
  void load(size_t i, PolarScan& scan) const;
  /// Range bins of the folder's first scan (from its header), 0 when unknown.
  int expectedBins() const { return expected_bins_; }

 private:
  struct File {
    std::string path;
    int64_t stamp_ns;
  };
  std::string dir_;
  ScanFormat format_ = ScanFormat::Auto;
  ScanFolderOptions options_;
  std::vector<File> files_;
  int expected_bins_ = 0;
};

}  // namespace spinradar
