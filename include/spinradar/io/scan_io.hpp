#pragma once
// Readers and writers of polar radar scans in the public dataset layouts.
//
// Oxford Radar RobotCar / Boreas PNG ("Navtech rows"): 8-bit single-channel PNG, one row per
// azimuth. Columns 0-7: int64 LE stamp in microseconds; 8-9: uint16 LE encoder (0..encoder_size-1,
// angle = enc / encoder_size * 2 pi, clockwise from forward); 10: valid byte (Oxford: 255) or
// chirp direction (Boreas-RT: 0 = down, 255 = up); 11..: power bins.
//
// Every loader throws std::runtime_error naming the file, the row/line when there is one, and
// the reason. Rows that are missing (all-zero metadata) or duplicated (same encoder as the row
// before) are kept but marked valid = 0. Non-monotonic stamps are reported through the warning
// handler, not thrown: real recordings contain them and the data is still usable.
#include <cstdint>
#include <functional>
#include <string>

#include <opencv2/core/mat.hpp>

#include "spinradar/core/polar_scan.hpp"

namespace spinradar {

/// Number of metadata columns in front of the bins of an Oxford/Boreas row.
constexpr int kNavtechMetaColumns = 11;

/// Receives loader warnings (default: print to stderr). Pass nullptr to restore the default.
using ScanWarningHandler = std::function<void(const std::string&)>;
void setScanWarningHandler(ScanWarningHandler handler);
/// Emits a warning through the current handler (used by the loaders).
void scanWarning(const std::string& message);

// ---- Oxford Radar RobotCar ----
PolarScan loadOxfordPng(const std::string& path, double range_resolution = 0.0438,
                        double range_offset = 0.0);
/// The same into an existing scan, reusing its buffers: once `scan` has held a scan of this
/// size, loading allocates nothing (the file bytes and the decoder's buffers are per thread and
/// reused too). Every field of `scan` is overwritten; after an exception its contents are
/// unspecified (but valid to load into again).
void loadOxfordPng(const std::string& path, PolarScan& scan, double range_resolution = 0.0438,
                   double range_offset = 0.0);
/// Writes the Oxford layout (column 10 = 255 for valid rows, 0 otherwise). Stamps are written in
/// microseconds (truncated). Throws std::runtime_error naming the file when it cannot be written.
void saveOxfordPng(const PolarScan& scan, const std::string& path);

/// In-memory versions of the above (e.g. for image messages). `name` is used in error messages.
PolarScan decodeOxfordImage(const cv::Mat& image, const std::string& name,
                            double range_resolution = 0.0438, double range_offset = 0.0);
void encodeOxfordImage(const PolarScan& scan, cv::Mat& image);

// ---- Boreas (Oxford row layout) ----
/// 3360 bins: the CIR204-H, 0.0596 m before its firmware upgrade of 2021-09-21 (Unix
/// kBoreasUpgradeUs, told by the first azimuth's stamp as pyboreas tells it by the file name)
/// and 0.04381 m after; 6848 bins -> 0.04381 m (Boreas-RT). Other widths are rejected. When column 10 holds both 0 and 255
/// (Boreas-RT alternating chirps), it fills `chirp_up` instead of the valid flags.
constexpr double kBoreasRangeOffset = -0.31;
constexpr int64_t kBoreasUpgradeUs = 1632182400LL * 1000000;  ///< 2021-09-21 00:00 UTC
PolarScan loadBoreasPng(const std::string& path, double range_offset = kBoreasRangeOffset);
/// Into an existing scan, reusing its buffers (as loadOxfordPng above).
void loadBoreasPng(const std::string& path, PolarScan& scan, double range_offset = kBoreasRangeOffset);
/// Column 10 = chirp_up ? 255 : 0 when chirp_up is present, else 255/0 valid flag.
void saveBoreasPng(const PolarScan& scan, const std::string& path);
/// Boreas names a scan file after the stamp of its middle azimuth (microseconds).
int64_t boreasFileStampUs(const PolarScan& scan);

// ---- MulRan ray CSV ----
/// One line per azimuth: stamp ns, azimuth deg, encoder, packet counter, bins (0.0595238 m).
/// Angles are taken from the encoder (clockwise, like the other Navtech formats); MulRan's own
/// tools draw this radar counter-clockwise, so mirror y when comparing with their images.
PolarScan loadMulranCsv(const std::string& path, double range_resolution = 0.0595238,
                        double range_offset = 0.0);

// ---- RADIATE polar PNG ----
/// Transposed layout: width = 400 azimuths, height = 576 bins of 0.17361 m, no per-row metadata.
/// The scan's time `scan_stamp_ns` is given to the first azimuth and the others are spread
/// evenly over one rotation at `rotation_hz` (RADIATE records one time per scan only, so these
/// per-azimuth stamps are synthesised). Angles are a / azimuths * 2 pi, clockwise.
PolarScan loadRadiatePng(const std::string& path, int64_t scan_stamp_ns,
                         double rotation_hz = 4.0, double range_resolution = 0.17361,
                         double range_offset = 0.0);

}  // namespace spinradar
