// Rigid RANSAC: closed-form fit against Eigen's Umeyama, recovery of a known transform with
// outliers, determinism under the fixed seed.
#include <gtest/gtest.h>

#include <random>

#include <Eigen/LU>
#include <Eigen/SVD>

#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/rigid_ransac.hpp"

using namespace spinradar;

namespace {

struct PointPairs {
  std::vector<Eigen::Vector2d> p1, p2;
  std::vector<bool> outlier;
};

/// p1 = T_12 p2 + noise for the inliers; outliers are random points.
PointPairs makePairs(const Eigen::Matrix3d& T_12, int n, double outliers, double noise,
                     uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-80.0, 80.0), u01(0.0, 1.0);
  std::normal_distribution<double> nn(0.0, noise);
  PointPairs pp;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d q(u(rng), u(rng));
    const bool bad = u01(rng) < outliers;
    Eigen::Vector2d p = T_12.topLeftCorner<2, 2>() * q + T_12.topRightCorner<2, 1>();
    if (bad) p = Eigen::Vector2d(u(rng), u(rng));
    pp.p1.push_back(p + Eigen::Vector2d(nn(rng), nn(rng)));
    pp.p2.push_back(q);
    pp.outlier.push_back(bad);
  }
  return pp;
}

}  // namespace

TEST(FitRigid2d, MatchesArunSvd) {
  // Reference: Arun et al. 1987 via the SVD of the cross-covariance, with the reflection fix.
  const Eigen::Matrix3d T = se2::exp(Eigen::Vector3d(2.0, -1.0, 0.4));
  const PointPairs pp = makePairs(T, 50, 0.0, 0.1, 1);
  std::vector<int> idx(50);
  for (int i = 0; i < 50; ++i) idx[i] = i;
  Eigen::Matrix3d fit;
  ASSERT_TRUE(fitRigid2d(pp.p1.data(), pp.p2.data(), idx.data(), 50, fit));
  Eigen::Vector2d c1 = Eigen::Vector2d::Zero(), c2 = Eigen::Vector2d::Zero();
  for (int i = 0; i < 50; ++i) {
    c1 += pp.p1[i] / 50.0;
    c2 += pp.p2[i] / 50.0;
  }
  Eigen::Matrix2d H = Eigen::Matrix2d::Zero();
  for (int i = 0; i < 50; ++i) H += (pp.p2[i] - c2) * (pp.p1[i] - c1).transpose();
  Eigen::JacobiSVD<Eigen::Matrix2d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix2d D = Eigen::Matrix2d::Identity();
  D(1, 1) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1.0 : 1.0;
  const Eigen::Matrix2d R = svd.matrixV() * D * svd.matrixU().transpose();
  EXPECT_LT((fit.topLeftCorner<2, 2>() - R).norm(), 1e-9);
  EXPECT_LT((fit.topRightCorner<2, 1>() - (c1 - R * c2)).norm(), 1e-9);
}

TEST(FitRigid2d, RejectsDegenerateSets) {
  std::vector<Eigen::Vector2d> a(2, Eigen::Vector2d(1, 1)), b(2, Eigen::Vector2d(3, 3));
  const int idx[2] = {0, 1};
  Eigen::Matrix3d T;
  EXPECT_FALSE(fitRigid2d(a.data(), b.data(), idx, 2, T));
  EXPECT_FALSE(fitRigid2d(a.data(), b.data(), idx, 1, T));
}

TEST(RigidRansac, RecoversTransformWith30PercentOutliers) {
  const Eigen::Vector3d truth_xi(2.5, 0.1, 5.0 * M_PI / 180.0);
  const Eigen::Matrix3d T = se2::exp(truth_xi);
  const PointPairs pp = makePairs(T, 800, 0.3, 0.05, 2);
  RigidRansac r;
  MotionEstimate est;
  ASSERT_TRUE(r.estimate(pp.p1, pp.p2, 0.25, est));
  const Eigen::Vector3d err = se2::log(se2::inverse(T) * est.T_12);
  EXPECT_LT(err.head<2>().norm(), 0.01);
  EXPECT_LT(std::abs(err(2)), 1e-3);
  EXPECT_LT((est.velocity - truth_xi / 0.25).norm(), 0.05);
  int bad = 0;
  for (int i : est.inliers) bad += pp.outlier[i];
  EXPECT_EQ(bad, 0);
  EXPECT_GT(est.inliers.size(), 500u);
  // 3-sigma consistency of the [x, y, yaw] covariance.
  const Eigen::Vector3d d = se2::toXyYaw(est.T_12) - se2::toXyYaw(T);
  for (int k = 0; k < 3; ++k) EXPECT_LT(std::abs(d(k)), 3.0 * std::sqrt(est.T_12_cov(k, k)));
}

TEST(RigidRansac, FixedSeedIsDeterministic) {
  const Eigen::Matrix3d T = se2::exp(Eigen::Vector3d(1.0, 0.0, 0.1));
  const PointPairs pp = makePairs(T, 300, 0.4, 0.05, 3);
  RigidRansac a, b;
  MotionEstimate ea, eb, ea2;
  ASSERT_TRUE(a.estimate(pp.p1, pp.p2, 0.25, ea));
  ASSERT_TRUE(b.estimate(pp.p1, pp.p2, 0.25, eb));
  ASSERT_TRUE(a.estimate(pp.p1, pp.p2, 0.25, ea2));
  EXPECT_EQ(ea.inliers, eb.inliers);
  EXPECT_EQ(ea.inliers, ea2.inliers);
  EXPECT_EQ((ea.T_12 - eb.T_12).norm(), 0.0);
}

TEST(RigidRansac, FailsCleanlyOnTooFewPoints) {
  RigidRansac r;
  MotionEstimate est;
  std::vector<Eigen::Vector2d> one(1, Eigen::Vector2d(1, 2));
  EXPECT_FALSE(r.estimate(one, one, 0.25, est));
  EXPECT_FALSE(est.ok);
}
