// Integer sums over one polar row for the Cen2018 noise estimate (private to src/features),
// 16 bins at a time with SSE2 (issue 19, sixteenth speed round): the compiler's own
// vectorisation of the scalar loops widened every byte to 32 bits and squared with pmulld.
// Integer sums, so the same values whichever way they are added.
#pragma once

#include <cstdint>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace spinradar {
namespace detail {

#if defined(__SSE2__)
inline uint32_t lane0(__m128i v) { return static_cast<uint32_t>(_mm_cvtsi128_si32(v)); }
#endif

/// The sum of row[0 .. n).
inline uint32_t rowSum(const uint8_t* row, int n) {
  uint32_t sum = 0;
  int j = 0;
#if defined(__SSE2__)
  __m128i acc = _mm_setzero_si128();
  for (; j + 16 <= n; j += 16)
    acc = _mm_add_epi64(acc, _mm_sad_epu8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(row + j)),
                                          _mm_setzero_si128()));
  sum = lane0(acc) + lane0(_mm_srli_si128(acc, 8));
#endif
  for (; j < n; ++j) sum += row[j];
  return sum;
}

/// Over the bins of row[0 .. n) with value <= below: their count, sum and sum of squares
/// (n up to 32768: the squares' 32-bit lanes cannot overflow).
inline void belowSums(const uint8_t* row, int n, uint32_t below, uint32_t& cnt, uint32_t& s1,
                      uint32_t& s2) {
  cnt = s1 = s2 = 0;
  if (below > 255) below = 255;
  int j = 0;
#if defined(__SSE2__)
  const __m128i bv = _mm_set1_epi8(static_cast<char>(below)), zero = _mm_setzero_si128();
  const __m128i one = _mm_set1_epi8(1);
  __m128i c = zero, s = zero, q = zero;
  for (; j + 16 <= n; j += 16) {
    const __m128i x = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + j));
    const __m128i in = _mm_cmpeq_epi8(_mm_min_epu8(x, bv), x);  // x <= below (unsigned)
    const __m128i xm = _mm_and_si128(x, in);
    c = _mm_add_epi64(c, _mm_sad_epu8(_mm_and_si128(in, one), zero));
    s = _mm_add_epi64(s, _mm_sad_epu8(xm, zero));
    const __m128i lo = _mm_unpacklo_epi8(xm, zero), hi = _mm_unpackhi_epi8(xm, zero);
    // Bytes widened to 16 bits (x < 256: positive as pmaddwd's signed words), squares summed
    // in pairs into 32-bit lanes.
    q = _mm_add_epi32(q, _mm_add_epi32(_mm_madd_epi16(lo, lo), _mm_madd_epi16(hi, hi)));
  }
  cnt = lane0(c) + lane0(_mm_srli_si128(c, 8));
  s1 = lane0(s) + lane0(_mm_srli_si128(s, 8));
  q = _mm_add_epi32(q, _mm_srli_si128(q, 8));
  q = _mm_add_epi32(q, _mm_srli_si128(q, 4));
  s2 = lane0(q);
#endif
  for (; j < n; ++j) {
    const uint32_t x = row[j];
    const uint32_t m = x <= below ? 1u : 0u;
    cnt += m;
    s1 += m * x;
    s2 += m * x * x;
  }
}

}  // namespace detail
}  // namespace spinradar
