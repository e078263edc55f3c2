#include "spinradar/estimation/azimuth_times.hpp"

#include <cmath>

namespace spinradar {

void uniformKeypointTimes(const PolarScan& scan, std::vector<Keypoint>& keypoints) {
  const int n = static_cast<int>(scan.stamp_ns.size());
  if (n < 2) return;
  // Fit relative to the first stamp so the sums stay exact in double.
  const int64_t t0 = scan.stamp_ns.front();
  double sw = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (int a = 0; a < n; ++a) {
    if (!scan.valid.empty() && !scan.valid[a]) continue;
    const double x = a, y = 1e-9 * static_cast<double>(scan.stamp_ns[a] - t0);
    sw += 1; sx += x; sy += y; sxx += x * x; sxy += x * y;
  }
  const double den = sw * sxx - sx * sx;
  if (sw < 2 || !(std::abs(den) > 0)) return;
  const double b = (sw * sxy - sx * sy) / den, a0 = (sy - b * sx) / sw;
  for (Keypoint& k : keypoints) {
    const int a = k.azimuth_index;
    if (a < 0 || a >= n) continue;
    const int64_t fitted = t0 + static_cast<int64_t>(std::llround(1e9 * (a0 + b * a)));
    k.stamp_ns = fitted + (k.stamp_ns - scan.stamp_ns[a]);
  }
}

}  // namespace spinradar
