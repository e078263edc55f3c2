#pragma once
// The only Lie-group helper module: SO(3), SE(2) and SE(3) with the notation of Barfoot,
// "State Estimation for Robotics" (2017), ch. 7. Tangent vectors are ordered translation
// first, xi = [rho; theta] (SE(2): 3-vector, SE(3): 6-vector). T_ab = pose of frame b in
// frame a. SE(2) lives inline here because it is on the per-match hot path of MC-RANSAC.
#include <cmath>

#include <Eigen/Core>

namespace spinradar {

namespace lie_detail {
/// Below this |angle| the closed forms divide ~0 by ~0 and Taylor series take over; the
/// truncated terms are O(angle^6) < 1e-18, far below double precision.
constexpr double kSmallAngle = 1e-3;
}  // namespace lie_detail

// ----------------------------------------------------------------------------------------
// SE(2): T = [C r; 0 1], C = rot(theta). xi = [rho_x, rho_y, theta].
// ----------------------------------------------------------------------------------------
namespace se2 {

/// The angle a wrapped into [-pi, pi] (IEEE remainder: exact, no rounding).
inline double wrapAngle(double a) { return std::remainder(a, 2.0 * M_PI); }

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

/// xi^ = [[0, -theta, rho_x], [theta, 0, rho_y], [0, 0, 0]].
inline Mat3 hat(const Vec3& xi) {
  Mat3 m;
  m << 0.0, -xi(2), xi(0), xi(2), 0.0, xi(1), 0.0, 0.0, 0.0;
  return m;
}

/// Inverse of hat (reads the skew and translation parts).
inline Vec3 vee(const Mat3& m) { return Vec3(m(0, 2), m(1, 2), m(1, 0)); }

/// a = sin(t)/t and b = (1 - cos(t))/t: the entries of V(t) = [[a, -b], [b, a]], the SE(2)
/// analogue of the SE(3) left Jacobian (r = V rho). Series of sin and cos for small t.
inline void vCoefficients(double t, double s, double c, double& a, double& b) {
  if (std::abs(t) < lie_detail::kSmallAngle) {
    const double t2 = t * t;
    a = 1.0 - t2 / 6.0 + t2 * t2 / 120.0;
    b = t * (0.5 - t2 / 24.0 + t2 * t2 / 720.0);
  } else {
    a = s / t;
    // 1 - cos t = sin^2 t / (1 + cos t) avoids the cancellation of 1 - cos t at small t.
    b = (c > 0.0 ? s * s / (1.0 + c) : 1.0 - c) / t;
  }
}

/// exp(xi^) = [C(theta), V(theta) rho; 0 1] (closed form of the matrix exponential).
inline Mat3 exp(const Vec3& xi) {
  const double t = xi(2), s = std::sin(t), c = std::cos(t);
  double a, b;
  vCoefficients(t, s, c, a, b);
  Mat3 T;
  T << c, -s, a * xi(0) - b * xi(1), s, c, b * xi(0) + a * xi(1), 0.0, 0.0, 1.0;
  return T;
}

/// log(T)^vee: theta = atan2(C10, C00) in (-pi, pi], rho = V(theta)^-1 r with
/// V^-1 = [[k, t/2], [-t/2, k]], k = (t/2) cot(t/2) (series 1 - t^2/12 - t^4/720).
inline Vec3 log(const Mat3& T) {
  const double t = std::atan2(T(1, 0), T(0, 0));
  double k;
  if (std::abs(t) < lie_detail::kSmallAngle) {
    const double t2 = t * t;
    k = 1.0 - t2 / 12.0 - t2 * t2 / 720.0;
  } else {
    // (t/2) cot(t/2) = (t/2) sin t / (1 - cos t) = (t/2) (1 + cos t) / sin t; take the form
    // without cancellation on each side of t = pi/2.
    const double s = std::sin(t), c = std::cos(t);
    k = c > 0.0 ? 0.5 * t * (1.0 + c) / s : 0.5 * t * s / (1.0 - c);
  }
  const double x = T(0, 2), y = T(1, 2);
  return Vec3(k * x + 0.5 * t * y, -0.5 * t * x + k * y, t);
}

inline Mat3 inverse(const Mat3& T) {
  Mat3 Ti = Mat3::Identity();
  Ti.topLeftCorner<2, 2>() = T.topLeftCorner<2, 2>().transpose();
  Ti.topRightCorner<2, 1>() = -Ti.topLeftCorner<2, 2>() * T.topRightCorner<2, 1>();
  return Ti;
}

/// Ad(T) with T exp(xi^) T^-1 = exp((Ad(T) xi)^): [[C, (r_y, -r_x)^T], [0, 0, 1]].
inline Mat3 adjoint(const Mat3& T) {
  Mat3 A = Mat3::Zero();
  A.topLeftCorner<2, 2>() = T.topLeftCorner<2, 2>();
  A(0, 2) = T(1, 2);
  A(1, 2) = -T(0, 2);
  A(2, 2) = 1.0;
  return A;
}

/// xi^curlyhat = ad(xi), the adjoint of the algebra: Ad(exp(xi^)) = exp(xi^curlyhat);
/// [[0, -theta, rho_y], [theta, 0, -rho_x], [0, 0, 0]].
inline Mat3 curlyhat(const Vec3& xi) {
  Mat3 m;
  m << 0.0, -xi(2), xi(1), xi(2), 0.0, -xi(0), 0.0, 0.0, 0.0;
  return m;
}

/// p^odot for a homogeneous point p = [x, y, eta]: xi^ p = p^odot xi (Barfoot 7.1.8 in 2D):
/// [[eta, 0, -y], [0, eta, x], [0, 0, 0]].
inline Mat3 odot(const Vec3& p) {
  Mat3 m;
  m << p(2), 0.0, -p(1), 0.0, p(2), p(0), 0.0, 0.0, 0.0;
  return m;
}

/// The 2x3 non-zero block of odot for a Euclidean point (eta = 1).
inline Eigen::Matrix<double, 2, 3> odot2(const Eigen::Vector2d& p) {
  Eigen::Matrix<double, 2, 3> m;
  m << 1.0, 0.0, -p(1), 0.0, 1.0, p(0);
  return m;
}

/// Pose -> [x, y, yaw].
inline Vec3 toXyYaw(const Mat3& T) { return Vec3(T(0, 2), T(1, 2), std::atan2(T(1, 0), T(0, 0))); }
/// [x, y, yaw] -> pose.
inline Mat3 fromXyYaw(const Vec3& p) {
  const double s = std::sin(p(2)), c = std::cos(p(2));
  Mat3 T;
  T << c, -s, p(0), s, c, p(1), 0.0, 0.0, 1.0;
  return T;
}

/// d [x, y, yaw](exp(xi^)) / d xi, to express a tangent covariance over [x, y, yaw]:
/// [x, y] = V(theta) rho, so the columns are V and V'(theta) rho; V' entries are
/// a' = (t cos t - sin t)/t^2 ~ -t/3 + t^3/30 and b' = (t sin t - 1 + cos t)/t^2
/// ~ 1/2 - t^2/8 + t^4/144.
inline Mat3 xyYawJacobian(const Vec3& xi) {
  const double t = xi(2), s = std::sin(t), c = std::cos(t);
  double a, b, da, db;
  vCoefficients(t, s, c, a, b);
  if (std::abs(t) < lie_detail::kSmallAngle) {
    const double t2 = t * t;
    da = t * (-1.0 / 3.0 + t2 / 30.0);
    db = 0.5 - t2 / 8.0 + t2 * t2 / 144.0;
  } else {
    da = (t * c - s) / (t * t);
    db = (t * s - 1.0 + c) / (t * t);
  }
  Mat3 J;
  J << a, -b, da * xi(0) - db * xi(1), b, a, db * xi(0) + da * xi(1), 0.0, 0.0, 1.0;
  return J;
}

/// Left Jacobian of SE(2): exp((xi + d)^) ~ exp((J_l(xi) d)^) exp(xi^). With a, b as in
/// vCoefficients, c1 = (t - sin t)/t^2 ~ t/6 - t^3/120, c2 = (1 - cos t)/t^2 ~ 1/2 - t^2/24:
/// J_l = [[a, -b, c1 rho_x + c2 rho_y], [b, a, -c2 rho_x + c1 rho_y], [0, 0, 1]]
/// (SE(3) analogue: Barfoot 7.1.5; 2D form e.g. Sola et al. 2018, "A micro Lie theory").
inline Mat3 leftJacobian(const Vec3& xi) {
  const double t = xi(2), s = std::sin(t), c = std::cos(t);
  double a, b, c1, c2;
  vCoefficients(t, s, c, a, b);
  if (std::abs(t) < lie_detail::kSmallAngle) {
    const double t2 = t * t;
    c1 = t * (1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0);
    c2 = 0.5 - t2 / 24.0 + t2 * t2 / 720.0;
  } else {
    c1 = (t - s) / (t * t);
    c2 = (1.0 - c) / (t * t);
  }
  Mat3 J;
  J << a, -b, c1 * xi(0) + c2 * xi(1), b, a, -c2 * xi(0) + c1 * xi(1), 0.0, 0.0, 1.0;
  return J;
}

/// d [x, y, yaw](exp(d^) T) / d d at d = 0: maps a left-perturbation covariance of T to
/// one over [x, y, yaw]: [[1, 0, -y], [0, 1, x], [0, 0, 1]].
inline Mat3 leftPerturbationToXyYaw(const Mat3& T) {
  Mat3 L = Mat3::Identity();
  L(0, 2) = -T(1, 2);
  L(1, 2) = T(0, 2);
  return L;
}

/// T_ac = T_ab T_bc with first-order propagation of independent covariances over
/// [x, y, yaw]: p' = p + R(yaw) t, yaw' = yaw + dyaw. P_ac may alias P_ab.
inline void compoundXyYaw(const Mat3& T_ab, const Mat3& P_ab, const Mat3& T_bc, const Mat3& C_bc,
                          Mat3& T_ac, Mat3& P_ac) {
  const Eigen::Matrix2d R = T_ab.topLeftCorner<2, 2>();
  const Eigen::Vector2d Rt = R * T_bc.topRightCorner<2, 1>();
  Mat3 F = Mat3::Identity();
  F(0, 2) = -Rt.y();
  F(1, 2) = Rt.x();
  Mat3 G = Mat3::Identity();
  G.topLeftCorner<2, 2>() = R;
  const Mat3 P = F * P_ab * F.transpose() + G * C_bc * G.transpose();
  T_ac = T_ab * T_bc;
  P_ac = P;
}

}  // namespace se2

// ----------------------------------------------------------------------------------------
// SO(3) / SE(3): T = [C r; 0 1]. xi = [rho (3); phi (3)].
// ----------------------------------------------------------------------------------------
namespace so3 {
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
/// phi^ (skew-symmetric cross-product matrix).
Mat3 hat(const Vec3& phi);
Vec3 vee(const Mat3& m);
/// Rodrigues: C = cos(t) 1 + (1 - cos t) a a^T + sin(t) a^ (Barfoot 7.1.3), series when small.
Mat3 exp(const Vec3& phi);
/// Rotation vector of C (angle in [0, pi]); robust near 0 and pi.
Vec3 log(const Mat3& C);
/// Left Jacobian J(phi) = 1 + (1 - cos t)/t^2 phi^ + (t - sin t)/t^3 phi^ phi^ (Barfoot 7.1.5).
Mat3 leftJacobian(const Vec3& phi);
/// J^-1(phi) = 1 - phi^/2 + (1/t^2)(1 - (t/2) cot(t/2)) phi^ phi^ (Barfoot 7.1.5).
Mat3 leftJacobianInverse(const Vec3& phi);
}  // namespace so3

namespace se3 {
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat4 = Eigen::Matrix4d;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Mat46 = Eigen::Matrix<double, 4, 6>;

/// xi^ = [[phi^, rho], [0^T, 0]].
Mat4 hat(const Vec6& xi);
Vec6 vee(const Mat4& m);
/// exp(xi^) = [C(phi), J(phi) rho; 0^T 1].
Mat4 exp(const Vec6& xi);
/// log(T)^vee: phi = log(C), rho = J(phi)^-1 r.
Vec6 log(const Mat4& T);
Mat4 inverse(const Mat4& T);
/// Ad(T) = [[C, r^ C], [0, C]].
Mat6 adjoint(const Mat4& T);
/// xi^curlyhat = [[phi^, rho^], [0, phi^]].
Mat6 curlyhat(const Vec6& xi);
/// p^odot = [[eta 1, -rho^], [0^T, 0^T]] for p = [rho; eta] (the paper's odot).
Mat46 odot(const Eigen::Vector4d& p);
}  // namespace se3

}  // namespace spinradar
