#include "spinradar/estimation/mc_ransac.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "spinradar/core/lie.hpp"

namespace spinradar {

void setMotionFromVelocity(const Eigen::Vector3d& xi, const Eigen::Matrix3d& xi_cov,
                           double dt_ref, MotionEstimate& out) {
  out.velocity = xi;
  out.velocity_cov = xi_cov;
  const Eigen::Vector3d tau = dt_ref * xi;
  out.T_12 = se2::exp(tau);
  const Eigen::Matrix3d J = se2::xyYawJacobian(tau);
  out.T_12_cov = (dt_ref * dt_ref) * J * xi_cov * J.transpose();
}

Eigen::Matrix2d cartesianInformation(const Eigen::Vector2d& p, double range_sigma,
                                     double azimuth_sigma, double tangential_floor) {
  // H = d(x, y)/d(r, phi) = [[cos phi, -r sin phi], [-sin phi, -r cos phi]] (REP 103,
  // clockwise phi); H R H^T = sr^2 u u^T + (r sa)^2 w w^T with u = p/r radial and w its
  // normal, whose inverse is u u^T / sr^2 + w w^T / (r sa)^2 = a u u^T + b 1.
  const double r2 = std::max(p.squaredNorm(), 1.0);
  const double inv_t =
      1.0 / (r2 * azimuth_sigma * azimuth_sigma + tangential_floor * tangential_floor);
  const double inv_r = 1.0 / (range_sigma * range_sigma);
  const Eigen::Vector2d u = p / std::sqrt(r2);
  return (inv_r - inv_t) * u * u.transpose() + inv_t * Eigen::Matrix2d::Identity();
}

Eigen::Matrix2d cartesianCovariance(const Eigen::Vector2d& p, double range_sigma,
                                    double azimuth_sigma, double tangential_floor) {
  const double r2 = std::max(p.squaredNorm(), 1.0);
  const double vt = r2 * azimuth_sigma * azimuth_sigma + tangential_floor * tangential_floor;
  const double vr = range_sigma * range_sigma;
  const Eigen::Vector2d u = p / std::sqrt(r2);
  return (vr - vt) * u * u.transpose() + vt * Eigen::Matrix2d::Identity();
}

bool withinInlierGate(const Eigen::Vector2d& e, const Eigen::Vector2d& p,
                      double inlier_threshold, double azimuth_sigma) {
  const double thr2 = inlier_threshold * inlier_threshold;
  const double r2 = std::max(p.squaredNorm(), 1e-6);
  const double q = McRansac::kAzimuthQuantum * azimuth_sigma;
  const double inv_tan2 = 1.0 / (thr2 + q * q * r2);
  const double er2 = e.dot(p) * e.dot(p) / r2;
  return er2 * (1.0 / thr2 - inv_tan2) + e.squaredNorm() * inv_tan2 < 1.0;
}

McRansac::McRansac(const EstimatorConfig& config) : config_(config) {}

void McRansac::load(const std::vector<Keypoint>& k1, const std::vector<Keypoint>& k2,
                    const std::vector<Match>& matches) {
  const size_t M = matches.size();
  x1_.resize(M);
  y1_.resize(M);
  x2_.resize(M);
  y2_.resize(M);
  dt_.resize(M);
  ux_.resize(M);
  uy_.resize(M);
  inv_tan2_.resize(M);
  max_abs_dt_ = 0.0;
  const double thr2 = config_.inlier_threshold * config_.inlier_threshold;
  const double q2 = kAzimuthQuantum * kAzimuthQuantum * config_.azimuth_sigma * config_.azimuth_sigma;
  for (size_t i = 0; i < M; ++i) {
    const Keypoint& a = k1[matches[i].i1];
    const Keypoint& b = k2[matches[i].i2];
    x1_[i] = a.x;
    y1_[i] = a.y;
    x2_[i] = b.x;
    y2_[i] = b.y;
    dt_[i] = 1e-9 * static_cast<double>(b.stamp_ns - a.stamp_ns);  // Delta t_m
    max_abs_dt_ = std::max(max_abs_dt_, std::abs(dt_[i]));
    const double r2 = std::max(b.x * b.x + b.y * b.y, 1e-6), r = std::sqrt(r2);
    ux_[i] = b.x / r;
    uy_[i] = b.y / r;
    inv_tan2_[i] = 1.0 / (thr2 + q2 * r2);
  }
}

namespace {

/// Below this |dt omega| the Taylor polynomials of sin t / t and (1 - cos t)/t up to t^8
/// are accurate to < 3e-11 relative (next term t^10/10!): < 1e-8 m at 150 m.
constexpr double kPolyAngle = 0.5;

/// a = sin t / t, b = (1 - cos t) / t by polynomial (branch-free, vectorisable).
inline void polyCoefficients(double t, double& a, double& b) {
  const double t2 = t * t;
  a = 1.0 + t2 * (-1.0 / 6 + t2 * (1.0 / 120 + t2 * (-1.0 / 5040 + t2 / 362880)));
  b = t * (0.5 + t2 * (-1.0 / 24 + t2 * (1.0 / 720 + t2 * (-1.0 / 40320 + t2 / 3628800))));
}

/// g = exp(dt varpi^) p1 without forming the matrix (the per-match inner loop); also
/// returns the rotation's cos/sin.
inline Eigen::Vector2d transformPoint(const Eigen::Vector3d& varpi, double dt, double x,
                                      double y, double* cs = nullptr, double* sn = nullptr) {
  const double t = dt * varpi(2);
  double a, b, s, c;
  if (std::abs(t) < kPolyAngle) {
    polyCoefficients(t, a, b);
    s = t * a;
    c = 1.0 - t * b;
  } else {
    s = std::sin(t);
    c = std::cos(t);
    se2::vCoefficients(t, s, c, a, b);
  }
  if (cs) *cs = c;
  if (sn) *sn = s;
  const double rx = dt * varpi(0), ry = dt * varpi(1);
  return {c * x - s * y + a * rx - b * ry, s * x + c * y + b * rx + a * ry};
}

}  // namespace

bool McRansac::gaussNewton(const int* idx, int n, int iterations, Eigen::Vector3d& varpi,
                           Eigen::Matrix3d* info, double* chi2) const {
  if (n < 2) return false;
  const double sr = config_.range_sigma, sa = config_.azimuth_sigma;
  Eigen::Matrix3d A;
  Eigen::Vector3d b;
  double cost = 0.0;
  for (int it = 0; it < iterations; ++it) {
    A.setZero();
    b.setZero();
    cost = 0.0;
    for (int k = 0; k < n; ++k) {
      const int m = idx[k];
      const double dt = dt_[m];
      // g_bar = T_bar_m p_m1 and G_m = dt_m (g_bar)^odot. The paper takes
      // exp(dt (varpi + d)^) ~ exp(dt d^) T_bar_m, i.e. it drops the left Jacobian
      // J_l(dt varpi); since dt_m is nearly the same for all matches this only rescales the
      // normal equations and leaves their solution unchanged.
      const Eigen::Vector2d g = transformPoint(varpi, dt, x1_[m], y1_[m]);
      const Eigen::Vector2d e = Eigen::Vector2d(x2_[m], y2_[m]) - g;
      Eigen::Matrix<double, 2, 3> G = dt * se2::odot2(g);
      // R_cart = H R H^T evaluated at g_bar (the paper's H_m).
      const Eigen::Matrix2d W = cartesianInformation(g, sr, sa, tangential_floor_);
      const Eigen::Matrix<double, 3, 2> GtW = G.transpose() * W;
      A.noalias() += GtW * G;
      b.noalias() += GtW * e;
      cost += e.dot(W * e);
    }
    Eigen::LDLT<Eigen::Matrix3d> ldlt(A);
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 1e-9 * A.trace()))
      return false;
    const Eigen::Vector3d d = ldlt.solve(b);
    if (!d.allFinite()) return false;
    varpi += d;
    if (d.head<2>().norm() < 1e-6 && std::abs(d(2)) < 1e-8) break;  // converged
  }
  if (info) *info = A;
  if (chi2) *chi2 = cost;
  return varpi.allFinite();
}

