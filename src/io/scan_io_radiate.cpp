// RADIATE polar PNG: transposed (width = azimuths, height = bins), no per-row metadata.
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <opencv2/core.hpp>

#include "spinradar/io/png_io.hpp"
#include "scan_io_detail.hpp"
#include "spinradar/core/checked_int.hpp"
#include "spinradar/io/scan_io.hpp"

namespace spinradar {

namespace {
constexpr int kRadiateAzimuths = 400;  ///< the CTS350-X beams per rotation
}  // namespace

PolarScan loadRadiatePng(const std::string& path, int64_t scan_stamp_ns, double rotation_hz,
                         double range_resolution, double range_offset) {
  const cv::Mat img = readPngGray8(path);  // names the file and the reason when it cannot
  if (!(rotation_hz > 0) || !std::isfinite(rotation_hz))
    throw std::runtime_error(path + ": rotation_hz must be positive");
  detail::checkScanShape(img.cols, img.rows, path, "RADIATE", "columns", "rows");
  if (img.cols != kRadiateAzimuths) {
    std::ostringstream s;
    s << path << ": " << img.cols << " x " << img.rows << " (columns x rows) but RADIATE images are "
      << kRadiateAzimuths << " azimuths across and the range bins down (400 x 576); "
      << (img.cols > img.rows ? "rows of azimuths with metadata are --format oxford or boreas"
                              : "is this a RADIATE scan?");
    throw std::runtime_error(s.str());
  }
  PolarScan scan;
  scan.resize(img.cols, img.rows);
  scan.range_resolution = range_resolution;
  scan.range_offset = range_offset;
  scan.encoder_size = 5600;
  cv::Mat rows(scan.azimuths, scan.bins, CV_8UC1, scan.power.data());
  cv::transpose(img, rows);
  // RADIATE stores one time per scan: the per-azimuth stamps below are synthesised, evenly
  // spread over one rotation starting at the scan time.
  const double period_ns = 1e9 / rotation_hz;
  // The last azimuth's stamp must fit in int64 (a stamp near 2^63 ns would wrap).
  addChecked(scan_stamp_ns, roundToInt64Checked(period_ns, path + ": rotation period (ns)"),
             path + ": scan stamp (ns)");
  for (int a = 0; a < scan.azimuths; ++a) {
    scan.azimuth[a] = 2.0 * M_PI * a / scan.azimuths;
    scan.encoder[a] = static_cast<uint16_t>(std::lround(double(a) * scan.encoder_size / scan.azimuths) %
                                            scan.encoder_size);
    scan.stamp_ns[a] = scan_stamp_ns + static_cast<int64_t>(std::llround(period_ns * a / scan.azimuths));
  }
  return scan;
}

}  // namespace spinradar
