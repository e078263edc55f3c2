#include "spinradar/localization/rsd.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "spinradar/core/param_check.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace spinradar {

void RsdConfig::validate() const {
  checkParamRanges(*this, "rsd");
  if (rsd_slices % 2 != 0) throw std::invalid_argument("parameter 'rsd_slices' must be even");
  if (rsd_radius / rsd_resolution > 2000.0)
    throw std::invalid_argument("parameter 'rsd_radius' / 'rsd_resolution' exceeds 2000 px");
  if (rsd_rings > 127) throw std::invalid_argument("parameter 'rsd_rings' must be <= 127");
}

RsdExtractor::RsdExtractor(const RsdConfig& config) { setConfig(config); }

void RsdExtractor::setConfig(const RsdConfig& config) {
  config.validate();
  config_ = config;
  rebuildTables();
}

void RsdExtractor::rebuildTables() {
  const double res = config_.rsd_resolution, R = config_.rsd_radius;
  const int N = config_.rsd_rings, M = config_.rsd_slices;
  radius_px_ = static_cast<int>(std::ceil(R / res));
  lut_width_ = 2 * radius_px_ + 1;
  // Cells of half the radius: the 5 x 5 block around a cell covers every disc centred in it.
  cell_px_ = std::max(1, (radius_px_ + 1) / 2);
  const int W = lut_width_;
  ring_lut_.assign(static_cast<size_t>(W) * W, -1);
  slice_lut_.assign(static_cast<size_t>(W) * W, 0);
  for (int dy = -radius_px_; dy <= radius_px_; ++dy) {
    for (int dx = -radius_px_; dx <= radius_px_; ++dx) {
      const size_t idx = static_cast<size_t>(dy + radius_px_) * W + (dx + radius_px_);
      const double d = res * std::sqrt(double(dx) * dx + double(dy) * dy);
      if (d == 0.0 || d > R) continue;
      ring_lut_[idx] = static_cast<int8_t>(std::min(N - 1, static_cast<int>(d / R * N)));
      if (M > 0) {
        const double a = std::atan2(double(dy), double(dx)) + M_PI;  // [0, 2 pi]
        slice_lut_[idx] = static_cast<uint8_t>(static_cast<int>(a / (2.0 * M_PI) * M) % M);
      }
    }
  }
  const int K = M / 2;
  dft_cos_.assign(static_cast<size_t>(K) * std::max(M, 1), 0.f);
  dft_sin_.assign(dft_cos_.size(), 0.f);
  for (int k = 1; k <= K; ++k)
    for (int m = 0; m < M; ++m) {
      const double a = 2.0 * M_PI * k * m / M;
      dft_cos_[static_cast<size_t>(k - 1) * M + m] = static_cast<float>(std::cos(a));
      dft_sin_[static_cast<size_t>(k - 1) * M + m] = static_cast<float>(std::sin(a));
    }
}

void RsdExtractor::compute(const std::vector<Keypoint>& keypoints, cv::Mat& descriptors) {
  pts_.resize(keypoints.size());
  for (size_t i = 0; i < keypoints.size(); ++i) pts_[i] = {keypoints[i].x, keypoints[i].y};
  compute(pts_.data(), static_cast<int>(pts_.size()), descriptors);
}

