// The detectors' scan for bins over a threshold, 16 bins at a time (private to src/features).
#pragma once

#include <cstdint>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace spinradar {
namespace detail {

/// Calls f(j) for every j in [b0, b1] with row[j] > t, in increasing order.
template <class F>
void forEachAbove(const uint8_t* row, int b0, int b1, int t, F&& f) {
  if (t >= 255) return;
  int j = b0;
  if (t < 0) {
    for (; j <= b1; ++j) f(j);
    return;
  }
#if defined(__SSE2__)
  const __m128i tv = _mm_set1_epi8(static_cast<char>(t + 1));
  for (; j + 16 <= b1 + 1; j += 16) {
    const __m128i x = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + j));
    // x >= t + 1  <=>  max(x, t + 1) == x (unsigned)
    unsigned m = static_cast<unsigned>(_mm_movemask_epi8(_mm_cmpeq_epi8(_mm_max_epu8(x, tv), x)));
    while (m) {
      f(j + __builtin_ctz(m));
      m &= m - 1;
    }
  }
#endif
  for (; j <= b1; ++j)
    if (row[j] > t) f(j);
}

}  // namespace detail
}  // namespace spinradar
