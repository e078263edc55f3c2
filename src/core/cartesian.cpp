#include "spinradar/core/cartesian.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>


namespace spinradar {

CartesianProjector::CartesianProjector(double resolution, int width) { setImageGeometry(resolution, width); }

void CartesianProjector::setImageGeometry(double resolution, int width) {
  if (!(resolution > 0) || width < 2)
    throw std::invalid_argument("CartesianProjector: resolution must be > 0 and width >= 2");
  if (resolution != resolution_ || width != width_) azimuths_ = -1;  // force a rebuild
  resolution_ = resolution;
  width_ = width;
  centre_ = 0.5 * (width - 1);
}

bool CartesianProjector::geometryChanged(const PolarScan& scan, double offset) const {
  if (scan.azimuths != azimuths_ || scan.bins != bins_ || scan.range_resolution != range_resolution_ ||
      std::abs(offset - offset_) > 1e-9)
    return true;
  const double tol = 0.02 * 2.0 * M_PI / std::max(1, scan.azimuths);
  for (int a = 0; a < scan.azimuths; ++a)
    if (std::abs(std::remainder(scan.azimuth[a] - angles_[a], 2.0 * M_PI)) > tol) return true;
  return false;
}

void CartesianProjector::buildTables(const PolarScan& scan, double offset) {
  const int n = scan.azimuths;
  azimuths_ = n;
  bins_ = scan.bins;
  range_resolution_ = scan.range_resolution;
  offset_ = offset;
  angles_.assign(scan.azimuth.begin(), scan.azimuth.end());
  ++builds_;

  // Unwrapped, increasing angles starting at row 0; row n (the copy of row 0) sits at +2 pi.
  std::vector<double> ang(n + 1);
  ang[0] = angles_[0];
  bool monotonic = true;
  for (int a = 1; a < n; ++a) {
    double d = angles_[a] - angles_[a - 1];
    while (d < 0) d += 2.0 * M_PI;
    ang[a] = ang[a - 1] + d;
    monotonic &= d > 0;
  }
  ang[n] = ang[0] + 2.0 * M_PI;
  if (!monotonic || ang[n - 1] >= ang[n]) {  // not one increasing sweep: assume uniform steps
    for (int a = 0; a <= n; ++a) ang[a] = ang[0] + 2.0 * M_PI * a / n;
  }

  box_ = std::clamp(static_cast<int>(std::lround(resolution_ / scan.range_resolution)), 1, 255);
  const size_t bins = static_cast<size_t>(scan.bins);
  const uint32_t zero_row = static_cast<uint32_t>((n + 1) * bins);
  offset_table_.resize(size_t(width_) * width_);
  weight_table_.resize(size_t(width_) * width_);
  for (int v = 0; v < width_; ++v) {
    const double x = (centre_ - v) * resolution_;
    for (int u = 0; u < width_; ++u) {
      const size_t i = size_t(v) * width_ + u;
      const double y = (centre_ - u) * resolution_;
      const double r = std::hypot(x, y);
      const double fb = (r - offset) / scan.range_resolution - 0.5;  // fractional bin
      const long bin = std::lround(fb);
      if (fb < -0.5 || bin >= scan.bins) {
        offset_table_[i] = zero_row;
        weight_table_[i] = 0;
        continue;
      }
      double phi = std::atan2(-y, x);  // clockwise from forward
      while (phi < ang[0]) phi += 2.0 * M_PI;
      while (phi >= ang[n]) phi -= 2.0 * M_PI;
      const int hi = static_cast<int>(std::upper_bound(ang.begin(), ang.end(), phi) - ang.begin());
      int lo = std::clamp(hi - 1, 0, n - 1);
      long w = std::lround(256.0 * (phi - ang[lo]) / (ang[lo + 1] - ang[lo]));
      if (w >= 256) {  // rounds onto the next row (row n is row 0 again)
        ++lo;
        w = 0;
      }
      offset_table_[i] = static_cast<uint32_t>(size_t(lo) * bins + size_t(std::max(0L, bin)));
      weight_table_[i] = static_cast<uint8_t>(std::clamp(w, 0L, 255L));
    }
  }
}

void CartesianProjector::render(const PolarScan& scan, cv::Mat& image, double extra_range_offset) {
  if (scan.empty() || scan.power.size() != size_t(scan.azimuths) * scan.bins ||
      scan.azimuth.size() != size_t(scan.azimuths))
    throw std::invalid_argument("CartesianProjector: empty or inconsistent PolarScan");
  const double offset = scan.range_offset + extra_range_offset;
  if (geometryChanged(scan, offset)) buildTables(scan, offset);

  const int n = scan.azimuths, bins = scan.bins;
  polar_.resize(size_t(n + 3) * bins);
  uint8_t* pol = polar_.data();
  const bool has_valid = scan.valid.size() == size_t(n);
  int last_valid = -1;
  if (has_valid)  // an invalid first row borrows from the last valid row of the sweep
    for (int a = n - 1; a >= 0 && last_valid < 0; --a)
      if (scan.valid[a]) last_valid = a;
  // Centred moving average over box_ bins (fewer at the ends), in fixed point.
  const int k = box_, left = (k - 1) / 2;
  const uint32_t inv = (65536u + k / 2) / k;
  box_sum_.resize(bins);
  for (int a = 0; a < n; ++a) {
    int src = a;
    if (has_valid) {
      if (scan.valid[a])
        last_valid = a;
      else if (last_valid >= 0)
        src = last_valid;
    }
    const uint8_t* row = scan.row(src);
    uint8_t* dst = pol + size_t(a) * bins;
    if (k == 1 || bins < k) {
      std::memcpy(dst, row, bins);
      continue;
    }
    // Interior bins (full window): sum of k shifted copies of the row, vectorisable.
    const int j0 = left, j1 = bins - (k - left);  // [j0, j1] have full windows
    uint16_t* acc = box_sum_.data();
    std::fill(acc + j0, acc + j1 + 1, uint16_t(0));
    for (int t = 0; t < k; ++t) {
      const uint8_t* src_t = row + t - left;
      for (int j = j0; j <= j1; ++j) acc[j] = static_cast<uint16_t>(acc[j] + src_t[j]);
    }
    for (int j = j0; j <= j1; ++j) dst[j] = static_cast<uint8_t>((uint32_t(acc[j]) * inv + 32768u) >> 16);
    auto edge = [&](int j) {  // the ends: shorter windows
      const int lo = std::max(0, j - left), hi = std::min(bins, j - left + k);
      uint32_t sum = 0;
      for (int q = lo; q < hi; ++q) sum += row[q];
      dst[j] = static_cast<uint8_t>((sum + (hi - lo) / 2) / (hi - lo));
    };
    for (int j = 0; j < j0; ++j) edge(j);
    for (int j = j1 + 1; j < bins; ++j) edge(j);
  }
  std::memcpy(pol + size_t(n) * bins, pol, bins);
  std::memset(pol + size_t(n + 1) * bins, 0, 2 * size_t(bins));

  image.create(width_, width_, CV_8UC1);
  const uint32_t* off = offset_table_.data();
  const uint8_t* wt = weight_table_.data();
  for (int v = 0; v < width_; ++v) {
    uint8_t* out = image.ptr<uint8_t>(v);
    const size_t base = size_t(v) * width_;
    for (int u = 0; u < width_; ++u) {
      const uint8_t* p = pol + off[base + u];
      const int a = p[0], b = p[bins], w = wt[base + u];
      out[u] = static_cast<uint8_t>(a + (((b - a) * w + 128) >> 8));
    }
  }
}

}  // namespace spinradar
