#include "spinradar/features/cartesian_tables.hpp"
#include "cpu_support.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>
#endif

namespace spinradar {

namespace {

/// std::lround without the library call (same result: v - trunc(v) is exact).
template <class T>
inline long roundHalfAway(T v) {
  T t = std::trunc(v);
  if (std::abs(v - t) >= T(0.5)) t += std::copysign(T(1), v);
  return static_cast<long>(t);
}

std::shared_ptr<CartesianPixelGeometry> buildPixelGeometry(double resolution, int width) {
  // hypot and atan2 for every pixel were most of a projector's construction (~0.25 G
  // instructions at 964 px). The grid is symmetric about the centre row and column and about
  // its diagonal: the eight pixels (+-x, +-y) and (+-y, +-x) have exactly the same coordinates up
  // to sign and order, so the same range (glibc's hypot takes |x|, |y| and orders them), and
  // angles of -theta, pi -+ theta and -+theta -+ pi/2: in 1/65536 turns, integer offsets of one
  // code. Each octant pixel is computed once. Its code is exactly what atan2 per pixel gives
  // unless turns * 65536 lies within 1e-6 of a rounding boundary (atan2 errs by < 1e-11 there);
  // such pixels, and the centre, are computed directly, so the tables equal the per-pixel ones
  // (tested for several geometries).
  auto g = std::make_shared<CartesianPixelGeometry>();
  g->resolution = resolution;
  g->width = width;
  const double centre = 0.5 * (width - 1);
  g->range.resize(size_t(width) * width);
  g->angle.resize(size_t(width) * width);
  float* pixel_range = g->range.data();
  uint16_t* pixel_angle = g->angle.data();
  auto turnsCode = [](double raw) {  // turns * 65536 clockwise from forward, in [0, 65536]
    double turns = raw / (2.0 * M_PI);
    if (turns < 0) turns += 1.0;
    return turns * 65536.0;
  };
  auto angleCode = [&](double raw) { return static_cast<uint16_t>(roundHalfAway(turnsCode(raw)) & 0xffff); };
  auto put = [&](int v, int u, float range, uint32_t code) {
    const size_t i = size_t(v) * width + u;
    pixel_range[i] = range;
    pixel_angle[i] = static_cast<uint16_t>(code & 0xffff);
  };
  auto direct = [&](int v, int u) {
    const double x = (centre - v) * resolution, y = (centre - u) * resolution;
    put(v, u, static_cast<float>(std::hypot(x, y)), angleCode(std::atan2(-y, x)));
  };
  const int half = (width - 1) / 2;  // rows (columns) 0..half have x >= 0 (y >= 0)
  for (int v = 0; v <= half; ++v) {
    const double x = (centre - v) * resolution;
    const int vm = width - 1 - v;
    for (int u = v; u <= half; ++u) {  // x >= y >= 0
      const double y = (centre - u) * resolution;
      const int um = width - 1 - u;
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
  return g;
}

#if defined(__GNUC__) && defined(__x86_64__)

/// The per-pixel loop of buildRemap, 8 pixels at a time with the same float operations (multiply
/// then add, round half away from zero, the same tests): identical tables (tested). Returns the
/// number of pixels done.
__attribute__((target("avx2"))) size_t remapPixelsAvx2(const float* range, const uint16_t* angle,
                                                        const uint32_t* angle_row, size_t pixels, float inv_res,
                                                        float b0, int nbins, uint32_t bins, uint32_t zero_row,
                                                        uint32_t* offsets, uint8_t* weights) {
  const __m256 vinv = _mm256_set1_ps(inv_res), vb0 = _mm256_set1_ps(b0), half = _mm256_set1_ps(0.5f);
  const __m256 minus_half = _mm256_set1_ps(-0.5f), fbins = _mm256_set1_ps(static_cast<float>(nbins));
  const __m256 sign_mask = _mm256_set1_ps(-0.0f), one = _mm256_set1_ps(1.0f);
  const __m256i vbins = _mm256_set1_epi32(static_cast<int>(bins)), vzero_row = _mm256_set1_epi32(static_cast<int>(zero_row));
  const __m256i lowbyte = _mm256_set1_epi32(0xff), zero = _mm256_setzero_si256();
  size_t i = 0;
  for (; i + 8 <= pixels; i += 8) {
    const __m256 fb = _mm256_add_ps(_mm256_mul_ps(_mm256_loadu_ps(range + i), vinv), vb0);
    __m256 t = _mm256_round_ps(fb, _MM_FROUND_TO_ZERO | _MM_FROUND_NO_EXC);
    const __m256 away = _mm256_cmp_ps(_mm256_andnot_ps(sign_mask, _mm256_sub_ps(fb, t)), half, _CMP_GE_OQ);
    t = _mm256_add_ps(t, _mm256_and_ps(away, _mm256_or_ps(one, _mm256_and_ps(sign_mask, fb))));
    const __m256 invalid = _mm256_or_ps(_mm256_cmp_ps(fb, minus_half, _CMP_LT_OQ), _mm256_cmp_ps(t, fbins, _CMP_GE_OQ));
    const __m256i bin = _mm256_max_epi32(_mm256_cvttps_epi32(t), zero);
    const __m256i code = _mm256_cvtepu16_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(angle + i)));
    const __m256i rw = _mm256_i32gather_epi32(reinterpret_cast<const int*>(angle_row), code, 4);
    __m256i off = _mm256_add_epi32(_mm256_mullo_epi32(_mm256_srli_epi32(rw, 8), vbins), bin);
    __m256i w = _mm256_and_si256(rw, lowbyte);
    const __m256i bad = _mm256_castps_si256(invalid);
    off = _mm256_blendv_epi8(off, vzero_row, bad);
    w = _mm256_andnot_si256(bad, w);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(offsets + i), off);
    const __m128i w16 = _mm_packus_epi32(_mm256_castsi256_si128(w), _mm256_extracti128_si256(w, 1));
    _mm_storel_epi64(reinterpret_cast<__m128i*>(weights + i), _mm_packus_epi16(w16, w16));
  }
  return i;
}
#endif

std::shared_ptr<CartesianRemap> buildRemap(const CartesianPixelGeometry& g, const PolarScan& scan, double offset,
                                           bool use_simd) {
  auto t = std::make_shared<CartesianRemap>();
  const int n = scan.azimuths;
  t->azimuths = n;
  t->bins = scan.bins;
  t->range_resolution = scan.range_resolution;
  t->offset = offset;
  t->angles.assign(scan.azimuth.begin(), scan.azimuth.end());

  // Unwrapped, increasing angles starting at row 0; row n (the copy of row 0) sits at +2 pi.
  std::vector<double> ang(n + 1);
  ang[0] = t->angles[0];
  bool monotonic = true;
  for (int a = 1; a < n; ++a) {
    double d = t->angles[a] - t->angles[a - 1];
    while (d < 0) d += 2.0 * M_PI;
    ang[a] = ang[a - 1] + d;
    monotonic &= d > 0;
  }
  ang[n] = ang[0] + 2.0 * M_PI;
  if (!monotonic || ang[n - 1] >= ang[n]) {  // not one increasing sweep: assume uniform steps
    for (int a = 0; a <= n; ++a) ang[a] = ang[0] + 2.0 * M_PI * a / n;
  }

  // angle (1/65536 turn) -> (row << 8) | weight of the next row, walking the sweep once.
  std::vector<uint32_t> angle_row(65536);
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
    angle_row[q] = (static_cast<uint32_t>(row) << 8) | static_cast<uint32_t>(std::clamp(w, 0L, 255L));
  }

