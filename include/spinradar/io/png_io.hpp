#pragma once
// Reading and writing PNG files without OpenCV's imgcodecs.
//
// Why: Debian's libopencv-imgcodecs pulls in GDAL, HEIF and about 120 more libraries; merely
// linking it costs every `spinradar` process about 0.3 s of CPU and 40 MB at start-up, more
// than decoding 30 scans. The CLI and the part libraries therefore read PNGs with the fast
// decoder (png_gray8.hpp) and libspng, and write them with libspng.
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace spinradar {

/// Loads an 8-bit single-channel PNG (grayscale of 1, 2, 4 or 8 bits, expanded to 8 bits as
/// OpenCV does). The result points into a per-thread buffer: use or copy it before the next
/// call on this thread. Throws std::runtime_error naming the file: "cannot open file", "not a
/// PNG file (bad signature)", "unreadable PNG (...)" or, for colour / 16-bit images,
/// "<n> channel(s) of <b>-bit, an 8-bit single-channel image expected" (channels and depth as
/// OpenCV would load them).
cv::Mat readPngGray8(const std::string& path);

/// PNG bytes of a CV_8UC1, CV_8UC3 (BGR) or CV_8UC4 (BGRA) image, zlib level 0-9, Sub filter
/// (as OpenCV writes). Throws std::runtime_error for other types.
void encodePng(const cv::Mat& image, std::vector<uint8_t>& png, int level = 1);

/// encodePng to a temporary file beside `path`, renamed to `path` once complete. Throws
/// std::runtime_error naming the file when it cannot be written.
void writePng(const cv::Mat& image, const std::string& path, int level = 1);

}  // namespace spinradar
