#include "scan_io_detail.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "spinradar/core/checked_int.hpp"
#include "spinradar/io/scan_io.hpp"

namespace spinradar::detail {

void markMissingAndDuplicates(PolarScan& scan, const std::string& name) {
  const int n = scan.azimuths;
  int prev = -1, backwards = 0, first_back = -1, empty = 0, repeated = 0;
  for (int a = 0; a < n; ++a) {
    if (scan.stamp_ns[a] == 0 && scan.encoder[a] == 0) {
      scan.valid[a] = 0;  // zero-filled row
      ++empty;
    }
    if (!scan.valid[a]) continue;
    if (prev >= 0 && scan.encoder[a] == scan.encoder[prev]) {
      scan.valid[a] = 0;  // the sensor repeated a packet
      ++repeated;
      continue;
    }
    if (prev >= 0 && scan.stamp_ns[a] < scan.stamp_ns[prev]) {
      if (backwards++ == 0) first_back = a;
    }
    prev = a;
  }
  const int valid = static_cast<int>(std::count(scan.valid.begin(), scan.valid.end(), 1));
  if (valid < n / 2) {  // not a rotation any estimator can use: say why
    std::ostringstream s;
    s << name << ": only " << valid << " of " << n << " rows are valid (" << repeated
      << " repeat the encoder of the row before, " << empty
      << " are all zero): a constant encoder or a zero-filled scan";
    throw std::runtime_error(s.str());
  }
  if (backwards > 0) {
    std::ostringstream s;
    s << name << ": row " << first_back << ": stamps not monotonic (" << backwards
      << " row(s) earlier than the row before)";
    scanWarning(s.str());
  }
  // Missing rows: interpolate angle and stamp between valid neighbours (nominal step at ends).
  const double step = 2.0 * M_PI / std::max(1, n);
  for (int a = 0; a < n; ++a) {
    if (scan.valid[a] || scan.stamp_ns[a] != 0 || scan.encoder[a] != 0) continue;
    int lo = a - 1, hi = a + 1;
    while (lo >= 0 && !scan.valid[lo]) --lo;
    while (hi < n && !scan.valid[hi]) ++hi;
    if (lo >= 0 && hi < n) {
      const double t = double(a - lo) / double(hi - lo);
      double d = scan.azimuth[hi] - scan.azimuth[lo];
      if (d < 0) d += 2.0 * M_PI;
      scan.azimuth[a] = std::fmod(scan.azimuth[lo] + t * d, 2.0 * M_PI);
      scan.stamp_ns[a] = scan.stamp_ns[lo] +
                         static_cast<int64_t>(std::llround(t * double(scan.stamp_ns[hi] - scan.stamp_ns[lo])));
    } else if (lo >= 0) {
      scan.azimuth[a] = std::fmod(scan.azimuth[lo] + (a - lo) * step, 2.0 * M_PI);
      scan.stamp_ns[a] = scan.stamp_ns[lo];
    } else if (hi < n) {
      scan.azimuth[a] = std::fmod(scan.azimuth[hi] - (hi - a) * step + 4.0 * M_PI, 2.0 * M_PI);
      scan.stamp_ns[a] = scan.stamp_ns[hi];
    }
  }
}

bool stemNumber(const std::string& path, long long& value) {
  const auto slash = path.find_last_of('/');
  std::string stem = slash == std::string::npos ? path : path.substr(slash + 1);
  const auto dot = stem.find('.');
  if (dot != std::string::npos) stem = stem.substr(0, dot);
  if (stem.empty()) return false;
  for (char c : stem)
    if (c < '0' || c > '9') return false;
  int64_t v = 0;
  if (!parseInt64(stem, v))
    throw std::runtime_error(path + ": the number in the file name (" + std::to_string(stem.size()) +
                             " digits) does not fit in 64 bits (largest 9223372036854775807)");
  value = v;
  return true;
}

void checkScanShape(int azimuths, int bins, const std::string& name, const char* format,
                    const char* azimuth_what, const char* bin_what) {
  std::ostringstream s;
  if (azimuths < kMinAzimuths || azimuths > kMaxAzimuths)
    s << name << ": " << azimuths << " azimuths (" << azimuth_what << ") but a " << format
      << " scan has " << kMinAzimuths << " to " << kMaxAzimuths
      << " (one per beam of a rotation, 400 for Navtech); a file cut short or of another layout?";
  else if (bins < kMinBins || bins > kMaxBins)
    s << name << ": " << bins << " range bins (" << bin_what << ") but a " << format << " scan has "
      << kMinBins << " to " << kMaxBins << "; a file cut short or of another layout?";
  else
    return;
  throw std::runtime_error(s.str());
}

}  // namespace spinradar::detail