  t->box = std::clamp(static_cast<int>(std::lround(g.resolution / scan.range_resolution)), 1, 255);
  const size_t bins = static_cast<size_t>(scan.bins);
  const uint32_t zero_row = static_cast<uint32_t>((n + 1) * bins);
  const size_t pixels = size_t(g.width) * g.width;
  t->offsets.resize(pixels);
  t->weights.resize(pixels);
  const float inv_res = static_cast<float>(1.0 / scan.range_resolution);
  const float b0 = static_cast<float>(-offset / scan.range_resolution - 0.5);
  size_t i = 0;
#if defined(__GNUC__) && defined(__x86_64__)
  static const bool avx2 = cpu::hasAvx2();
  if (avx2 && use_simd)
    i = remapPixelsAvx2(g.range.data(), g.angle.data(), angle_row.data(), pixels, inv_res, b0, scan.bins,
                        static_cast<uint32_t>(bins), zero_row, t->offsets.data(), t->weights.data());
#endif
  for (; i < pixels; ++i) {
    const float fb = g.range[i] * inv_res + b0;  // fractional bin
    const long bin = roundHalfAway(fb);
    if (fb < -0.5f || bin >= scan.bins) {
      t->offsets[i] = zero_row;
      t->weights[i] = 0;
      continue;
    }
    const uint32_t rw = angle_row[g.angle[i]];
    t->offsets[i] = static_cast<uint32_t>(size_t(rw >> 8) * bins + size_t(std::max(0L, bin)));
    t->weights[i] = static_cast<uint8_t>(rw & 0xff);
  }
  return t;
}

}  // namespace

bool CartesianRemap::fits(const PolarScan& scan, double offset_m) const {
  if (scan.azimuths != azimuths || scan.bins != bins || scan.range_resolution != range_resolution ||
      std::abs(offset_m - offset) > 1e-9)
    return false;
  const double tol = 0.1 * 2.0 * M_PI / std::max(1, scan.azimuths);
  for (int a = 0; a < scan.azimuths; ++a)
    if (std::abs(std::remainder(scan.azimuth[a] - angles[a], 2.0 * M_PI)) > tol) return false;
  return true;
}

CartesianTableCache::CartesianTableCache(double resolution, int width) : resolution_(resolution), width_(width) {
  if (!(resolution > 0) || width < 2)
    throw std::invalid_argument("CartesianProjector: resolution must be > 0 and width >= 2");
}

std::shared_ptr<const CartesianPixelGeometry> CartesianTableCache::pixelsLocked() {
  if (!pixels_) pixels_ = buildPixelGeometry(resolution_, width_);
  return pixels_;
}

std::shared_ptr<const CartesianPixelGeometry> CartesianTableCache::pixels() {
  std::lock_guard<std::mutex> lock(mutex_);
  return pixelsLocked();
}

std::shared_ptr<const CartesianRemap> CartesianTableCache::remapFor(const PolarScan& scan, double offset,
                                                                    bool& built) {
  std::lock_guard<std::mutex> lock(mutex_);  // held while building: the others wait for it
  built = !remap_ || !remap_->fits(scan, offset);
  if (built) {
    remap_ = buildRemap(*pixelsLocked(), scan, offset, use_simd_);
    ++builds_;
  }
  return remap_;
}

int CartesianTableCache::builds() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return builds_;
}

}  // namespace spinradar