int McRansac::selectInliers(const Eigen::Vector3d& varpi, std::vector<int>* inliers) const {
  const double inv_thr2 = 1.0 / (config_.inlier_threshold * config_.inlier_threshold);
  const int M = static_cast<int>(x1_.size());
  int n = 0;
  if (inliers) inliers->clear();
  if (!inliers && std::abs(varpi(2)) * max_abs_dt_ < kPolyAngle) {
    // Hot path (every hypothesis): branch-free polynomial exp, vectorised by the compiler.
    const double w = varpi(2), vx = varpi(0), vy = varpi(1);
    const double* x1 = x1_.data(); const double* y1 = y1_.data();
    const double* x2 = x2_.data(); const double* y2 = y2_.data();
    const double* dt = dt_.data();
    const double* ux = ux_.data(); const double* uy = uy_.data();
    const double* it2 = inv_tan2_.data();
    for (int m = 0; m < M; ++m) {
      const double t = dt[m] * w;
      double a, b;
      polyCoefficients(t, a, b);
      const double s = t * a, c = 1.0 - t * b;  // sin t, cos t
      const double rx = dt[m] * vx, ry = dt[m] * vy;
      const double ex = x2[m] - (c * x1[m] - s * y1[m] + a * rx - b * ry);
      const double ey = y2[m] - (s * x1[m] + c * y1[m] + b * rx + a * ry);
      const double er = ex * ux[m] + ey * uy[m];
      n += (er * er * (inv_thr2 - it2[m]) + (ex * ex + ey * ey) * it2[m] < 1.0) ? 1 : 0;
    }
    return n;
  }
  for (int m = 0; m < M; ++m) {
    const Eigen::Vector2d g = transformPoint(varpi, dt_[m], x1_[m], y1_[m]);
    const double ex = x2_[m] - g.x(), ey = y2_[m] - g.y();
    const double er = ex * ux_[m] + ey * uy_[m];
    if (er * er * (inv_thr2 - inv_tan2_[m]) + (ex * ex + ey * ey) * inv_tan2_[m] < 1.0) {
      ++n;
      if (inliers) inliers->push_back(m);
    }
  }
  return n;
}

