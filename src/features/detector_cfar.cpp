// CA-CFAR keypoint detector (DetectorConfig::detector == "cfar"): one keypoint per run of bins
// over cfar_threshold times the mean of the training cells on both sides.
#include <algorithm>
#include <cmath>

#include "for_each_above.hpp"
#include "spinradar/features/detector.hpp"

namespace spinradar {

using detail::forEachAbove;

void Detector::detectCfar(const PolarScan& scan, std::vector<Keypoint>& out) {
  out.clear();
  if (scan.empty()) return;
  requireConsistent(scan);
  const int n = scan.bins, W = config_.cfar_window, G = config_.cfar_guard;
  int b0, b1;
  rangeWindow(scan, b0, b1);
  if (b0 > b1) return;
  cos_.resize(scan.azimuths);
  sin_.resize(scan.azimuths);
  prefix_.resize(size_t(n) + 1);
  const float thr = static_cast<float>(config_.cfar_threshold);
  const bool has_valid = scan.valid.size() == size_t(scan.azimuths);
  int32_t* ps = prefix_.data();

  hit_.resize(size_t(n));
  mean_.resize(size_t(n));
  uint8_t* hit = hit_.data();
  float* mean = mean_.data();
  for (int a = 0; a < scan.azimuths; ++a) {
    if (has_valid && !scan.valid[a]) continue;
    cos_[a] = std::cos(scan.azimuth[a]);
    sin_[a] = std::sin(scan.azimuth[a]);
    const uint8_t* row = scan.row(a);
    ps[0] = 0;
    for (int j = 0; j < n; ++j) ps[j + 1] = ps[j] + row[j];
    // Interior bins have full windows on both sides: constant cell count, branch-free loop.
    const int i0 = std::max(b0, G + W), i1 = std::min(b1, n - 1 - G - W);
    auto general = [&](int j) {
      const int l0 = std::max(0, j - G - W), l1 = std::max(0, j - G);          // [l0, l1)
      const int r0 = std::min(n, j + G + 1), r1 = std::min(n, j + G + 1 + W);  // [r0, r1)
      const int cnt = (l1 - l0) + (r1 - r0);
      mean[j] = cnt > 0 ? float((ps[l1] - ps[l0]) + (ps[r1] - ps[r0])) / float(cnt) : 0.f;
      hit[j] = cnt > 0 && float(row[j]) > thr * mean[j];
    };
    for (int j = b0; j <= std::min(b1, i0 - 1); ++j) general(j);
    const float inv = 1.f / float(2 * W);
    for (int j = i0; j <= i1; ++j) {
      const int32_t sum = (ps[j - G] - ps[j - G - W]) + (ps[j + G + 1 + W] - ps[j + G + 1]);
      mean[j] = float(sum) * inv;
      hit[j] = float(row[j]) > thr * mean[j];
    }
    for (int j = std::max(b0, i1 + 1); j <= b1; ++j) general(j);
    // One keypoint per run of hits, at its strongest bin (hits found 16 at a time).
    int best = -1, last = -2;
    forEachAbove(hit, b0, b1, 0, [&](int j) {
      if (j != last + 1 && best >= 0) {
        emit(scan, a, best, float(row[best]) - mean[best], out);
        best = -1;
      }
      if (best < 0 || row[j] > row[best]) best = j;
      last = j;
    });
    if (best >= 0) emit(scan, a, best, float(row[best]) - mean[best], out);
  }
}

}  // namespace spinradar
