// Alternating-chirp Doppler from one scan: per-row range shift against the neighbours (which
// used the other chirp direction), then a robust cosine fit. See chirp_doppler.hpp.
#include "spinradar/diagnose/chirp_doppler.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <Eigen/Dense>
#include <opencv2/core.hpp>

#include "spinradar/diagnose/stats.hpp"

namespace spinradar::diagnose {

namespace {

struct Work {
  std::vector<uint8_t> column;
  std::vector<float> threshold;
  std::vector<int16_t> floor;
  cv::Mat x, ref, fx, fref, prod, corr;  // rows x padded length
};
Work& work() {
  thread_local Work w;  // a folder of scans reuses the buffers
  return w;
}

/// One row's measurement: shift d = r_row - r_neighbours (m) at azimuth phi.
struct RowShift {
  int row;
  double phi;
  double d;
  double weight;
  double parity;  // +1: row is a down chirp, -1: up chirp
};

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  auto mid = v.begin() + v.size() / 2;
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

/// Robust weighted fit of y = A cos phi - B sin phi + C: deterministic RANSAC start, then
/// Cauchy IRLS with a MAD scale; covariance inflated for correlation between neighbouring rows.
ChirpShiftFit robustFit(const std::vector<RowShift>& m, const std::vector<double>& y, double res) {
  ChirpShiftFit f;
  const int n = int(m.size());
  if (n < 6) return f;
  Eigen::MatrixXd X(n, 3);
  Eigen::VectorXd Y(n), w(n);
  for (int i = 0; i < n; ++i) {
    X(i, 0) = std::cos(m[i].phi);
    X(i, 1) = -std::sin(m[i].phi);
    X(i, 2) = 1.0;
    Y(i) = y[i];
    w(i) = m[i].weight;
  }
  // RANSAC start: moving objects and ambiguous correlation peaks give gross outliers.
  Eigen::Vector3d best = Eigen::Vector3d::Zero();
  double best_score = -1;
  const double thr0 = 3.0 * res;
  std::mt19937 rng(12345);
  std::uniform_int_distribution<int> pick(0, n - 1);
  for (int it = 0; it < 300; ++it) {
    int i = pick(rng), j = pick(rng), k = pick(rng);
    if (i == j || j == k || i == k) continue;
    Eigen::Matrix3d A;
    A << X.row(i), X.row(j), X.row(k);
    Eigen::Vector3d rhs(Y(i), Y(j), Y(k));
    Eigen::FullPivLU<Eigen::Matrix3d> lu(A);
    if (!lu.isInvertible()) continue;
    Eigen::Vector3d beta = lu.solve(rhs);
    double score = (((Y - X * beta).array().abs() < thr0).cast<double>() * w.array()).sum();
    if (score > best_score) {
      best_score = score;
      best = beta;
    }
  }
  Eigen::Vector3d beta = best;
  Eigen::VectorXd r(n), W(n);
  double sigma = res;
  for (int it = 0; it < 30; ++it) {
    r = Y - X * beta;
    std::vector<double> ar(n);
    for (int i = 0; i < n; ++i) ar[i] = std::abs(r(i));
    sigma = std::max(1.4826 * median(ar), 0.1 * res);
    const double c = 2.385 * sigma;
    for (int i = 0; i < n; ++i) W(i) = w(i) / (1.0 + (r(i) / c) * (r(i) / c));
    Eigen::Matrix3d H = X.transpose() * W.asDiagonal() * X;
    Eigen::Vector3d g = X.transpose() * (W.array() * Y.array()).matrix();
    Eigen::Vector3d next = H.ldlt().solve(g);
    const bool done = (next - beta).norm() < 1e-6 * res;
    beta = next;
    if (done) break;
  }
  r = Y - X * beta;
  Eigen::Matrix3d H = X.transpose() * W.asDiagonal() * X;
  double s2 = 0, rms = 0;
  int inl = 0;
  for (int i = 0; i < n; ++i) {
    s2 += W(i) * r(i) * r(i);
    if (std::abs(r(i)) < 3 * sigma) {
      rms += r(i) * r(i);
      ++inl;
    }
  }
  // Weights are relative (correlation quality x Cauchy): the WLS variance factor absorbs their scale.
  s2 /= std::max(1, n - 3);
  // Lag-1 correlation of residuals of adjacent rows (they share rows in the measurement).
  double num = 0, den = 0;
  for (int i = 0; i < n; ++i) {
    if (std::abs(r(i)) >= 3 * sigma) continue;
    den += r(i) * r(i);
    if (i + 1 < n && m[i + 1].row == m[i].row + 1 && std::abs(r(i + 1)) < 3 * sigma) num += r(i) * r(i + 1);
  }
  const double rho = den > 0 ? num / den : 0.0;
  f.inflation = std::max(1.0, 1.0 + 2.0 * rho);
  Eigen::Matrix3d cov = H.inverse() * s2 * f.inflation;
  f.a = beta(0);
  f.b = beta(1);
  f.c = beta(2);
  f.sa = std::sqrt(std::max(0.0, cov(0, 0)));
  f.sb = std::sqrt(std::max(0.0, cov(1, 1)));
  f.sc = std::sqrt(std::max(0.0, cov(2, 2)));
  f.cov_ab = cov(0, 1);
  Eigen::Matrix2d cab = cov.topLeftCorner<2, 2>();
  Eigen::Vector2d ab(f.a, f.b);
  f.chi2 = cab.determinant() > 0 ? ab.dot(cab.ldlt().solve(ab)) : 0.0;
  f.p = chi2Sf(f.chi2, 2);
  f.residual_rms = inl > 0 ? std::sqrt(rms / inl) : 0.0;
  f.robust_sigma = sigma;
  f.inliers = inl;
  return f;
}

double r4(double v, double scale = 1e4) { return std::round(v * scale) / scale; }

}  // namespace

double ChirpShiftFit::amplitude() const { return std::hypot(a, b); }

double ChirpShiftFit::amplitudeSigma() const {
  const double amp = amplitude();
  if (amp <= 0) return std::sqrt(0.5 * (sa * sa + sb * sb));
  const double ga = a / amp, gb = b / amp;
  return std::sqrt(std::max(0.0, ga * ga * sa * sa + 2 * ga * gb * cov_ab + gb * gb * sb * sb));
}

nlohmann::json ChirpShiftFit::toJson() const {
  return {{"a_m", r4(a)},           {"b_m", r4(b)},          {"c_m", r4(c)},
          {"a_sigma_m", r4(sa, 1e5)}, {"b_sigma_m", r4(sb, 1e5)}, {"c_sigma_m", r4(sc, 1e5)},
          {"amplitude_m", r4(amplitude())}, {"amplitude_sigma_m", r4(amplitudeSigma(), 1e5)},
          {"chi2", r4(chi2, 100)},  {"p_value", p},          {"residual_rms_m", r4(residual_rms)},
          {"robust_sigma_m", r4(robust_sigma)}, {"variance_inflation", r4(inflation, 1000)},
          {"inliers", inliers}};
}

nlohmann::json ChirpDopplerResult::toJson() const {
  nlohmann::json j = {
      {"detected", detected},
      {"verdict", verdict},
      {"chirp_source", chirp_source},
      {"sign_ambiguous", sign_ambiguous},
      {"rows_total", rows_total},
      {"rows_measured", rows_measured},
      {"rows_used", rows_used},
      {"range_resolution_m", range_resolution},
      {"shift_model", "r_down - r_up = 2 beta (vx cos phi - vy sin phi) + c"},
      {"fit", fit.toJson()},
      {"control_non_alternating", control.toJson()},
      {"beta_v_m", r4(beta_v)},
      {"beta_v_sigma_m", r4(beta_v_sigma, 1e5)},
      {"direction_rad", r4(direction)},
      {"direction_sigma_rad", r4(direction_sigma)},
      {"chirp_range_bias_m", r4(fit.c)},
      {"chirp_range_bias_sigma_m", r4(fit.sc, 1e5)},
  };
  if (beta_given) {
    j["beta_given_s"] = *beta_given;
    j["velocity"] = {{"vx_mps", r4(*vx, 1e3)},           {"vy_mps", r4(*vy, 1e3)},
                     {"vx_sigma_mps", r4(*vx_sigma, 1e4)}, {"vy_sigma_mps", r4(*vy_sigma, 1e4)},
                     {"speed_mps", r4(*speed, 1e3)},     {"speed_sigma_mps", r4(*speed_sigma, 1e4)}};
  }
  if (speed_given) {
    j["speed_given_mps"] = *speed_given;
    j["beta_s"] = r4(*beta, 1e5);
    j["beta_sigma_s"] = r4(*beta_sigma, 1e6);
  }
  return j;
}

ChirpDopplerResult estimateChirpDoppler(const PolarScan& scan, const ChirpDopplerOptions& o) {
  if (scan.empty()) throw std::invalid_argument("chirp-doppler: empty scan");
  if (scan.power.size() != size_t(scan.azimuths) * scan.bins || int(scan.azimuth.size()) != scan.azimuths)
    throw std::invalid_argument("chirp-doppler: scan arrays do not match azimuths x bins");
  if (!(scan.range_resolution > 0)) throw std::invalid_argument("chirp-doppler: range_resolution must be > 0");
  if (!(o.max_shift > 0)) throw std::invalid_argument("chirp-doppler: max_shift must be > 0");
  if (!(o.min_range >= 0) || !(o.max_range > o.min_range))
    throw std::invalid_argument("chirp-doppler: need 0 <= min_range < max_range");
  if (o.beta && !(*o.beta > 0)) throw std::invalid_argument("chirp-doppler: beta must be > 0 s");
  if (o.speed && !(*o.speed > 0)) throw std::invalid_argument("chirp-doppler: speed must be > 0 m/s");

  const int N = scan.azimuths, M = scan.bins;
  const double res = scan.range_resolution;
  ChirpDopplerResult out;
  out.rows_total = N;
  out.range_resolution = res;
  out.beta_given = o.beta;
  out.speed_given = o.speed;

  auto valid = [&](int a) { return scan.valid.size() != size_t(N) || scan.valid[a] != 0; };
  // Chirp direction: the scan's flags when they alternate, else row parity (even = up).
  bool flags = false;
  if (scan.chirp_up.size() == size_t(N)) {
    int flips = 0;
    for (int a = 1; a < N; ++a) flips += scan.chirp_up[a] != scan.chirp_up[a - 1];
    flags = flips >= (N - 1) * 9 / 10;
  }
  out.chirp_source = flags ? "chirp_up" : "row_parity";
  out.sign_ambiguous = !flags;
  auto isUp = [&](int a) { return flags ? scan.chirp_up[a] != 0 : a % 2 == 0; };

  const int b0 = std::clamp(int(std::ceil(scan.binOfRange(o.min_range))), 0, M);
  const int b1 = std::clamp(int(std::floor(scan.binOfRange(std::min(o.max_range, 1e7)))) + 1, b0, M);
  const int L = b1 - b0;
  const int K = std::max(2, int(std::ceil(o.max_shift / res)));
  if (L < 4 * K) throw std::invalid_argument("chirp-doppler: range window too short for max_shift");

  Work& w = work();
  // Noise floor per range bin over the rotation: median + robust spread (the floor follows range).
  w.threshold.assign(L, 0.f);
  w.floor.assign(L, 0);
  w.column.resize(N);
  std::vector<uint8_t> dev(N);
  for (int b = 0; b < L; ++b) {
    int n = 0;
    for (int a = 0; a < N; ++a)
      if (valid(a)) w.column[n++] = scan.row(a)[b0 + b];
    if (n == 0) continue;
    auto mid = w.column.begin() + n / 2;
    std::nth_element(w.column.begin(), mid, w.column.begin() + n);
    const int med = *mid;
    w.floor[b] = int16_t(med);
    for (int i = 0; i < n; ++i) dev[i] = uint8_t(std::abs(int(w.column[i]) - med));
    auto dmid = dev.begin() + n / 2;
    std::nth_element(dev.begin(), dmid, dev.begin() + n);
    w.threshold[b] = float(med + std::max(o.min_floor_margin, o.floor_sigmas * 1.4826 * *dmid));
  }
  // Smooth the threshold along range: its bin-to-bin jitter (integer medians) is common to all
  // rows, and noise poking through it would correlate at zero lag and bias small shifts to 0.
  {
    const int h = 32;
    std::vector<double> cum(L + 1, 0.0);
    for (int b = 0; b < L; ++b) cum[b + 1] = cum[b] + w.threshold[b];
    for (int b = 0; b < L; ++b) {
      const int lo = std::max(0, b - h), hi = std::min(L, b + h + 1);
      w.threshold[b] = float((cum[hi] - cum[lo]) / (hi - lo));
    }
  }

  const int P = cv::getOptimalDFTSize(L + K + 1);
  w.x.create(N, P, CV_32F);
  w.ref.create(N, P, CV_32F);
  w.x.setTo(0);
  w.ref.setTo(0);
  std::vector<double> energy(N, 0.0);
  for (int a = 0; a < N; ++a) {
    if (!valid(a)) continue;
    const uint8_t* p = scan.row(a) + b0;
    // The row's own floor level (per-azimuth gain jitter) as the median of its offsets from the
    // per-bin floor: without it a whole smooth floor profile, which no Doppler shifts, would
    // leak above the threshold on loud rows and pull the correlation peak towards zero lag.
    int hist[511] = {};
    for (int b = 0; b < L; ++b) ++hist[int(p[b]) - w.floor[b] + 255];
    int offset = 0;
    for (int i = 0, acc = 0; i < 511; ++i)
      if ((acc += hist[i]) * 2 >= L) {
        offset = i - 255;
        break;
      }
    float* x = w.x.ptr<float>(a);
    double e = 0;
    for (int b = 0; b < L; ++b) {
      const float v = std::max(0.f, float(p[b]) - w.threshold[b] - float(offset));
      x[b] = v;
      e += double(v) * v;
    }
    energy[a] = e;
  }
  // Reference of row a: mean of its neighbours, which used the other chirp direction. Their
  // mean also cancels the linear change of the scene with azimuth.
  std::vector<char> usable(N, 0);
  std::vector<double> ref_energy(N, 0.0);
  for (int a = 1; a + 1 < N; ++a) {
    if (!valid(a) || !valid(a - 1) || !valid(a + 1)) continue;
    const bool up = isUp(a);
    if (isUp(a - 1) == up || isUp(a + 1) == up) continue;
    if (energy[a] <= 0 || energy[a - 1] <= 0 || energy[a + 1] <= 0) continue;
    const float* x0 = w.x.ptr<float>(a - 1);
    const float* x2 = w.x.ptr<float>(a + 1);
    float* r = w.ref.ptr<float>(a);
    double e = 0;
    for (int b = 0; b < L; ++b) {
      r[b] = 0.5f * (x0[b] + x2[b]);
      e += double(r[b]) * r[b];
    }
    ref_energy[a] = e;
    usable[a] = 1;
  }
  cv::dft(w.x, w.fx, cv::DFT_ROWS);
  cv::dft(w.ref, w.fref, cv::DFT_ROWS);
  // corr[k] = sum_n x[n + k] ref[n]: peak at k = (range of row) - (range of neighbours) in bins.
  cv::mulSpectrums(w.fx, w.fref, w.prod, cv::DFT_ROWS, true);
  cv::idft(w.prod, w.corr, cv::DFT_ROWS | cv::DFT_SCALE | cv::DFT_REAL_OUTPUT);

  std::vector<RowShift> meas;
  meas.reserve(N);
  for (int a = 1; a + 1 < N; ++a) {
    if (!usable[a]) continue;
    const float* c = w.corr.ptr<float>(a);
    auto at = [&](int k) { return double(c[k >= 0 ? k : P + k]); };
    int kbest = 0;
    double vbest = -1e300;
    for (int k = -K; k <= K; ++k)
      if (at(k) > vbest) {
        vbest = at(k);
        kbest = k;
      }
    if (kbest <= -K || kbest >= K) continue;  // at the edge of the search: not a peak
    const double q = vbest / std::sqrt(energy[a] * ref_energy[a]);
    if (!(q >= o.min_correlation)) continue;
    const double ym = at(kbest - 1), y0 = vbest, yp = at(kbest + 1);
    const double den = ym - 2 * y0 + yp;
    const double delta = den < 0 ? std::clamp(0.5 * (ym - yp) / den, -0.5, 0.5) : 0.0;
    meas.push_back({a, scan.azimuth[a], (kbest + delta) * res, std::min(q, 1.0), isUp(a) ? -1.0 : 1.0});
  }
  out.rows_measured = int(meas.size());

  std::vector<double> s(meas.size()), d(meas.size());
  for (size_t i = 0; i < meas.size(); ++i) {
    d[i] = meas[i].d;
    s[i] = meas[i].parity * meas[i].d;  // r_down - r_up
  }
  out.fit = robustFit(meas, s, res);
  out.control = robustFit(meas, d, res);
  out.rows_used = out.fit.inliers;

  const double amp = out.fit.amplitude(), samp = out.fit.amplitudeSigma();
  out.beta_v = 0.5 * amp;
  out.beta_v_sigma = 0.5 * samp;
  out.direction = std::atan2(out.fit.b, out.fit.a);
  if (amp > 0) {
    const double ha = -out.fit.b / (amp * amp), hb = out.fit.a / (amp * amp);
    out.direction_sigma = std::sqrt(std::max(
        0.0, ha * ha * out.fit.sa * out.fit.sa + 2 * ha * hb * out.fit.cov_ab + hb * hb * out.fit.sb * out.fit.sb));
  }
  out.detected = out.rows_measured >= 6 && out.fit.p < o.alpha && amp >= o.min_amplitude_bins * res &&
                 out.fit.chi2 > out.control.chi2;
  if (o.beta) {
    const double k = 0.5 / *o.beta;
    out.vx = out.fit.a * k;
    out.vy = out.fit.b * k;
    out.vx_sigma = out.fit.sa * k;
    out.vy_sigma = out.fit.sb * k;
    out.speed = amp * k;
    out.speed_sigma = samp * k;
  }
  if (o.speed) {
    out.beta = 0.5 * amp / *o.speed;
    out.beta_sigma = 0.5 * samp / *o.speed;
  }

  std::ostringstream v;
  v.setf(std::ios::fixed);
  v.precision(3);
  if (out.detected) {
    v << "alternating-chirp Doppler detected: beta*|v| = " << out.beta_v << " +- " << out.beta_v_sigma
      << " m, heading " << out.direction * 180 / M_PI << " deg";
    if (out.speed) v << ", |v| = " << *out.speed << " +- " << *out.speed_sigma << " m/s (beta " << *o.beta << " s)";
    if (out.beta) v << ", beta = " << *out.beta << " +- " << *out.beta_sigma << " s (|v| " << *o.speed << " m/s)";
    if (out.sign_ambiguous) v << "; chirp directions inferred from row parity: the sign of v is ambiguous";
  } else if (out.rows_measured < 6) {
    v << "not enough rows with signal (" << out.rows_measured << ") to test for alternating chirps";
  } else {
    v << "no alternating-chirp Doppler: beta*|v| = " << out.beta_v << " +- " << out.beta_v_sigma
      << " m (p = " << out.fit.p << ")";
    if (out.speed) v << ", |v| = " << *out.speed << " +- " << *out.speed_sigma << " m/s given beta " << *o.beta << " s";
  }
  out.verdict = v.str();
  return out;
}

}  // namespace spinradar::diagnose