bool McRansac::finish(const Eigen::Vector3d& varpi_in, const std::vector<int>& inliers,
                      double dt_ref, MotionEstimate& out) const {
  Eigen::Vector3d varpi = varpi_in;
  const int n = static_cast<int>(inliers.size());
  if (!gaussNewton(inliers.data(), n, config_.gn_iterations, varpi, nullptr, nullptr))
    return false;
  setMotionFromVelocity(-varpi, out.velocity_cov, dt_ref, out);  // covariance: see below
  out.ok = true;
  return true;
}

bool McRansac::covariance(const std::vector<int>& inliers, double dt_ref,
                          MotionEstimate& out) const {
  const Eigen::Vector3d varpi = -out.velocity;
  const int n = static_cast<int>(inliers.size());
  // Covariance. The paper weights e_m by R_cart of y_m2 only, but p_m1 is just as noisy and
  // its (large) tangential noise, rotated into frame 2, leaks into the radial direction of
  // near points. The true residual covariance is S_m = R_cart(p_m2) + C_m R_cart(p_m1) C_m^T,
  // so the honest covariance of the paper's estimator is the sandwich
  // A^-1 (sum G^T W S W G) A^-1, scaled up by the reduced chi^2 (under S) when the residuals
  // exceed what range_sigma/azimuth_sigma claim.
  const double sr = config_.range_sigma, sa = config_.azimuth_sigma;
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero(), B = Eigen::Matrix3d::Zero();
  double chi2 = 0.0;
  for (int m : inliers) {
    const double dt = dt_[m];
    const Eigen::Vector2d p1(x1_[m], y1_[m]), p2(x2_[m], y2_[m]);
    double c, sn;
    const Eigen::Vector2d g = transformPoint(varpi, dt, p1.x(), p1.y(), &c, &sn);
    const Eigen::Vector2d e = p2 - g;
    const Eigen::Matrix<double, 2, 3> G = dt * se2::odot2(g);
    const Eigen::Matrix2d W = cartesianInformation(g, sr, sa, tangential_floor_);
    Eigen::Matrix2d C;
    C << c, -sn, sn, c;
    const Eigen::Matrix2d S =
        cartesianCovariance(p2, sr, sa, tangential_floor_) +
        C * cartesianCovariance(p1, sr, sa, tangential_floor_) * C.transpose();
    const Eigen::Matrix<double, 3, 2> GtW = G.transpose() * W;
    A.noalias() += GtW * G;
    B.noalias() += GtW * S * GtW.transpose();
    chi2 += e.dot(S.inverse() * e);
  }
  const int dof = 2 * n - 3;
  const double scale = dof > 0 ? std::max(1.0, chi2 / dof) : 1.0;
  Eigen::LDLT<Eigen::Matrix3d> ldlt(A);
  if (ldlt.info() != Eigen::Success) return false;
  const Eigen::Matrix3d Ainv = ldlt.solve(Eigen::Matrix3d::Identity());
  const Eigen::Matrix3d cov = scale * Ainv * B * Ainv;
  // varpi (world seen from the sensor) -> body velocity xi = -varpi; covariance unchanged.
  setMotionFromVelocity(-varpi, cov, dt_ref, out);
  return true;
}