void RsdExtractor::compute(const Eigen::Vector2d* points, int n, cv::Mat& descriptors) {
  const int N = config_.rsd_rings, M = config_.rsd_slices, D = config_.dimension();
  const int H = N + M;  // histogram entries per pixel
  descriptors.create(n, D, CV_32F);
  if (n == 0) return;
  if (n >= (1 << 21)) throw std::invalid_argument("RSD: more than 2^21 keypoints");

  // 1. Rasterise: sort (pixel, index) keys, collapse equal pixels.
  constexpr int64_t kOff = 1 << 20, kBits = 21;
  const double inv_res = 1.0 / config_.rsd_resolution;
  keys_.resize(n);
  for (int i = 0; i < n; ++i) {
    const double fx = points[i].x() * inv_res, fy = points[i].y() * inv_res;
    const int64_t ix = std::clamp<int64_t>(std::llround(std::isfinite(fx) ? fx : 0.0), -kOff + 1, kOff - 1);
    const int64_t iy = std::clamp<int64_t>(std::llround(std::isfinite(fy) ? fy : 0.0), -kOff + 1, kOff - 1);
    keys_[i] = (((iy + kOff) << kBits) + (ix + kOff)) << kBits | i;
  }
  std::sort(keys_.begin(), keys_.end());
  px_.clear();
  py_.clear();
  pixel_of_.resize(n);
  int64_t last = -1;
  for (int k = 0; k < n; ++k) {
    const int64_t pix = keys_[k] >> kBits;
    if (pix != last) {
      px_.push_back(static_cast<int>((pix & ((int64_t(1) << kBits) - 1)) - kOff));
      py_.push_back(static_cast<int>((pix >> kBits) - kOff));
      last = pix;
    }
    pixel_of_[keys_[k] & ((int64_t(1) << kBits) - 1)] = static_cast<int>(px_.size()) - 1;
  }
  const int U = static_cast<int>(px_.size());

  // 2. Bucket the occupied pixels into cells (counting sort).
  const auto [xmin_it, xmax_it] = std::minmax_element(px_.begin(), px_.end());
  const auto [ymin_it, ymax_it] = std::minmax_element(py_.begin(), py_.end());
  const int x0 = *xmin_it, y0 = *ymin_it;
  int cell = cell_px_;
  int cw = (*xmax_it - x0) / cell + 1, ch = (*ymax_it - y0) / cell + 1;
  // Far-flung points (not a radar scan): coarser cells keep the table bounded; the 5 x 5
  // block is then widened accordingly below.
  while (static_cast<int64_t>(cw) * ch > 4'000'000) {
    cell *= 2;
    cw = (*xmax_it - x0) / cell + 1;
    ch = (*ymax_it - y0) / cell + 1;
  }
  const int reach = (radius_px_ + cell - 1) / cell;
  cell_start_.assign(static_cast<size_t>(cw) * ch + 1, 0);
  cell_of_.resize(U);
  for (int u = 0; u < U; ++u) {
    cell_of_[u] = ((py_[u] - y0) / cell) * cw + (px_[u] - x0) / cell;
    ++cell_start_[cell_of_[u] + 1];
  }
  for (size_t c = 1; c < cell_start_.size(); ++c) cell_start_[c] += cell_start_[c - 1];
  cell_items_.resize(U);
  fill_.assign(cell_start_.begin(), cell_start_.end() - 1);
  for (int u = 0; u < U; ++u) cell_items_[fill_[cell_of_[u]]++] = u;

  // 3. Every unordered pair of occupied pixels within the radius, once.
  hist_.assign(static_cast<size_t>(U) * H, 0);
  const int R = radius_px_, W = lut_width_, WW = W * W;
  const int8_t* ring = ring_lut_.data();
  const uint8_t* slice = slice_lut_.data();
  int32_t* hist = hist_.data();
  for (int cy = 0; cy < ch; ++cy) {
    for (int cx = 0; cx < cw; ++cx) {
      const int ca = cy * cw + cx;
      const int a0 = cell_start_[ca], a1 = cell_start_[ca + 1];
      if (a0 == a1) continue;
      for (int oy = 0; oy <= reach; ++oy) {
        if (cy + oy >= ch) break;
        for (int ox = (oy == 0 ? 0 : -reach); ox <= reach; ++ox) {
          if (cx + ox < 0 || cx + ox >= cw) continue;
          const int cb = ca + oy * cw + ox;
          const int b0 = cell_start_[cb], b1 = cell_start_[cb + 1];
          for (int ia = a0; ia < a1; ++ia) {
            const int a = cell_items_[ia], ax = px_[a], ay = py_[a];
            int32_t* ha = hist + static_cast<size_t>(a) * H;
            for (int ib = (cb == ca ? ia + 1 : b0); ib < b1; ++ib) {
              const int b = cell_items_[ib];
              const int dx = px_[b] - ax, dy = py_[b] - ay;
              if (dx < -R || dx > R || dy < -R || dy > R) continue;
              const int idx = (dy + R) * W + (dx + R);
              const int r = ring[idx];
              if (r < 0) continue;
              int32_t* hb = hist + static_cast<size_t>(b) * H;
              ++ha[r];
              ++hb[r];
              if (M > 0) {
                ++ha[N + slice[idx]];
                ++hb[N + slice[WW - 1 - idx]];  // the offset seen from b is -(dx, dy)
              }
            }
          }
        }
      }
    }
  }

  // 4. Histograms -> descriptors per occupied pixel.
  desc_.assign(static_cast<size_t>(U) * D, 0.f);
  const float w = static_cast<float>(config_.rsd_azimuth_weight);
  for (int u = 0; u < U; ++u) {
    const int32_t* h = hist + static_cast<size_t>(u) * H;
    float* d = desc_.data() + static_cast<size_t>(u) * D;
    int count = 0;
    double sq = 0.0;
    for (int r = 0; r < N; ++r) {
      count += h[r];
      sq += double(h[r]) * h[r];
    }
    if (count == 0 || count < config_.rsd_min_neighbours) continue;
    const float inv = static_cast<float>(1.0 / std::sqrt(sq));
    for (int r = 0; r < N; ++r) d[r] = h[r] * inv;
    const float inv_count = w / static_cast<float>(count);
    for (int k = 0; k < M / 2; ++k) {
      const float* c = dft_cos_.data() + static_cast<size_t>(k) * M;
      const float* s = dft_sin_.data() + static_cast<size_t>(k) * M;
      float re = 0.f, im = 0.f;
      for (int m = 0; m < M; ++m) {
        re += c[m] * h[N + m];
        im += s[m] * h[N + m];
      }
      d[N + k] = std::sqrt(re * re + im * im) * inv_count;
    }
  }
  for (int i = 0; i < n; ++i)
    std::copy_n(desc_.data() + static_cast<size_t>(pixel_of_[i]) * D, D,
                descriptors.ptr<float>(i));
}

