#include "spinradar/features/cartesian.hpp"
#include "cpu_support.hpp"

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

CartesianProjector::CartesianProjector(std::shared_ptr<CartesianTableCache> tables) {
  if (!tables) throw std::invalid_argument("CartesianProjector: no tables given");
  cache_ = std::move(tables);
  resolution_ = cache_->resolution();
  width_ = cache_->width();
  centre_ = 0.5 * (width_ - 1);
}

void CartesianProjector::setImageGeometry(double resolution, int width) {
  if (!(resolution > 0) || width < 2)
    throw std::invalid_argument("CartesianProjector: resolution must be > 0 and width >= 2");
  if (!cache_ || resolution != resolution_ || width != width_) {
    cache_ = std::make_shared<CartesianTableCache>(resolution, width);
    remap_.reset();
    resolution_ = resolution;
    width_ = width;
    centre_ = 0.5 * (width - 1);
  }
}

namespace {
#if defined(__GNUC__) && defined(__x86_64__)

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

#if !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // GCC 12's AVX-512 headers
#endif
/// As remapAvx2, 16 pixels at a time.
__attribute__((target("avx512f,avx512bw"))) void remapAvx512(const uint8_t* pol, int bins, const uint32_t* off,
                                                              const uint8_t* wt, uint8_t* out, int count) {
  const __m512i lowbyte = _mm512_set1_epi32(0xff), half = _mm512_set1_epi32(128);
  const int* base_a = reinterpret_cast<const int*>(pol);
  const int* base_b = reinterpret_cast<const int*>(pol + bins);
  int i = 0;
  for (; i + 16 <= count; i += 16) {
    const __m512i o = _mm512_loadu_si512(off + i);
    const __m512i a = _mm512_and_si512(_mm512_i32gather_epi32(o, base_a, 1), lowbyte);
    const __m512i b = _mm512_and_si512(_mm512_i32gather_epi32(o, base_b, 1), lowbyte);
    const __m512i w = _mm512_cvtepu8_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(wt + i)));
    const __m512i r =
        _mm512_add_epi32(a, _mm512_srai_epi32(_mm512_add_epi32(_mm512_mullo_epi32(_mm512_sub_epi32(b, a), w), half), 8));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + i), _mm512_cvtusepi32_epi8(_mm512_max_epi32(r, _mm512_setzero_si512())));
  }
  for (; i < count; ++i) {
    const uint8_t* p = pol + off[i];
    const int a = p[0], b = p[bins];
    out[i] = static_cast<uint8_t>(a + (((b - a) * wt[i] + 128) >> 8));
  }
}
#if !defined(__clang__)
#pragma GCC diagnostic pop
#endif

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
  const int bins = remap_->bins;
  const uint32_t* off = remap_->offsets.data();
  const uint8_t* wt = remap_->weights.data();
#if defined(__GNUC__) && defined(__x86_64__)
  static const bool avx2 = cpu::hasAvx2();
  static const bool avx512 = avx2 && cpu::hasAvx512bw();
  if (avx512 && simd_ >= 2) {
    for (int v = 0; v < width_; ++v)
      remapAvx512(pol, bins, off + size_t(v) * width_, wt + size_t(v) * width_, image + v * image_step, width_);
    return;
  }
  if (avx2 && simd_ >= 1) {
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
  if (!remap_ || !remap_->fits(scan, offset)) {
    bool built = false;
    remap_ = cache_->remapFor(scan, offset, built);
    builds_ += built;
  }

  const int n = scan.azimuths, bins = scan.bins;
  polar_.resize(size_t(n + 3) * bins + 4);  // + 4: the gather reads 4 bytes at a time
  uint8_t* pol = polar_.data();
  const bool has_valid = scan.valid.size() == size_t(n);
  int last_valid = -1;
  if (has_valid)  // an invalid first row borrows from the last valid row of the sweep
    for (int a = n - 1; a >= 0 && last_valid < 0; --a)
      if (scan.valid[a]) last_valid = a;
  // Centred moving average over `box` bins (fewer at the ends), in fixed point.
  const int k = remap_->box, left = (k - 1) / 2;
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
    static const bool avx2 = cpu::hasAvx2();
    if (avx2 && simd_ >= 1) j = boxRowAvx2(row, dst, j, j1, left, k, static_cast<uint16_t>((65536 + k - 1) / k));
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