bool McRansac::estimate(const std::vector<Keypoint>& k1, const std::vector<Keypoint>& k2,
                        const std::vector<Match>& matches, int64_t ref1_ns, int64_t ref2_ns,
                        MotionEstimate& out) {
  out.ok = false;
  out.matches = static_cast<int>(matches.size());
  out.inliers.clear();
  load(k1, k2, matches);
  const int M = static_cast<int>(x1_.size());
  const double dt_ref = 1e-9 * static_cast<double>(ref2_ns - ref1_ns);
  if (M < 2 || !(dt_ref > 0.0)) return false;

  rng_.seed(static_cast<uint32_t>(config_.ransac_seed));  // fixed seed, as the paper
  std::uniform_int_distribution<int> pick(0, M - 1);
  int best_n = 0;
  Eigen::Vector3d best_varpi = Eigen::Vector3d::Zero();
  for (int it = 0; it < config_.ransac_iterations; ++it) {
    const int sub[2] = {pick(rng_), pick(rng_)};
    const double dx = x1_[sub[0]] - x1_[sub[1]], dy = y1_[sub[0]] - y1_[sub[1]];
    if (sub[0] == sub[1] || dx * dx + dy * dy < 1.0) continue;  // rotation ill-defined
    Eigen::Vector3d varpi = Eigen::Vector3d::Zero();
    if (!gaussNewton(sub, 2, kHypothesisSteps, varpi, nullptr, nullptr)) continue;
    const int n = selectInliers(varpi, nullptr);
    if (n > best_n) {
      best_n = n;
      best_varpi = varpi;
    }
  }
  if (best_n < 2) return false;
  selectInliers(best_varpi, &best_);
  if (!finish(best_varpi, best_, dt_ref, out)) return false;
  // The hypothesis that chose the inlier set carries the error of a 2-point fit, and points
  // near the threshold are kept or dropped according to it, which pulls the refit towards
  // it. Re-selecting with the refined velocity and refitting (until the set is stable, at
  // most kReselectRounds) removes that dependence.
  for (int round = 0; round < kReselectRounds; ++round) {
    selectInliers(-out.velocity, &work_);
    if (work_ == best_ || work_.size() < 2) break;
    best_.swap(work_);
    if (!finish(-out.velocity, best_, dt_ref, out)) return false;
  }
  if (!covariance(best_, dt_ref, out)) return out.ok = false;
  out.inliers.assign(best_.begin(), best_.end());
  return true;
}

bool McRansac::refit(const std::vector<Keypoint>& k1, const std::vector<Keypoint>& k2,
                     const std::vector<Match>& matches, int64_t ref1_ns, int64_t ref2_ns,
                     MotionEstimate& inout, bool with_covariance) {
  load(k1, k2, matches);
  const double dt_ref = 1e-9 * static_cast<double>(ref2_ns - ref1_ns);
  if (inout.inliers.size() < 2 || !(dt_ref > 0.0)) return inout.ok = false;
  work_.assign(inout.inliers.begin(), inout.inliers.end());
  const Eigen::Vector3d start = -inout.velocity;
  if (!finish(start, work_, dt_ref, inout) ||
      (with_covariance && !covariance(work_, dt_ref, inout)))
    return inout.ok = false;
  // The refit ran on the given set; report the inliers of the refined velocity.
  selectInliers(-inout.velocity, &best_);
  if (best_.size() < 2) return inout.ok = false;
  inout.inliers.assign(best_.begin(), best_.end());
  inout.matches = static_cast<int>(matches.size());
  inout.ok = true;
  return true;
}

bool McRansac::updateCovariance(int64_t ref1_ns, int64_t ref2_ns, MotionEstimate& inout) const {
  const double dt_ref = 1e-9 * static_cast<double>(ref2_ns - ref1_ns);
  if (inout.inliers.size() < 2 || !(dt_ref > 0.0)) return false;
  return covariance(inout.inliers, dt_ref, inout);
}

}  // namespace spinradar
