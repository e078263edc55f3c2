#include "spinradar/features/cartesian.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>
#endif
#if defined(__SSE4_1__)
#include <smmintrin.h>
#endif

namespace spinradar {

CartesianProjector::CartesianProjector(double resolution, int width) { setImageGeometry(resolution, width); }

void CartesianProjector::setImageGeometry(double resolution, int width) {
  if (!(resolution > 0) || width < 2)
    throw std::invalid_argument("CartesianProjector: resolution must be > 0 and width >= 2");
  if (resolution != resolution_ || width != width_ || pixel_range_.empty()) {
    azimuths_ = -1;  // force a rebuild
    resolution_ = resolution;
    width_ = width;
    centre_ = 0.5 * (width - 1);
    buildPixelGeometry();
  }
}

namespace {
/// std::lround without the library call (same result: v - trunc(v) is exact).
template <class T>
inline long roundHalfAway(T v) {
  T t = std::trunc(v);
  if (std::abs(v - t) >= T(0.5)) t += std::copysign(T(1), v);
  return static_cast<long>(t);
}
}  // namespace

void CartesianProjector::buildPixelGeometry() {
  // hypot and atan2 for every pixel were most of a projector's construction (~0.25 G
  // instructions at 964 px). The grid is symmetric about the centre row and column and about
  // its diagonal: the eight pixels (+-x, +-y) and (+-y, +-x) have exactly the same coordinates up
  // to sign and order, so the same range (glibc's hypot takes |x|, |y| and orders them), and
  // angles of -theta, pi -+ theta and -+theta -+ pi/2: in 1/65536 turns, integer offsets of one
  // code. Each octant pixel is computed once. Its code is exactly what atan2 per pixel gives
  // unless turns * 65536 lies within 1e-6 of a rounding boundary (atan2 errs by < 1e-11 there);
  // such pixels, and the centre, are computed directly, so the tables equal the per-pixel ones
  // (tested for several geometries).
  pixel_range_.resize(size_t(width_) * width_);
  pixel_angle_.resize(size_t(width_) * width_);
  auto turnsCode = [](double raw) {  // turns * 65536 clockwise from forward, in [0, 65536]
    double turns = raw / (2.0 * M_PI);
    if (turns < 0) turns += 1.0;
    return turns * 65536.0;
  };
  auto angleCode = [&](double raw) { return static_cast<uint16_t>(roundHalfAway(turnsCode(raw)) & 0xffff); };
  auto put = [&](int v, int u, float range, uint32_t code) {
    const size_t i = size_t(v) * width_ + u;
    pixel_range_[i] = range;
    pixel_angle_[i] = static_cast<uint16_t>(code & 0xffff);
  };
  auto direct = [&](int v, int u) {
    const double x = (centre_ - v) * resolution_, y = (centre_ - u) * resolution_;
    put(v, u, static_cast<float>(std::hypot(x, y)), angleCode(std::atan2(-y, x)));
  };
  const int half = (width_ - 1) / 2;  // rows (columns) 0..half have x >= 0 (y >= 0)
  for (int v = 0; v <= half; ++v) {
    const double x = (centre_ - v) * resolution_;
    const int vm = width_ - 1 - v;
    for (int u = v; u <= half; ++u) {  // x >= y >= 0
      const double y = (centre_ - u) * resolution_;
      const int um = width_ - 1 - u;
      const double t = turnsCode(std::atan2(-y, x));
      if ((x == 0 && y == 0) || std::abs(t - std::floor(t) - 0.5) < 1e-6) {
        for (const auto& [a, b] : {std::pair{v, u}, {v, um}, {vm, u}, {vm, um}, {u, v}, {u, vm}, {um, v}, {um, vm}})
          direct(a, b);
        continue;
      }
      const float range = static_cast<float>(std::hypot(x, y));
      const uint32_t c = static_cast<uint32_t>(roundHalfAway(t));
      put(v, u, range, c);               // ( x,  y)
      put(v, um, range, 65536 - c);      // ( x, -y): -theta
      put(vm, u, range, 32768 - c);      // (-x,  y): pi - theta
      put(vm, um, range, 32768 + c);     // (-x, -y): pi + theta
      put(u, v, range, 49152 - c);       // ( y,  x): -theta - pi/2
      put(u, vm, range, c + 16384);      // ( y, -x): theta + pi/2
      put(um, v, range, c + 49152);      // (-y,  x): theta - pi/2
      put(um, vm, range, 16384 + 65536 - c);  // (-y, -x): pi/2 - theta
    }
  }
}

bool CartesianProjector::geometryChanged(const PolarScan& scan, double offset) const {
  if (scan.azimuths != azimuths_ || scan.bins != bins_ || scan.range_resolution != range_resolution_ ||
      std::abs(offset - offset_) > 1e-9)
    return true;
  const double tol = 0.1 * 2.0 * M_PI / std::max(1, scan.azimuths);
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

  // angle (1/65536 turn) -> fractional row, walking the sweep once.
  angle_row_.resize(65536);
  int lo = 0;
  for (int q = 0; q < 65536; ++q) {
    double phi = 2.0 * M_PI * q / 65536.0;
    while (phi < ang[0]) phi += 2.0 * M_PI;
    while (phi >= ang[n]) phi -= 2.0 * M_PI;
    if (phi < ang[lo]) lo = 0;  // wrapped past the sweep's start
    while (lo + 1 < n && ang[lo + 1] <= phi) ++lo;
    int row = lo;
    long w = roundHalfAway(256.0 * (phi - ang[row]) / (ang[row + 1] - ang[row]));
    if (w >= 256) {  // rounds onto the next row (row n is row 0 again)
      ++row;
      w = 0;
    }
    angle_row_[q] = (static_cast<uint32_t>(row) << 8) | static_cast<uint32_t>(std::clamp(w, 0L, 255L));
  }

  box_ = std::clamp(static_cast<int>(std::lround(resolution_ / scan.range_resolution)), 1, 255);
  const size_t bins = static_cast<size_t>(scan.bins);
  const uint32_t zero_row = static_cast<uint32_t>((n + 1) * bins);
  const size_t pixels = size_t(width_) * width_;
  offset_table_.resize(pixels);
  weight_table_.resize(pixels);
  const float inv_res = static_cast<float>(1.0 / scan.range_resolution);
  const float b0 = static_cast<float>(-offset / scan.range_resolution - 0.5);
  for (size_t i = 0; i < pixels; ++i) {
    const float fb = pixel_range_[i] * inv_res + b0;  // fractional bin
    const long bin = roundHalfAway(fb);
    if (fb < -0.5f || bin >= scan.bins) {
      offset_table_[i] = zero_row;
      weight_table_[i] = 0;
      continue;
    }
    const uint32_t rw = angle_row_[pixel_angle_[i]];
    offset_table_[i] = static_cast<uint32_t>(size_t(rw >> 8) * bins + size_t(std::max(0L, bin)));
    weight_table_[i] = static_cast<uint8_t>(rw & 0xff);
  }
}

namespace {
#if defined(__GNUC__) && defined(__x86_64__)
bool cpuHasAvx2() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2");
}

/// Eight pixels at a time with gathers; `pol` must be readable 3 bytes past its last row.
__attribute__((target("avx2"))) void remapAvx2(const uint8_t* pol, int bins, const uint32_t* off, const uint8_t* wt,
                                               uint8_t* out, int count) {
  const __m256i lowbyte = _mm256_set1_epi32(0xff), half = _mm256_set1_epi32(128);
  const int* base_a = reinterpret_cast<const int*>(pol);
  const int* base_b = reinterpret_cast<const int*>(pol + bins);
  int i = 0;
  for (; i + 8 <= count; i += 8) {
    const __m256i o = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(off + i));
    const __m256i a = _mm256_and_si256(_mm256_i32gather_epi32(base_a, o, 1), lowbyte);
    const __m256i b = _mm256_and_si256(_mm256_i32gather_epi32(base_b, o, 1), lowbyte);
    const __m256i w = _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(wt + i)));
    const __m256i r =
        _mm256_add_epi32(a, _mm256_srai_epi32(_mm256_add_epi32(_mm256_mullo_epi32(_mm256_sub_epi32(b, a), w), half), 8));
    const __m128i r16 = _mm_packus_epi32(_mm256_castsi256_si128(r), _mm256_extracti128_si256(r, 1));
    _mm_storel_epi64(reinterpret_cast<__m128i*>(out + i), _mm_packus_epi16(r16, r16));
  }
  for (; i < count; ++i) {
    const uint8_t* p = pol + off[i];
    const int a = p[0], b = p[bins];
    out[i] = static_cast<uint8_t>(a + (((b - a) * wt[i] + 128) >> 8));
  }
}

