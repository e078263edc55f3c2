// SO(3)/SE(3) helpers; formulas from Barfoot, "State Estimation for Robotics" (2017), ch. 7.
#include "spinradar/core/lie.hpp"

#include <Eigen/Geometry>

namespace spinradar {

namespace so3 {

Mat3 hat(const Vec3& p) {
  Mat3 m;
  m << 0.0, -p(2), p(1), p(2), 0.0, -p(0), -p(1), p(0), 0.0;
  return m;
}

Vec3 vee(const Mat3& m) { return Vec3(m(2, 1), m(0, 2), m(1, 0)); }

Mat3 exp(const Vec3& phi) {
  const double t = phi.norm();
  const Mat3 P = hat(phi);
  double a, b;  // C = 1 + a phi^ + b phi^ phi^
  if (t < lie_detail::kSmallAngle) {
    const double t2 = t * t;
    a = 1.0 - t2 / 6.0 + t2 * t2 / 120.0;  // sin t / t
    b = 0.5 - t2 / 24.0 + t2 * t2 / 720.0;  // (1 - cos t) / t^2
  } else {
    const double s = std::sin(t), c = std::cos(t);
    a = s / t;
    b = (c > 0.0 ? s * s / (1.0 + c) : 1.0 - c) / (t * t);  // no cancellation near 0
  }
  return Mat3::Identity() + a * P + b * P * P;
}

Vec3 log(const Mat3& C) {
  // Eigen goes through the quaternion, which stays accurate near 0 and near pi where the
  // textbook acos((tr C - 1)/2) loses digits.
  const Eigen::AngleAxisd aa(C);
  return aa.angle() * aa.axis();
}

Mat3 leftJacobian(const Vec3& phi) {
  const double t = phi.norm();
  const Mat3 P = hat(phi);
  double a, b;  // J = 1 + a phi^ + b phi^ phi^
  if (t < lie_detail::kSmallAngle) {
    const double t2 = t * t;
    a = 0.5 - t2 / 24.0 + t2 * t2 / 720.0;            // (1 - cos t) / t^2
    b = 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0;    // (t - sin t) / t^3
  } else {
    a = (1.0 - std::cos(t)) / (t * t);
    b = (t - std::sin(t)) / (t * t * t);
  }
  return Mat3::Identity() + a * P + b * P * P;
}

Mat3 leftJacobianInverse(const Vec3& phi) {
  const double t = phi.norm();
  const Mat3 P = hat(phi);
  double b;  // (1/t^2)(1 - (t/2) cot(t/2))
  if (t < lie_detail::kSmallAngle) {
    const double t2 = t * t;
    b = 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0;
  } else {
    b = (1.0 - 0.5 * t / std::tan(0.5 * t)) / (t * t);
  }
  return Mat3::Identity() - 0.5 * P + b * P * P;
}

}  // namespace so3

namespace se3 {

Mat4 hat(const Vec6& xi) {
  Mat4 m = Mat4::Zero();
  m.topLeftCorner<3, 3>() = so3::hat(xi.tail<3>());
  m.topRightCorner<3, 1>() = xi.head<3>();
  return m;
}

Vec6 vee(const Mat4& m) {
  Vec6 xi;
  xi.head<3>() = m.topRightCorner<3, 1>();
  xi.tail<3>() = so3::vee(m.topLeftCorner<3, 3>());
  return xi;
}

Mat4 exp(const Vec6& xi) {
  Mat4 T = Mat4::Identity();
  T.topLeftCorner<3, 3>() = so3::exp(xi.tail<3>());
  T.topRightCorner<3, 1>() = so3::leftJacobian(xi.tail<3>()) * xi.head<3>();
  return T;
}

Vec6 log(const Mat4& T) {
  Vec6 xi;
  xi.tail<3>() = so3::log(T.topLeftCorner<3, 3>());
  xi.head<3>() = so3::leftJacobianInverse(xi.tail<3>()) * T.topRightCorner<3, 1>();
  return xi;
}

Mat4 inverse(const Mat4& T) {
  Mat4 Ti = Mat4::Identity();
  Ti.topLeftCorner<3, 3>() = T.topLeftCorner<3, 3>().transpose();
  Ti.topRightCorner<3, 1>() = -Ti.topLeftCorner<3, 3>() * T.topRightCorner<3, 1>();
  return Ti;
}

Mat6 adjoint(const Mat4& T) {
  const Eigen::Matrix3d C = T.topLeftCorner<3, 3>();
  Mat6 A = Mat6::Zero();
  A.topLeftCorner<3, 3>() = C;
  A.bottomRightCorner<3, 3>() = C;
  A.topRightCorner<3, 3>() = so3::hat(T.topRightCorner<3, 1>()) * C;
  return A;
}

Mat6 curlyhat(const Vec6& xi) {
  Mat6 m = Mat6::Zero();
  const Eigen::Matrix3d P = so3::hat(xi.tail<3>());
  m.topLeftCorner<3, 3>() = P;
  m.bottomRightCorner<3, 3>() = P;
  m.topRightCorner<3, 3>() = so3::hat(xi.head<3>());
  return m;
}

Mat46 odot(const Eigen::Vector4d& p) {
  Mat46 m = Mat46::Zero();
  m.topLeftCorner<3, 3>() = p(3) * Eigen::Matrix3d::Identity();
  m.topRightCorner<3, 3>() = -so3::hat(p.head<3>());
  return m;
}

}  // namespace se3

}  // namespace spinradar
