// Lie-group identities against finite differences and round trips.
#include <gtest/gtest.h>

#include <random>

#include <unsupported/Eigen/MatrixFunctions>

#include "spinradar/core/lie.hpp"

using namespace spinradar;

namespace {

std::vector<Eigen::Vector3d> se2Samples() {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Vector3d> xs;
  for (double t : {0.0, 1e-12, 1e-8, 5e-4, 9.99e-4, 1.001e-3, 0.1, 1.0, 3.0, -3.1})
    xs.emplace_back(5.0 * u(rng), 5.0 * u(rng), t);
  for (int i = 0; i < 20; ++i) xs.emplace_back(20 * u(rng), 20 * u(rng), 3.0 * u(rng));
  return xs;
}

std::vector<se3::Vec6> se3Samples() {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<se3::Vec6> xs;
  for (double t : {0.0, 1e-12, 1e-7, 5e-4, 1.001e-3, 0.2, 1.5, 3.0}) {
    Eigen::Vector3d axis(u(rng), u(rng), u(rng));
    axis.normalize();
    se3::Vec6 xi;
    xi << 4 * u(rng), 4 * u(rng), 4 * u(rng), t * axis;
    xs.push_back(xi);
  }
  return xs;
}

}  // namespace

TEST(LieSe2, ExpMatchesMatrixExponential) {
  for (const auto& xi : se2Samples()) {
    const Eigen::Matrix3d ref = se2::hat(xi).exp();
    EXPECT_LT((se2::exp(xi) - ref).norm(), 1e-11) << xi.transpose();
  }
}

TEST(LieSe2, LogExpRoundTrip) {
  for (const auto& xi : se2Samples()) {
    const Eigen::Vector3d back = se2::log(se2::exp(xi));
    EXPECT_LT((back - xi).norm(), 1e-11 * (1.0 + xi.norm())) << xi.transpose();
    const Eigen::Matrix3d T = se2::exp(xi);
    EXPECT_LT((se2::exp(se2::log(T)) - T).norm(), 1e-11);
  }
}

TEST(LieSe2, HatVeeAndInverse) {
  for (const auto& xi : se2Samples()) {
    EXPECT_LT((se2::vee(se2::hat(xi)) - xi).norm(), 1e-15);
    const Eigen::Matrix3d T = se2::exp(xi);
    EXPECT_LT((se2::inverse(T) * T - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  }
}

TEST(LieSe2, OdotSwapsTheProduct) {
  const Eigen::Vector3d p(3.0, -2.0, 1.0);
  for (const auto& xi : se2Samples()) {
    EXPECT_LT((se2::hat(xi) * p - se2::odot(p) * xi).norm(), 1e-12);
    EXPECT_LT(((se2::hat(xi) * p).head<2>() - se2::odot2(p.head<2>()) * xi).norm(), 1e-12);
  }
}

TEST(LieSe2, OdotJacobianMatchesFiniteDifferences) {
  // d/d(dxi) of exp(dxi^) T p at dxi = 0 is (T p)^odot (left perturbation).
  const Eigen::Vector3d p(12.0, -7.0, 1.0);
  for (const auto& xi : se2Samples()) {
    const Eigen::Matrix3d T = se2::exp(xi);
    const Eigen::Matrix3d J = se2::odot(T * p);
    const double h = 1e-6;
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      d(k) = h;
      const Eigen::Vector3d fd = (se2::exp(d) * T * p - se2::exp(-d) * T * p) / (2 * h);
      EXPECT_LT((fd - J.col(k)).norm(), 1e-7) << "column " << k;
    }
  }
}

TEST(LieSe2, AdjointIdentities) {
  for (const auto& xi : se2Samples()) {
    const Eigen::Matrix3d T = se2::exp(Eigen::Vector3d(1.5, -0.7, 0.4));
    // T exp(xi^) T^-1 = exp((Ad(T) xi)^)
    const Eigen::Matrix3d lhs = T * se2::exp(xi) * se2::inverse(T);
    EXPECT_LT((lhs - se2::exp(se2::adjoint(T) * xi)).norm(), 1e-10);
    // Ad(exp(xi^)) = exp(xi^curlyhat)
    const Eigen::Matrix3d ad = se2::curlyhat(xi).exp();
    EXPECT_LT((se2::adjoint(se2::exp(xi)) - ad).norm(), 1e-9 * (1.0 + ad.norm()));
  }
}

TEST(LieSe2, XyYawJacobianMatchesFiniteDifferences) {
  for (const auto& xi : se2Samples()) {
    const Eigen::Matrix3d J = se2::xyYawJacobian(xi);
    const double h = 1e-6;
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      d(k) = h;
      Eigen::Vector3d fd = (se2::toXyYaw(se2::exp(xi + d)) - se2::toXyYaw(se2::exp(xi - d))) / (2 * h);
      EXPECT_LT((fd - J.col(k)).norm(), 1e-6 * (1.0 + xi.norm())) << xi.transpose() << " col " << k;
    }
  }
}

TEST(LieSe2, XyYawRoundTrip) {
  const Eigen::Vector3d p(1.0, -2.0, 2.5);
  EXPECT_LT((se2::toXyYaw(se2::fromXyYaw(p)) - p).norm(), 1e-14);
}

