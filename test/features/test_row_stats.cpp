// The detector's row sums (src/features/row_stats.hpp, SSE2) equal the plain loops they
// replace: random rows of every length around the 16-byte steps, thresholds from below the
// smallest to above the largest value, saturated rows.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "../../src/features/row_stats.hpp"

using namespace spinradar;

TEST(RowStats, SameSumsAsThePlainLoops) {
  std::mt19937 rng(7);
  int checked = 0;
  for (int n : {1, 15, 16, 17, 31, 33, 100, 3768, 6848}) {
    for (int trial = 0; trial < 40; ++trial) {
      std::vector<uint8_t> row(static_cast<size_t>(n));
      const int hi = trial % 4 == 0 ? 256 : 1 + static_cast<int>(rng() % 256);
      for (auto& x : row) x = static_cast<uint8_t>(trial % 10 == 9 ? 255 : rng() % hi);
      uint32_t sum = 0;
      for (uint8_t x : row) sum += x;
      EXPECT_EQ(detail::rowSum(row.data(), n), sum);
      for (uint32_t below : {0u, 1u, 37u, 128u, 254u, 255u, static_cast<uint32_t>(sum / n)}) {
        uint32_t cnt = 0, s1 = 0, s2 = 0;
        for (uint8_t v : row) {
          const uint32_t x = v, m = x <= below ? 1u : 0u;
          cnt += m;
          s1 += m * x;
          s2 += m * x * x;
        }
        uint32_t c = 7, a = 7, b = 7;
        detail::belowSums(row.data(), n, below, c, a, b);
        ASSERT_EQ(c, cnt) << "n " << n << " below " << below;
        ASSERT_EQ(a, s1) << "n " << n << " below " << below;
        ASSERT_EQ(b, s2) << "n " << n << " below " << below;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 2000);
}
