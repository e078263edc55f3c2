#include "scan_io_detail.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "spinradar/io/scan_io.hpp"

namespace spinradar::detail {

void markMissingAndDuplicates(PolarScan& scan, const std::string& name) {
  const int n = scan.azimuths;
  int prev = -1, backwards = 0, first_back = -1;
  for (int a = 0; a < n; ++a) {
    if (scan.stamp_ns[a] == 0 && scan.encoder[a] == 0) scan.valid[a] = 0;  // zero-filled row
    if (!scan.valid[a]) continue;
    if (prev >= 0 && scan.encoder[a] == scan.encoder[prev]) {
      scan.valid[a] = 0;  // the sensor repeated a packet
      continue;
    }
    if (prev >= 0 && scan.stamp_ns[a] < scan.stamp_ns[prev]) {
      if (backwards++ == 0) first_back = a;
    }
    prev = a;
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
  if (stem.empty() || stem.size() > 19) return false;
  for (char c : stem)
    if (c < '0' || c > '9') return false;
  value = std::stoll(stem);
  return true;
}

}  // namespace spinradar::detail