/// Centred box sums of `k` bins for bins [j, j1], 16 at a time, in the same 16-bit fixed point
/// as the SSE loop below (identical bytes). Returns the first bin not done.
__attribute__((target("avx2"))) int boxRowAvx2(const uint8_t* row, uint8_t* dst, int j, int j1, int left, int k,
                                               uint16_t inv16) {
  const __m256i inv = _mm256_set1_epi16(static_cast<short>(inv16)), rnd = _mm256_set1_epi16(short(k / 2));
  for (; j + 16 <= j1 + 1; j += 16) {
    __m256i sum = rnd;
    const uint8_t* src = row + j - left;
    for (int t = 0; t < k; ++t)
      sum = _mm256_add_epi16(sum, _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(src + t))));
    const __m256i avg = _mm256_mulhi_epu16(sum, inv);
    const __m256i packed = _mm256_permute4x64_epi64(_mm256_packus_epi16(avg, avg), 0xD8);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(dst + j), _mm256_castsi256_si128(packed));
  }
  return j;
}
#endif
}  // namespace

void CartesianProjector::remapRows(uint8_t* image, size_t image_step) const {
  const uint8_t* pol = polar_.data();
  const int bins = bins_;
  const uint32_t* off = offset_table_.data();
  const uint8_t* wt = weight_table_.data();
#if defined(__GNUC__) && defined(__x86_64__)
  static const bool avx2 = cpuHasAvx2();
  if (avx2 && use_simd_) {
    for (int v = 0; v < width_; ++v)
      remapAvx2(pol, bins, off + size_t(v) * width_, wt + size_t(v) * width_, image + v * image_step, width_);
    return;
  }
#endif
  for (int v = 0; v < width_; ++v) {
    uint8_t* out = image + v * image_step;
    const size_t base = size_t(v) * width_;
    for (int u = 0; u < width_; ++u) {
      const uint8_t* p = pol + off[base + u];
      const int a = p[0], b = p[bins], w = wt[base + u];
      out[u] = static_cast<uint8_t>(a + (((b - a) * w + 128) >> 8));
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
  polar_.resize(size_t(n + 3) * bins + 4);  // + 4: the gather reads 4 bytes at a time
  uint8_t* pol = polar_.data();
  const bool has_valid = scan.valid.size() == size_t(n);
  int last_valid = -1;
  if (has_valid)  // an invalid first row borrows from the last valid row of the sweep
    for (int a = n - 1; a >= 0 && last_valid < 0; --a)
      if (scan.valid[a]) last_valid = a;
  // Centred moving average over box_ bins (fewer at the ends), in fixed point.
  const int k = box_, left = (k - 1) / 2;
  const uint32_t inv = (65536u + k / 2) / k;
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
    // Interior bins (full window): sum of k shifted copies of the row, 8 bins at a time.
    const int j0 = left, j1 = bins - (k - left);  // [j0, j1] have full windows
    int j = j0;
#if defined(__GNUC__) && defined(__x86_64__)
    static const bool avx2 = cpuHasAvx2();
    if (avx2 && use_simd_) j = boxRowAvx2(row, dst, j, j1, left, k, static_cast<uint16_t>((65536 + k - 1) / k));
#endif
#if defined(__SSE4_1__)
    const __m128i inv16 = _mm_set1_epi16(static_cast<short>((65536 + k - 1) / k)), rnd = _mm_set1_epi16(short(k / 2));
    for (; j + 8 <= j1 + 1; j += 8) {
      __m128i sum = rnd;
      const uint8_t* src = row + j - left;
      for (int t = 0; t < k; ++t)
        sum = _mm_add_epi16(sum, _mm_cvtepu8_epi16(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(src + t))));
      const __m128i avg = _mm_mulhi_epu16(sum, inv16);
      _mm_storel_epi64(reinterpret_cast<__m128i*>(dst + j), _mm_packus_epi16(avg, avg));
    }
#endif
    for (; j <= j1; ++j) {
      uint32_t sum = 0;
      for (int t = 0; t < k; ++t) sum += row[j - left + t];
      dst[j] = static_cast<uint8_t>((sum * inv + 32768u) >> 16);
    }
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
  remapRows(image.data, image.step);
}

}  // namespace spinradar