TEST(LieSo3, ExpLogAndJacobians) {
  for (const auto& xi : se3Samples()) {
    const Eigen::Vector3d phi = xi.tail<3>();
    const Eigen::Matrix3d ref = so3::hat(phi).exp();
    EXPECT_LT((so3::exp(phi) - ref).norm(), 1e-12);
    EXPECT_LT((so3::log(so3::exp(phi)) - phi).norm(), 1e-10) << phi.transpose();
    EXPECT_LT((so3::leftJacobian(phi) * so3::leftJacobianInverse(phi) - Eigen::Matrix3d::Identity()).norm(), 1e-10);
  }
  // Near pi the rotation vector is still recovered (up to the sign ambiguity at exactly pi).
  const Eigen::Vector3d phi = (M_PI - 1e-7) * Eigen::Vector3d(1, 2, 2).normalized();
  EXPECT_LT((so3::log(so3::exp(phi)) - phi).norm(), 1e-6);
}

TEST(LieSo3, LeftJacobianMatchesFiniteDifferences) {
  // exp((phi + d)^) ~ exp((J(phi) d)^) exp(phi^)
  for (const auto& xi : se3Samples()) {
    const Eigen::Vector3d phi = xi.tail<3>();
    const Eigen::Matrix3d J = so3::leftJacobian(phi);
    const double h = 1e-6;
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      d(k) = h;
      const Eigen::Vector3d plus = so3::log(so3::exp(phi + d) * so3::exp(phi).transpose());
      const Eigen::Vector3d minus = so3::log(so3::exp(phi - d) * so3::exp(phi).transpose());
      EXPECT_LT(((plus - minus) / (2 * h) - J.col(k)).norm(), 1e-6);
    }
  }
}

TEST(LieSe3, ExpLogRoundTripAndMatrixExponential) {
  for (const auto& xi : se3Samples()) {
    const Eigen::Matrix4d ref = se3::hat(xi).exp();
    EXPECT_LT((se3::exp(xi) - ref).norm(), 1e-11) << xi.transpose();
    EXPECT_LT((se3::log(se3::exp(xi)) - xi).norm(), 1e-9 * (1.0 + xi.norm())) << xi.transpose();
    EXPECT_LT((se3::vee(se3::hat(xi)) - xi).norm(), 1e-15);
    const Eigen::Matrix4d T = se3::exp(xi);
    EXPECT_LT((se3::inverse(T) * T - Eigen::Matrix4d::Identity()).norm(), 1e-12);
  }
}

TEST(LieSe3, OdotAndAdjoint) {
  const Eigen::Vector4d p(3.0, -1.0, 2.0, 1.0);
  const se3::Vec6 xi0 = (se3::Vec6() << 0.3, -0.2, 1.0, 0.1, -0.4, 0.7).finished();
  const Eigen::Matrix4d T = se3::exp(xi0);
  for (const auto& xi : se3Samples()) {
    EXPECT_LT((se3::hat(xi) * p - se3::odot(p) * xi).norm(), 1e-12);
    const Eigen::Matrix4d lhs = T * se3::exp(xi) * se3::inverse(T);
    EXPECT_LT((lhs - se3::exp(se3::adjoint(T) * xi)).norm(), 1e-9);
    const se3::Mat6 ad = se3::curlyhat(xi).exp();
    EXPECT_LT((se3::adjoint(se3::exp(xi)) - ad).norm(), 1e-9 * (1.0 + ad.norm()));
  }
  // Analytic odot Jacobian vs finite differences of exp(d^) T p.
  const Eigen::Matrix<double, 4, 6> J = se3::odot(T * p);
  for (int k = 0; k < 6; ++k) {
    se3::Vec6 d = se3::Vec6::Zero();
    d(k) = 1e-6;
    const Eigen::Vector4d fd = (se3::exp(d) * T * p - se3::exp(-d) * T * p) / 2e-6;
    EXPECT_LT((fd - J.col(k)).norm(), 1e-7);
  }
}

TEST(LieSe2, LeftJacobianMatchesFiniteDifferences) {
  for (const auto& xi : se2Samples()) {
    const Eigen::Matrix3d J = se2::leftJacobian(xi);
    const Eigen::Matrix3d Tinv = se2::inverse(se2::exp(xi));
    const double h = 1e-6;
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      d(k) = h;
      const Eigen::Vector3d fd =
          (se2::log(se2::exp(xi + d) * Tinv) - se2::log(se2::exp(xi - d) * Tinv)) / (2 * h);
      EXPECT_LT((fd - J.col(k)).norm(), 1e-6 * (1.0 + xi.norm())) << xi.transpose() << " col " << k;
    }
    // Consistency with the [x, y, yaw] Jacobian: d xyYaw / d xi = L(T) J_l(xi).
    const Eigen::Matrix3d lhs = se2::xyYawJacobian(xi);
    const Eigen::Matrix3d rhs = se2::leftPerturbationToXyYaw(se2::exp(xi)) * J;
    EXPECT_LT((lhs - rhs).norm(), 1e-9 * (1.0 + xi.norm()));
  }
}
