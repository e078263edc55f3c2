#include "spinradar/features/gaussian_blur.hpp"
#include "cpu_support.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include <opencv2/core.hpp>

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>
#endif

namespace spinradar {

namespace {

/// OpenCV's normalised Gaussian (getGaussianKernelBitExact, in doubles here).
std::vector<double> gaussian(int n, double sigma) {
  const int n2 = (n - 1) / 2;
  const double scale2 = -0.125 / (sigma * sigma);  // x below is twice the offset
  std::vector<double> k(n);
  double sum = 0;
  for (int i = 0, x = 1 - n; i < n2; ++i, x += 2) sum += k[i] = std::exp(double(x * x) * scale2);
  const double mul = 1.0 / (sum * 2 + 1);
  for (int i = 0; i < n2; ++i) k[n - 1 - i] = k[i] = k[i] * mul;
  k[n2] = mul;
  return k;
}

/// The fixed-point path's taps (getGaussianKernelFixedPoint_ED, 8 fraction bits): each outer
/// tap times 256 plus the rounding error carried from the tap before, rounded to nearest (ties
/// to even); the mirror tap the same; the centre whatever makes the sum 256.
std::vector<uint32_t> fixedPointTaps(const std::vector<double>& k) {
  const int n = static_cast<int>(k.size()), n2 = n / 2;
  std::vector<uint32_t> taps(n);
  double err = 0;
  uint32_t total = 0;
  for (int i = 0; i < n2; ++i) {
    const double adj = k[i] * 256.0 + err;
    const double v = std::nearbyint(adj);
    err = adj - v;
    taps[i] = taps[n - 1 - i] = static_cast<uint32_t>(v);
    total += static_cast<uint32_t>(v);
  }
  taps[n2] = 256 - 2 * total;
  return taps;
}

#define SPINRADAR_ALWAYS_INLINE inline __attribute__((always_inline))

// WholeImage: integer sums. Row sums in 1/256; `pad` holds the row with radius reflected pixels
// at each end. The symmetric 7-tap case (ORB's) is spelled out so that it vectorises.
SPINRADAR_ALWAYS_INLINE void rowSumsBody(const uint8_t* pad, const uint32_t* t, int k, uint32_t* out, int width) {
  if (k == 7) {
    const uint32_t t0 = t[0], t1 = t[1], t2 = t[2], t3 = t[3];
    for (int x = 0; x < width; ++x) {
      const uint8_t* p = pad + x;
      out[x] = t0 * uint32_t(p[0] + p[6]) + t1 * uint32_t(p[1] + p[5]) + t2 * uint32_t(p[2] + p[4]) + t3 * p[3];
    }
    return;
  }
  for (int x = 0; x < width; ++x) {
    uint32_t s = 0;
    for (int j = 0; j < k; ++j) s += t[j] * pad[x + j];
    out[x] = s;
  }
}

/// Column sums of k rows of row sums (1/65536), rounded half up to 8 bits (<= 255: the taps
/// sum to 256).
SPINRADAR_ALWAYS_INLINE void columnSumsBody(const uint32_t* const* r, const uint32_t* t, int k, uint8_t* out,
                                            int width) {
  if (k == 7) {
    const uint32_t t0 = t[0], t1 = t[1], t2 = t[2], t3 = t[3];
    const uint32_t *r0 = r[0], *r1 = r[1], *r2 = r[2], *r3 = r[3], *r4 = r[4], *r5 = r[5], *r6 = r[6];
    for (int x = 0; x < width; ++x)
      out[x] = static_cast<uint8_t>(
          (t0 * (r0[x] + r6[x]) + t1 * (r1[x] + r5[x]) + t2 * (r2[x] + r4[x]) + t3 * r3[x] + 32768u) >> 16);
    return;
  }
  for (int x = 0; x < width; ++x) {
    uint32_t s = 32768u;
    for (int j = 0; j < k; ++j) s += t[j] * r[j][x];
    out[x] = static_cast<uint8_t>(s >> 16);
  }
}

// View: OpenCV's float separable filter, in its order of operations (each step rounded to
// float as its SIMD code rounds it; `Fma` = its AVX2 build, multiply-adds fused). Row: the taps
// left to right, s = x0 k0, then s += xj kj. Column: s = centre kc, then s += (up + down) kj
// outwards; rounded half to even and saturated.
template <bool Fma>
SPINRADAR_ALWAYS_INLINE float mulAdd(float a, float b, float c) {
  if constexpr (Fma) return std::fma(a, b, c);
  return a * b + c;
}

template <bool Fma>
SPINRADAR_ALWAYS_INLINE void floatRowBody(const float* pad, const float* t, int k, float* out, int width) {
  for (int x = 0; x < width; ++x) {
    const float* p = pad + x;
    float s = p[0] * t[0];
    for (int j = 1; j < k; ++j) s = mulAdd<Fma>(p[j], t[j], s);
    out[x] = s;
  }
}

template <bool Fma>
SPINRADAR_ALWAYS_INLINE void floatColumnBody(const float* const* r, const float* t, int k, uint8_t* out, int width) {
  const int c = k / 2;
  for (int x = 0; x < width; ++x) {
    float s = t[c] * r[c][x];
    for (int j = 1; j <= c; ++j) s = mulAdd<Fma>(t[c + j], r[c + j][x] + r[c - j][x], s);
    const float v = std::nearbyint(s);
    out[x] = static_cast<uint8_t>(v < 0.f ? 0.f : (v > 255.f ? 255.f : v));
  }
}

void rowSums(const uint8_t* pad, const uint32_t* t, int k, uint32_t* out, int width) {
  rowSumsBody(pad, t, k, out, width);
}
void columnSums(const uint32_t* const* r, const uint32_t* t, int k, uint8_t* out, int width) {
  columnSumsBody(r, t, k, out, width);
}
void toFloatPlain(const uint8_t* p, float* out, int n) {
  for (int x = 0; x < n; ++x) out[x] = p[x];
}
void floatRow(const float* pad, const float* t, int k, float* out, int width) {
  floatRowBody<false>(pad, t, k, out, width);
}
void floatColumn(const float* const* r, const float* t, int k, uint8_t* out, int width) {
  floatColumnBody<false>(r, t, k, out, width);
}

#if defined(__GNUC__) && defined(__x86_64__)
__attribute__((target("avx2,fma"))) void rowSumsAvx2(const uint8_t* pad, const uint32_t* t, int k, uint32_t* out,
                                                     int width) {
  rowSumsBody(pad, t, k, out, width);
}
__attribute__((target("avx2,fma"))) void columnSumsAvx2(const uint32_t* const* r, const uint32_t* t, int k,
                                                        uint8_t* out, int width) {
  columnSumsBody(r, t, k, out, width);
}
/// The same operations 8 pixels at a time (lanes are independent: identical results); K > 0:
/// the kernel size, known at compile time (ORB's 7), else `k`.
template <int K>
__attribute__((target("avx2,fma"))) void floatRowAvx2T(const float* pad, const float* t, int k, float* out,
                                                       int width) {
  if (K > 0) k = K;
  int x = 0;
  for (; x + 16 <= width; x += 16) {  // two independent chains
    const float* p = pad + x;
    __m256 s = _mm256_mul_ps(_mm256_loadu_ps(p), _mm256_set1_ps(t[0]));
    __m256 u = _mm256_mul_ps(_mm256_loadu_ps(p + 8), _mm256_set1_ps(t[0]));
    for (int j = 1; j < k; ++j) {
      const __m256 tj = _mm256_set1_ps(t[j]);
      s = _mm256_fmadd_ps(_mm256_loadu_ps(p + j), tj, s);
      u = _mm256_fmadd_ps(_mm256_loadu_ps(p + 8 + j), tj, u);
    }
    _mm256_storeu_ps(out + x, s);
    _mm256_storeu_ps(out + x + 8, u);
  }
  floatRowBody<true>(pad + x, t, k, out + x, width - x);
}
__attribute__((target("avx2"))) void toFloatAvx2(const uint8_t* p, float* out, int n) {
  int x = 0;
  for (; x + 8 <= n; x += 8)
    _mm256_storeu_ps(out + x, _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(
                                  _mm_loadl_epi64(reinterpret_cast<const __m128i*>(p + x)))));
  for (; x < n; ++x) out[x] = p[x];
}
template <int K>
__attribute__((target("avx2,fma"))) void floatColumnAvx2T(const float* const* r, const float* t, int k, uint8_t* out,
                                                          int width) {
  if (K > 0) k = K;
  const int c = k / 2;
  int x = 0;
  for (; x + 8 <= width; x += 8) {
    __m256 s = _mm256_mul_ps(_mm256_set1_ps(t[c]), _mm256_loadu_ps(r[c] + x));
    for (int j = 1; j <= c; ++j)
      s = _mm256_fmadd_ps(_mm256_set1_ps(t[c + j]),
                          _mm256_add_ps(_mm256_loadu_ps(r[c + j] + x), _mm256_loadu_ps(r[c - j] + x)), s);
    const __m256i v = _mm256_cvtps_epi32(s);  // to nearest, ties to even
    const __m128i v16 = _mm_packs_epi32(_mm256_castsi256_si128(v), _mm256_extracti128_si256(v, 1));
    _mm_storel_epi64(reinterpret_cast<__m128i*>(out + x), _mm_packus_epi16(v16, v16));
  }
  const float* rest[63];
  for (int j = 0; j < k; ++j) rest[j] = r[j] + x;
  floatColumnBody<true>(rest, t, k, out + x, width - x);
}
#if !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // GCC 12's AVX-512 headers
#endif
/// And 16 at a time with AVX-512 (same operations per lane).
template <int K>
__attribute__((target("avx512f"))) void floatRowAvx512T(const float* pad, const float* t, int k, float* out,
                                                        int width) {
  if (K > 0) k = K;
  int x = 0;
  for (; x + 16 <= width; x += 16) {
    const float* p = pad + x;
    __m512 s = _mm512_mul_ps(_mm512_loadu_ps(p), _mm512_set1_ps(t[0]));
    for (int j = 1; j < k; ++j) s = _mm512_fmadd_ps(_mm512_loadu_ps(p + j), _mm512_set1_ps(t[j]), s);
    _mm512_storeu_ps(out + x, s);
  }
  floatRowBody<true>(pad + x, t, k, out + x, width - x);
}
template <int K>
__attribute__((target("avx512f"))) void floatColumnAvx512T(const float* const* r, const float* t, int k,
                                                           uint8_t* out, int width) {
  if (K > 0) k = K;
  const int c = k / 2;
  int x = 0;
  for (; x + 16 <= width; x += 16) {
    __m512 s = _mm512_mul_ps(_mm512_set1_ps(t[c]), _mm512_loadu_ps(r[c] + x));
    for (int j = 1; j <= c; ++j)
      s = _mm512_fmadd_ps(_mm512_set1_ps(t[c + j]),
                          _mm512_add_ps(_mm512_loadu_ps(r[c + j] + x), _mm512_loadu_ps(r[c - j] + x)), s);
    const __m512i v = _mm512_max_epi32(_mm512_cvtps_epi32(s), _mm512_setzero_si512());  // ties to even
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + x), _mm512_cvtusepi32_epi8(v));     // saturated
  }
  const float* rest[63];
  for (int j = 0; j < k; ++j) rest[j] = r[j] + x;
  floatColumnBody<true>(rest, t, k, out + x, width - x);
}
#if !defined(__clang__)
#pragma GCC diagnostic pop
#endif
void floatRowAvx512(const float* pad, const float* t, int k, float* out, int width) {
  (k == 7 ? floatRowAvx512T<7> : floatRowAvx512T<0>)(pad, t, k, out, width);
}
void floatColumnAvx512(const float* const* r, const float* t, int k, uint8_t* out, int width) {
  (k == 7 ? floatColumnAvx512T<7> : floatColumnAvx512T<0>)(r, t, k, out, width);
}
void floatRowAvx2(const float* pad, const float* t, int k, float* out, int width) {
  (k == 7 ? floatRowAvx2T<7> : floatRowAvx2T<0>)(pad, t, k, out, width);
}
void floatColumnAvx2(const float* const* r, const float* t, int k, uint8_t* out, int width) {
  (k == 7 ? floatColumnAvx2T<7> : floatColumnAvx2T<0>)(r, t, k, out, width);
}
#endif

}  // namespace

