// Cen2018 (real-time variant) keypoint detector, azimuth peaks (CA-CFAR: detector_cfar.cpp).
//
// Speed: the Cen2018 score needs a 51-tap Gaussian and two exponentials per bin, about 80 M
// multiply-adds per 400 x 3768 scan if done everywhere. The score is bounded by
// y <= q + 2 e^{-1/2} sigma (each exponential-weighted term is at most sigma e^{-1/2}), so a bin can
// only pass y > zq sigma when q > (zq - 1.2131) sigma. Tighter: with d = q - p, y = q - d N(d) -
// p N(p), and for q > 0 the two terms cannot both reach their maximum, so max over p of y is
// about q + 0.61 sigma (computed once per zq, see candidateFactor): at zq = 3 bins need q > 2.35
// sigma instead of 1.79 sigma, which on the real Oxford scans leaves about a third of the
// candidates. The filter and the exponentials are only evaluated at those candidate bins (found
// 16 at a time with SSE2); the result is identical to evaluating every bin.
#include "spinradar/features/detector.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#if defined(__SSE4_1__)
#include <smmintrin.h>
#elif defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "for_each_above.hpp"
#include "row_stats.hpp"

namespace spinradar {

namespace {

using detail::forEachAbove;

constexpr int kKernelBits = 15;  // fixed-point Gaussian taps as int16 (pmaddwd), sum = 2^15
constexpr float kNoiseFallback = 0.034f * 255.f;  // sigma when a row has no sample below its mean
constexpr double kScoreBound = 1.2131;  // 2 e^{-1/2}, see the file comment

/// Smallest q / sigma at which the Cen2018 score can exceed zq sigma (never above the
/// 2 e^{-1/2} bound's zq - 1.2131). In sigma units y(q, p) = q - d e^{-d^2/2} - p e^{-p^2/2},
/// d = q - p; dy/dq = 1 - e^{-d^2/2} (1 - d^2) >= 0, so max_p y(q, p) grows with q and the first q
/// on a 0.02 grid where it reaches zq - 0.05 (p on a 0.01 grid: error < 0.01), one step back, is
/// a safe threshold.
double candidateFactor(double zq) {
  const double loose = zq - kScoreBound;
  auto ymax = [](double q) {
    double m = -1e300;
    for (double p = -8.0; p <= q + 8.0; p += 0.01) {
      const double d = q - p;
      m = std::max(m, q - d * std::exp(-0.5 * d * d) - p * std::exp(-0.5 * p * p));
    }
    return m;
  };
  thread_local double cached_zq = -1, cached = 0;  // ~1 ms a call; detectors share their zq
  if (zq == cached_zq) return cached;
  double factor = loose;
  for (double q = loose; q < zq + 1.0; q += 0.02)
    if (ymax(q) >= zq - 0.05) {
      factor = std::max(loose, q - 0.02);
      break;
    }
  cached_zq = zq;
  cached = factor;
  return factor;
}

int reflect101(int i, int n) {
  if (n == 1) return 0;
  while (i < 0 || i >= n) i = i < 0 ? -i : 2 * n - 2 - i;
  return i;
}

/// exp(x) for x <= 0 with ~2e-6 relative error; branch-free so that loops over it vectorize.
inline float fastExpNeg(float x) {
  x = std::max(x, -80.f);  // keeps the result a normal float: denormals are very slow
  const float t = x * 1.44269504f;
  const float fi = static_cast<float>(static_cast<int32_t>(t - 0.5f));  // round (t <= 0)
  const float f = t - fi;  // [-0.5, 0.5]
  float p = 1.33335581e-3f;
  p = p * f + 9.61812911e-3f;
  p = p * f + 5.55041087e-2f;
  p = p * f + 2.40226507e-1f;
  p = p * f + 6.93147181e-1f;
  p = p * f + 1.0f;
  int32_t bits;
  std::memcpy(&bits, &p, 4);
  bits += static_cast<int32_t>(fi) * (1 << 23);
  float r;
  std::memcpy(&r, &bits, 4);
  return r;
}

/// y = q (1 - e^{-(q-p)^2 k}) + p (e^{-(q-p)^2 k} - e^{-p^2 k}) for c < n (the Cen2018 score).
void cen2018Scores(const float* __restrict pv, const float* __restrict qv, float* __restrict yv, int n,
                   float k) {
  int c = 0;
#if defined(__SSE4_1__)
  auto exp4 = [](__m128 x) {
    x = _mm_max_ps(x, _mm_set1_ps(-80.f));
    const __m128 t = _mm_mul_ps(x, _mm_set1_ps(1.44269504f));
    const __m128 fi = _mm_round_ps(t, _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
    const __m128 f = _mm_sub_ps(t, fi);
    __m128 p = _mm_set1_ps(1.33335581e-3f);
    p = _mm_add_ps(_mm_mul_ps(p, f), _mm_set1_ps(9.61812911e-3f));
    p = _mm_add_ps(_mm_mul_ps(p, f), _mm_set1_ps(5.55041087e-2f));
    p = _mm_add_ps(_mm_mul_ps(p, f), _mm_set1_ps(2.40226507e-1f));
    p = _mm_add_ps(_mm_mul_ps(p, f), _mm_set1_ps(6.93147181e-1f));
    p = _mm_add_ps(_mm_mul_ps(p, f), _mm_set1_ps(1.0f));
    const __m128i e = _mm_slli_epi32(_mm_cvtps_epi32(fi), 23);
    return _mm_castsi128_ps(_mm_add_epi32(_mm_castps_si128(p), e));
  };
  const __m128 nk = _mm_set1_ps(-k), one = _mm_set1_ps(1.f);
  for (; c + 4 <= n; c += 4) {
    const __m128 p = _mm_loadu_ps(pv + c), q = _mm_loadu_ps(qv + c);
    const __m128 d = _mm_sub_ps(q, p);
    const __m128 nqp = exp4(_mm_mul_ps(_mm_mul_ps(d, d), nk));
    const __m128 npp = exp4(_mm_mul_ps(_mm_mul_ps(p, p), nk));
    const __m128 y = _mm_add_ps(_mm_mul_ps(q, _mm_sub_ps(one, nqp)), _mm_mul_ps(p, _mm_sub_ps(nqp, npp)));
    _mm_storeu_ps(yv + c, y);
  }
#endif
  for (; c < n; ++c) {
    const float p = pv[c], q = qv[c], d = q - p;
    const float nqp = fastExpNeg(-d * d * k), npp = fastExpNeg(-p * p * k);
    yv[c] = q * (1.f - nqp) + p * (nqp - npp);
  }
}

/// sum_k w[k] * x[k] for k < taps8 (a multiple of 8; w zero-padded, x readable that far).
inline int32_t dotU8I16(const uint8_t* x, const int16_t* w, int taps8) {
#if defined(__SSE4_1__)
  __m128i acc = _mm_setzero_si128();
  for (int k = 0; k < taps8; k += 8) {
    const __m128i xv = _mm_cvtepu8_epi16(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(x + k)));
    const __m128i wv = _mm_loadu_si128(reinterpret_cast<const __m128i*>(w + k));
    acc = _mm_add_epi32(acc, _mm_madd_epi16(xv, wv));
  }
  acc = _mm_add_epi32(acc, _mm_shuffle_epi32(acc, _MM_SHUFFLE(1, 0, 3, 2)));
  acc = _mm_add_epi32(acc, _mm_shuffle_epi32(acc, _MM_SHUFFLE(2, 3, 0, 1)));
  return _mm_cvtsi128_si32(acc);
#else
  int32_t acc = 0;
  for (int k = 0; k < taps8; ++k) acc += int32_t(w[k]) * int32_t(x[k]);
  return acc;
#endif
}

}  // namespace

Detector::Detector(const DetectorConfig& config) { setConfig(config); }

void Detector::setConfig(const DetectorConfig& config) {
  config.validate();
  config_ = config;
  rebuildKernel();
}

void Detector::rebuildKernel() {
  // As the authors' implementation: 3 * sigma taps, i.e. truncated at about +-1.5 sigma.
  radius_ = std::max(1, (3 * config_.sigma_gauss) / 2);
  const int size = 2 * radius_ + 1;
  std::vector<double> g(size);
  double s = 0;
  const double s2 = double(config_.sigma_gauss) * config_.sigma_gauss;
  for (int i = 0; i < size; ++i) s += g[i] = std::exp(-0.5 * (i - radius_) * (i - radius_) / s2);
  const int taps8 = (size + 7) / 8 * 8;
  kernel_.assign(taps8, 0);
  int32_t total = 0;
  for (int i = 0; i < size; ++i)
    total += kernel_[i] = static_cast<int16_t>(std::lround(g[i] / s * (1 << kKernelBits)));
  kernel_[radius_] = static_cast<int16_t>(kernel_[radius_] + ((1 << kKernelBits) - total));  // sum 1.0
  cand_factor_ = candidateFactor(config_.zq);
}

// Both detectors are public entry points: each checks the scan it is given.
void Detector::requireConsistent(const PolarScan& scan) {
  if (scan.power.size() != size_t(scan.azimuths) * scan.bins || scan.azimuth.size() != size_t(scan.azimuths) ||
      scan.stamp_ns.size() != size_t(scan.azimuths))
    throw std::invalid_argument("Detector: inconsistent PolarScan sizes");
}

void Detector::detect(const PolarScan& scan, std::vector<Keypoint>& out) {
  if (config_.detector == "cfar")
    detectCfar(scan, out);
  else
    detectCen2018(scan, out);
  if (config_.azimuth_peaks) keepAzimuthPeaks(scan, out);
}

void Detector::keepAzimuthPeaks(const PolarScan& scan, std::vector<Keypoint>& out) const {
  // A return shows in every row whose beam covers it (about +-2 rows), and each row's
  // keypoint sits on the row's angle, not on the target: keep the row where the peak power
  // (within +-2 bins) is highest across rows and move it to the parabola vertex through the
  // neighbouring rows (dB power ~ parabolic beam), its time with it.
  constexpr int kMaxPlateauRows = 16;
  const int N = scan.azimuths;
  if (N < 3 || out.empty()) return;
  const double step = 2.0 * M_PI / N;
  const double row_dt = double(scan.stamp_ns.back() - scan.stamp_ns.front()) / (N - 1);
  auto peakPower = [&](int a, int b) {
    a = (a % N + N) % N;
    if (!scan.valid.empty() && !scan.valid[a]) return -1;
    const uint8_t* row = scan.row(a);
    int m = 0;
    for (int j = std::max(0, b - 2); j <= std::min(scan.bins - 1, b + 2); ++j) m = std::max<int>(m, row[j]);
    return m;
  };
  size_t w = 0;
  for (size_t i = 0; i < out.size(); ++i) {
    Keypoint k = out[i];
    const int a = k.azimuth_index, b = int(std::lround(k.bin));
    const int pm = peakPower(a - 1, b), p0 = peakPower(a, b), pp = peakPower(a + 1, b);
    // Not an azimuthal peak: drop it. A plateau (saturation) is kept once, at its first row,
    // and moved to its centre.
    if (p0 < pm || p0 < pp || p0 == pm) continue;
    double d = 0.0;
    if (p0 == pp) {
      int len = 2;
      while (len < kMaxPlateauRows && peakPower(a + len, b) == p0) ++len;
      d = 0.5 * (len - 1);
    } else if (pm >= 0 && pp >= 0) {
      const double den = pm - 2.0 * p0 + pp;
      d = std::clamp(0.5 * (pm - pp) / den, -0.5, 0.5);  // den < 0: p0 > pm, p0 > pp
    }
    k.azimuth = scan.azimuth[a] + d * step;
    if (k.azimuth >= 2.0 * M_PI) k.azimuth -= 2.0 * M_PI;
    k.x = k.range * std::cos(k.azimuth);
    k.y = -k.range * std::sin(k.azimuth);
    k.stamp_ns += std::llround(d * row_dt);
    out[w++] = k;
  }
  out.resize(w);
}

void Detector::rangeWindow(const PolarScan& scan, int& b0, int& b1) const {
  const double off = config_.range_offset;
  b0 = std::max(0, static_cast<int>(std::ceil(scan.binOfRange(config_.min_range - off))));
  b1 = std::min(scan.bins - 1, static_cast<int>(std::floor(scan.binOfRange(config_.max_range - off))));
}

void Detector::emit(const PolarScan& scan, int a, double bin, float score,
                    std::vector<Keypoint>& out) const {
  const double r = scan.rangeOfBin(bin) + config_.range_offset;
  if (r < config_.min_range || r > config_.max_range) return;
  Keypoint k;
  k.range = r;
  k.azimuth = scan.azimuth[a];
  k.x = r * cos_[a];
  k.y = -r * sin_[a];
  k.stamp_ns = scan.stamp_ns[a];
  k.power = score;
  k.azimuth_index = a;
  k.bin = static_cast<float>(bin);
  out.push_back(k);
}

void Detector::detectCen2018(const PolarScan& scan, std::vector<Keypoint>& out) {
  out.clear();
  if (scan.empty()) return;
  requireConsistent(scan);
  const int n = scan.bins, R = radius_;
  int b0, b1;
  rangeWindow(scan, b0, b1);
  if (b0 > b1) return;
  cos_.resize(scan.azimuths);
  sin_.resize(scan.azimuths);
  const int taps8 = static_cast<int>(kernel_.size());
  padded_.assign(size_t(n) + 2 * R + taps8, 0);  // + taps8: the dot product may over-read zeros
  cand_.resize(n + 2);
  p_.resize(n + 2);
  y_.resize(n + 2);
  q_.resize(n + 2);
  const int16_t* w = kernel_.data();
  const float inv_scale = 1.0f / float(1 << kKernelBits);
  const bool has_valid = scan.valid.size() == size_t(scan.azimuths);

  for (int a = 0; a < scan.azimuths; ++a) {
    if (has_valid && !scan.valid[a]) continue;
    cos_[a] = std::cos(scan.azimuth[a]);
    sin_[a] = std::sin(scan.azimuth[a]);
    const uint8_t* row = scan.row(a);
    const uint32_t sum = detail::rowSum(row, n);
    const double mean = double(sum) / n;
    // Noise from the samples below the mean: sum (x - mean)^2 = s2 - 2 mean s1 + cnt mean^2.
    const int below = static_cast<int>(std::ceil(mean)) - 1;  // x < mean <=> x <= below
    uint32_t cnt = 0, s1 = 0, s2 = 0;
    if (below >= 0) detail::belowSums(row, n, static_cast<uint32_t>(below), cnt, s1, s2);
    float sigma = kNoiseFallback;
    if (cnt > 0) {
      const double ss = double(s2) - 2.0 * mean * s1 + cnt * mean * mean;
      sigma = static_cast<float>(std::sqrt(std::max(0.0, 2.0 * ss / cnt)));
      if (!(sigma > 0)) sigma = kNoiseFallback;
    }
    const float thres = static_cast<float>(config_.zq) * sigma;
    const double cand = mean + cand_factor_ * sigma - 1e-3;  // y > zq sigma needs q > factor sigma
    const int cand_t = score_every_bin_ ? -1 : static_cast<int>(std::floor(std::max(-1.0, std::min(255.0, cand))));

    // 1. candidate bins
    int nc = 0;
    int* ci = cand_.data();
    forEachAbove(row, b0, b1, cand_t, [&](int j) { ci[nc++] = j; });
    if (nc == 0) continue;
    // 2. Gaussian-smoothed row at the candidates (reflected borders, as BORDER_REFLECT_101)
    uint8_t* pd = padded_.data();
    std::memcpy(pd + R, row, n);
    for (int i = 1; i <= R; ++i) {
      pd[R - i] = row[reflect101(-i, n)];
      pd[R + n - 1 + i] = row[reflect101(n - 1 + i, n)];
    }
    const float fmean = static_cast<float>(mean);
    float* __restrict pv = p_.data();
    float* __restrict qv = q_.data();
    for (int c = 0; c < nc; ++c) {
      pv[c] = float(dotU8I16(pd + ci[c], w, taps8)) * inv_scale - fmean;
      qv[c] = float(row[ci[c]]) - fmean;
    }
    // 3. scores (branch-free, vectorised)
    const float inv2s2 = 0.5f / (sigma * sigma);
    float* yv = y_.data();
    cen2018Scores(pv, qv, yv, nc, inv2s2);
    auto scoreAt = [&](int j) {
      const float p = float(dotU8I16(pd + j, w, taps8)) * inv_scale - fmean;
      const float q = float(row[j]) - fmean;
      const float d = q - p;
      const float nqp = fastExpNeg(-d * d * inv2s2);
      return q * (1.f - nqp) + p * (nqp - fastExpNeg(-p * p * inv2s2));
    };
    // 4. runs of consecutive bins above the threshold -> their peak
    int last = -2, best = -1;
    float best_y = 0.f;
    auto finishRun = [&] {
      double bin = best;
      if (best > 0 && best + 1 < n) {  // parabola through the peak and its neighbours
        const float ym = scoreAt(best - 1), yp = scoreAt(best + 1);
        const float den = ym - 2.f * best_y + yp;
        if (den < 0.f) bin += std::clamp(0.5 * double(ym - yp) / den, -0.5, 0.5);
      }
      emit(scan, a, bin, best_y, out);
      best = -1;
    };
    for (int c = 0; c < nc; ++c) {
      if (!(yv[c] > thres)) continue;
      const int j = ci[c];
      if (j != last + 1 && best >= 0) finishRun();  // a gap ends the previous run
      if (best < 0 || yv[c] > best_y) {
        best = j;
        best_y = yv[c];
      }
      last = j;
    }
    if (best >= 0) finishRun();
  }
}

}  // namespace spinradar
