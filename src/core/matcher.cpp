// Brute-force Hamming matching with the ratio test. For 32-byte (ORB) descriptors the distance
// is four 64-bit XOR + POPCNT; four query rows are compared against each train row at once so
// that every train descriptor is loaded once per four queries. No allocation besides `out`.
#include "spinradar/core/matcher.hpp"

#include <climits>
#include <cstdint>
#include <cstring>
#include <stdexcept>

namespace spinradar {

namespace {

inline int popcount64(uint64_t v) { return __builtin_popcountll(v); }

struct Best2 {
  int d1 = INT_MAX, d2 = INT_MAX, j = -1;
  inline void push(int d, int idx) {
    if (d < d2) {
      if (d < d1) {
        d2 = d1;
        d1 = d;
        j = idx;
      } else {
        d2 = d;
      }
    }
  }
};

inline uint64_t load64(const uint8_t* p) {
  uint64_t v;
  std::memcpy(&v, p, 8);
  return v;
}

void emit(const Best2& b, int i, double nndr, std::vector<Match>& out) {
  // second == INT_MAX when d2 has a single row: no ratio test possible, no match.
  if (b.j >= 0 && b.d2 != INT_MAX && double(b.d1) < nndr * double(b.d2))
    out.push_back({i, b.j, static_cast<float>(b.d1)});
}

void match32(const cv::Mat& d1, const cv::Mat& d2, double nndr, std::vector<Match>& out) {
  const int n1 = d1.rows, n2 = d2.rows;
  int i = 0;
  for (; i + 4 <= n1; i += 4) {
    uint64_t q[4][4];
    for (int r = 0; r < 4; ++r)
      for (int w = 0; w < 4; ++w) q[r][w] = load64(d1.ptr<uint8_t>(i + r) + 8 * w);
    Best2 b[4];
    for (int j = 0; j < n2; ++j) {
      const uint8_t* t = d2.ptr<uint8_t>(j);
      const uint64_t t0 = load64(t), t1 = load64(t + 8), t2 = load64(t + 16), t3 = load64(t + 24);
      for (int r = 0; r < 4; ++r) {
        const int d = popcount64(q[r][0] ^ t0) + popcount64(q[r][1] ^ t1) + popcount64(q[r][2] ^ t2) +
                      popcount64(q[r][3] ^ t3);
        b[r].push(d, j);
      }
    }
    for (int r = 0; r < 4; ++r) emit(b[r], i + r, nndr, out);
  }
  for (; i < n1; ++i) {
    const uint8_t* s = d1.ptr<uint8_t>(i);
    const uint64_t q0 = load64(s), q1 = load64(s + 8), q2 = load64(s + 16), q3 = load64(s + 24);
    Best2 b;
    for (int j = 0; j < n2; ++j) {
      const uint8_t* t = d2.ptr<uint8_t>(j);
      b.push(popcount64(q0 ^ load64(t)) + popcount64(q1 ^ load64(t + 8)) + popcount64(q2 ^ load64(t + 16)) +
                 popcount64(q3 ^ load64(t + 24)),
             j);
    }
    emit(b, i, nndr, out);
  }
}

void matchGeneric(const cv::Mat& d1, const cv::Mat& d2, double nndr, std::vector<Match>& out) {
  const int bytes = d1.cols;
  for (int i = 0; i < d1.rows; ++i) {
    const uint8_t* s = d1.ptr<uint8_t>(i);
    Best2 b;
    for (int j = 0; j < d2.rows; ++j) {
      const uint8_t* t = d2.ptr<uint8_t>(j);
      int d = 0, k = 0;
      for (; k + 8 <= bytes; k += 8) d += popcount64(load64(s + k) ^ load64(t + k));
      for (; k < bytes; ++k) d += __builtin_popcount(unsigned(s[k] ^ t[k]));
      b.push(d, j);
    }
    emit(b, i, nndr, out);
  }
}

}  // namespace

void matchDescriptors(const cv::Mat& d1, const cv::Mat& d2, double nndr, std::vector<Match>& out) {
  out.clear();
  if (d1.empty() || d2.empty()) return;
  if (d1.type() != CV_8UC1 || d2.type() != CV_8UC1 || d1.cols != d2.cols)
    throw std::invalid_argument("matchDescriptors: both descriptor sets must be CV_8UC1 with equal widths");
  if (d1.cols == 32)
    match32(d1, d2, nndr, out);
  else
    matchGeneric(d1, d2, nndr, out);
}

}  // namespace spinradar