bool rsdValid(const cv::Mat& descriptors, int r) {
  // Valid rows carry a unit range histogram, so some entry is positive.
  const float* d = descriptors.ptr<float>(r);
  for (int c = 0; c < descriptors.cols; ++c)
    if (d[c] > 0.f) return true;
  return false;
}

namespace {

inline float sqDist(const float* a, const float* b, int D) {
  float s = 0.f;
  for (int k = 0; k < D; ++k) {
    const float t = a[k] - b[k];
    s += t * t;
  }
  return s;
}

}  // namespace

void RsdMatcher::match(const cv::Mat& d1, const cv::Mat& d2, double nndr, std::vector<Match>& out,
                       const Eigen::Vector2d* p1, const Eigen::Vector2d* p2, double gate_m) {
  out.clear();
  if (d1.empty() || d2.empty()) return;
  if (d1.type() != CV_32F || d2.type() != CV_32F || d1.cols != d2.cols)
    throw std::invalid_argument("RsdMatcher: descriptors must be CV_32F with equal widths");
  const int D = d1.cols;
  valid2_.clear();
  for (int j = 0; j < d2.rows; ++j)
    if (rsdValid(d2, j)) valid2_.push_back(j);
  const int V = static_cast<int>(valid2_.size());
  rows2_.resize(static_cast<size_t>(V) * D);
  for (int v = 0; v < V; ++v) std::copy_n(d2.ptr<float>(valid2_[v]), D, rows2_.data() + size_t(v) * D);
  const float ratio2 = static_cast<float>(nndr * nndr);
  const bool gated = p1 && p2 && gate_m > 0.0;

  auto consider = [&](const float* a, int v, float& best, float& second, int& best_v) {
    const float d = sqDist(a, rows2_.data() + static_cast<size_t>(v) * D, D);
    if (d < best) {
      second = best;
      best = d;
      best_v = v;
    } else if (d < second) {
      second = d;
    }
  };
  auto emit = [&](int i, float best, float second, int best_v) {
    if (best_v < 0) return;
    // A lone candidate (second = inf) passes: nothing competes with it.
    if (best < ratio2 * second) out.push_back({i, valid2_[best_v], std::sqrt(best)});
  };

  if (!gated) {
    // |a - b|^2 = |a|^2 + |b|^2 - 2 a.b; queries in blocks of 4 against d2 stored
    // feature-major, so the inner loop runs over contiguous candidates (vectorised) and each
    // candidate value loaded serves four queries.
    const int VP = (V + 3) & ~3;  // padded to whole SSE vectors; pads never win
    cols2_.assign(static_cast<size_t>(VP) * D, 0.f);
    norm2_.assign(VP, std::numeric_limits<float>::max());
    for (int v = 0; v < V; ++v) {
      float n2 = 0.f;
      for (int k = 0; k < D; ++k) {
        const float x = rows2_[static_cast<size_t>(v) * D + k];
        cols2_[static_cast<size_t>(k) * VP + v] = x;
        n2 += x * x;
      }
      norm2_[v] = n2;
    }
    int q[4];
    int nq = 0;
    auto flush = [&]() {
      if (nq == 0) return;
      const float* a[4];
      for (int j = 0; j < 4; ++j) a[j] = d1.ptr<float>(q[std::min(j, nq - 1)]);
      float best[4], second[4];
      int best_v[4];
      for (int j = 0; j < 4; ++j) {
        best[j] = second[j] = std::numeric_limits<float>::infinity();
        best_v[j] = -1;
      }
      // For 4 queries x 4 candidates, accumulate the dot products in registers over k;
      // d' = |b|^2 - 2 a.b ranks candidates like |a - b|^2.
      dots_.resize(static_cast<size_t>(D) * 4);
      for (int k = 0; k < D; ++k)
        for (int j = 0; j < 4; ++j) dots_[k * 4 + j] = -2.f * a[j][k];
      for (int v = 0; v < VP; v += 4) {
#if defined(__SSE2__)
        __m128 acc[4] = {_mm_loadu_ps(norm2_.data() + v), _mm_loadu_ps(norm2_.data() + v),
                         _mm_loadu_ps(norm2_.data() + v), _mm_loadu_ps(norm2_.data() + v)};
        for (int k = 0; k < D; ++k) {
          const __m128 x = _mm_loadu_ps(cols2_.data() + static_cast<size_t>(k) * VP + v);
          const float* w = dots_.data() + k * 4;
          acc[0] = _mm_add_ps(acc[0], _mm_mul_ps(_mm_set1_ps(w[0]), x));
          acc[1] = _mm_add_ps(acc[1], _mm_mul_ps(_mm_set1_ps(w[1]), x));
          acc[2] = _mm_add_ps(acc[2], _mm_mul_ps(_mm_set1_ps(w[2]), x));
          acc[3] = _mm_add_ps(acc[3], _mm_mul_ps(_mm_set1_ps(w[3]), x));
        }
        for (int j = 0; j < nq; ++j) {
          if (_mm_movemask_ps(_mm_cmplt_ps(acc[j], _mm_set1_ps(second[j]))) == 0) continue;
          alignas(16) float d[4];
          _mm_store_ps(d, acc[j]);
#else
        for (int j = 0; j < nq; ++j) {
          float d[4];
          for (int l = 0; l < 4; ++l) {
            d[l] = norm2_[v + l];
            for (int k = 0; k < D; ++k)
              d[l] += dots_[k * 4 + j] * cols2_[static_cast<size_t>(k) * VP + v + l];
          }
#endif
          for (int l = 0; l < 4; ++l) {
            if (d[l] < second[j]) {
              if (d[l] < best[j]) {
                second[j] = best[j];
                best[j] = d[l];
                best_v[j] = v + l;
              } else {
                second[j] = d[l];
              }
            }
          }
        }
      }
      for (int j = 0; j < nq; ++j) {
        float na = 0.f;
        for (int k = 0; k < D; ++k) na += a[j][k] * a[j][k];
        // Back to true squared distances (clamped: rounding can dip below zero).
        emit(q[j], std::max(best[j] + na, 0.f), std::max(second[j] + na, 0.f), best_v[j]);
      }
      nq = 0;
    };
    for (int i = 0; i < d1.rows; ++i) {
      if (!rsdValid(d1, i)) continue;
      q[nq++] = i;
      if (nq == 4) flush();
    }
    flush();
    return;
  }

  // Gated: bucket the valid rows of d2 by position in cells of the gate size.
  double xmin = 1e300, ymin = 1e300, xmax = -1e300, ymax = -1e300;
  for (int v = 0; v < V; ++v) {
    const Eigen::Vector2d& q = p2[valid2_[v]];
    xmin = std::min(xmin, q.x());
    xmax = std::max(xmax, q.x());
    ymin = std::min(ymin, q.y());
    ymax = std::max(ymax, q.y());
  }
  if (V == 0) return;
  double cs = gate_m;
  int cw = static_cast<int>((xmax - xmin) / cs) + 1, ch = static_cast<int>((ymax - ymin) / cs) + 1;
  while (static_cast<int64_t>(cw) * ch > 1'000'000) {
    cs *= 2.0;
    cw = static_cast<int>((xmax - xmin) / cs) + 1;
    ch = static_cast<int>((ymax - ymin) / cs) + 1;
  }
  auto cellOf = [&](const Eigen::Vector2d& q, int& cx, int& cy) {
    cx = static_cast<int>(std::floor((q.x() - xmin) / cs));
    cy = static_cast<int>(std::floor((q.y() - ymin) / cs));
  };
  cell_start_.assign(static_cast<size_t>(cw) * ch + 1, 0);
  for (int v = 0; v < V; ++v) {
    int cx, cy;
    cellOf(p2[valid2_[v]], cx, cy);
    ++cell_start_[cy * cw + cx + 1];
  }
  for (size_t c = 1; c < cell_start_.size(); ++c) cell_start_[c] += cell_start_[c - 1];
  cell_items_.resize(V);
  fill_.assign(cell_start_.begin(), cell_start_.end() - 1);
  for (int v = 0; v < V; ++v) {
    int cx, cy;
    cellOf(p2[valid2_[v]], cx, cy);
    cell_items_[fill_[cy * cw + cx]++] = v;
  }
  const double g2 = gate_m * gate_m;
  for (int i = 0; i < d1.rows; ++i) {
    if (!rsdValid(d1, i) || !p1[i].allFinite()) continue;
    const float* a = d1.ptr<float>(i);
    float best = std::numeric_limits<float>::infinity(), second = best;
    int best_v = -1;
    int cx, cy;
    cellOf(p1[i], cx, cy);
    for (int y = std::max(cy - 1, 0); y <= std::min(cy + 1, ch - 1); ++y)
      for (int x = std::max(cx - 1, 0); x <= std::min(cx + 1, cw - 1); ++x) {
        const int c = y * cw + x;
        for (int k = cell_start_[c]; k < cell_start_[c + 1]; ++k) {
          const int v = cell_items_[k];
          if ((p2[valid2_[v]] - p1[i]).squaredNorm() >= g2) continue;
          consider(a, v, best, second, best_v);
        }
      }
    emit(i, best, second, best_v);
  }
}

}  // namespace spinradar