GaussianBlur8u::GaussianBlur8u(int ksize, double sigma, Path path) : ksize_(ksize), radius_(ksize / 2), path_(path) {
  if (ksize < 1 || ksize % 2 == 0 || ksize > 63 || !(sigma > 0) || !std::isfinite(sigma))
    throw std::invalid_argument("GaussianBlur8u: the kernel size must be odd, 1 to 63, and sigma > 0");
  const std::vector<double> k = gaussian(ksize, sigma);
  taps_ = fixedPointTaps(k);
  for (double v : k) float_taps_.push_back(static_cast<float>(v));  // OpenCV's CV_32F kernel
}

void GaussianBlur8u::apply(const cv::Mat& src, cv::Mat& dst) {
  if (src.type() != CV_8UC1 || src.empty()) throw std::invalid_argument("GaussianBlur8u: CV_8UC1 image expected");
  const int W = src.cols, H = src.rows, k = ksize_, r = radius_;
  dst.create(H, W, CV_8UC1);
  if (dst.data == src.data) throw std::invalid_argument("GaussianBlur8u: dst must not be src");
#if defined(__GNUC__) && defined(__x86_64__)
  static const bool avx2 = cpu::hasAvx2Fma();
  auto rows = avx2 ? rowSumsAvx2 : rowSums;
  auto columns = avx2 ? columnSumsAvx2 : columnSums;
  static const bool avx512_cpu = avx2 && cpu::hasAvx512f();
  const bool avx512 = avx512_cpu && simd_ >= 2;
  auto frows = avx512 ? floatRowAvx512 : avx2 && simd_ >= 1 ? floatRowAvx2 : floatRow;
  auto fcolumns = avx512 ? floatColumnAvx512 : avx2 && simd_ >= 1 ? floatColumnAvx2 : floatColumn;
  auto toFloat = avx2 ? toFloatAvx2 : toFloatPlain;
#else
  auto toFloat = toFloatPlain;
  auto rows = rowSums;
  auto columns = columnSums;
  auto frows = floatRow;
  auto fcolumns = floatColumn;
#endif
  const bool whole = path_ == Path::WholeImage;
  padded_.resize(size_t(W) + 2 * r);
  if (!whole) padded_float_.resize(padded_.size());
  if (whole)
    ring_.resize(size_t(k) * W);
  else
    float_ring_.resize(size_t(k) * W);
  uint32_t* ring = ring_.data();
  float* fring = float_ring_.data();
  // Row sums of source row y go to ring slot y % k. Output row y reads the rows y - r .. y + r,
  // reflected into [0, H): a window of at most k consecutive rows, so distinct slots.
  auto rowSumsOf = [&](int y) {
    const uint8_t* s = src.ptr<uint8_t>(y);
    uint8_t* p = padded_.data();
    std::memcpy(p + r, s, W);
    for (int j = 1; j <= r; ++j) {
      p[r - j] = s[cv::borderInterpolate(-j, W, cv::BORDER_REFLECT_101)];
      p[r + W - 1 + j] = s[cv::borderInterpolate(W - 1 + j, W, cv::BORDER_REFLECT_101)];
    }
    if (whole) {
      rows(p, taps_.data(), k, ring + size_t(y % k) * W, W);
    } else {
      float* pf = padded_float_.data();
      toFloat(p, pf, W + 2 * r);  // exact
      frows(pf, float_taps_.data(), k, fring + size_t(y % k) * W, W);
    }
  };
  const uint32_t* taps_rows[63];
  const float* ftaps_rows[63];
  int done = 0;  // source rows [0, done) have their row sums in the ring
  for (int y = 0; y < H; ++y) {
    for (; done < std::min(H, y + r + 1); ++done) rowSumsOf(done);
    for (int j = 0; j < k; ++j) {
      const size_t slot = size_t(cv::borderInterpolate(y - r + j, H, cv::BORDER_REFLECT_101) % k) * W;
      if (whole)  // (only the ring in use has storage)
        taps_rows[j] = ring + slot;
      else
        ftaps_rows[j] = fring + slot;
    }
    if (whole)
      columns(taps_rows, taps_.data(), k, dst.ptr<uint8_t>(y), W);
    else
      fcolumns(ftaps_rows, float_taps_.data(), k, dst.ptr<uint8_t>(y), W);
  }
}

}  // namespace spinradar
