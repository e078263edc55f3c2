// Statistics of the grey-box regression on synthetic residuals with known truth.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "spinradar/diagnose/stats.hpp"

using namespace spinradar::diagnose;

TEST(Stats, Chi2SurvivalMatchesTables) {
  EXPECT_NEAR(chi2Sf(3.841, 1), 0.05, 1e-4);
  EXPECT_NEAR(chi2Sf(6.635, 1), 0.01, 1e-4);
  EXPECT_NEAR(chi2Sf(5.991, 2), 0.05, 1e-4);
  EXPECT_NEAR(chi2Sf(18.307, 10), 0.05, 1e-4);
  EXPECT_NEAR(chi2Sf(0.0, 3), 1.0, 1e-12);
  EXPECT_NEAR(normalTwoSidedP(1.96), 0.05, 1e-3);
}

TEST(Stats, HolmStepDown) {
  // Sorted 0.001 < 0.012 < 0.06: thresholds 0.05/3, 0.05/2, 0.05 -> first two rejected.
  const auto r = holm({0.06, 0.001, 0.012}, 0.05);
  EXPECT_FALSE(r[0]);
  EXPECT_TRUE(r[1]);
  EXPECT_TRUE(r[2]);
  const auto s = holm({0.3, 0.02}, 0.05);
  EXPECT_FALSE(s[0]);
  EXPECT_TRUE(s[1]);
}

TEST(Stats, AbsorbedFractionAndVif) {
  const int n = 400;
  Eigen::MatrixXd N(n, 1);
  Eigen::VectorXd x(n), z(n);
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0, 1);
  for (int i = 0; i < n; ++i) {
    N(i, 0) = 1.0;
    x(i) = 2.0 + g(rng);  // mean 2, sd 1: 4/5 of |x|^2 is the constant
    z(i) = x(i) + 0.05 * g(rng);
  }
  EXPECT_NEAR(absorbedFraction(N, x), 0.8, 0.05);
  Eigen::MatrixXd X(n, 2);
  X << x, z;
  const Eigen::VectorXd v = vif(N, X);
  EXPECT_GT(v(0), 10.0);  // x and z nearly collinear after removing the mean
  EXPECT_GT(v(1), 10.0);
}

// y = 0.5 * x1 + noise with candidates x1, x2 (independent) and x3 (copy of x1 + small noise).
TEST(Stats, StepwiseFindsTheTrueEffectAndFlagsItsTwin) {
  for (int seed = 1; seed <= 5; ++seed) {
    const int n = 600;
    std::mt19937 rng(seed);
    std::normal_distribution<double> g(0, 1);
    Eigen::MatrixXd C(n, 3), N(n, 0);
    Eigen::VectorXd y(n);
    for (int i = 0; i < n; ++i) {
      C(i, 0) = g(rng);
      C(i, 1) = g(rng);
      C(i, 2) = C(i, 0) + 0.1 * g(rng);
      y(i) = 0.5 * C(i, 0) + g(rng);
    }
    const SelectionResult r = stepwiseSelect(y, N, C);
    ASSERT_EQ(r.selected.size(), 1u) << "seed " << seed;
    const int k = r.selected[0];
    EXPECT_TRUE(k == 0 || k == 2);
    ASSERT_FALSE(r.steps[0].confounded.empty());
    EXPECT_NEAR(r.joint.coef(0), 0.5, 0.15);
    EXPECT_NEAR(std::sqrt(r.joint.cov(0, 0)), 1.0 / std::sqrt(n), 0.02);
  }
}

// Null case: pure noise, five candidates; the false-positive rate must stay near alpha.
TEST(Stats, StepwiseNullRateIsCalibrated) {
  int false_pos = 0;
  const int runs = 200;
  for (int seed = 0; seed < runs; ++seed) {
    const int n = 300;
    std::mt19937 rng(100 + seed);
    std::normal_distribution<double> g(0, 1);
    Eigen::MatrixXd C(n, 5), N(n, 1);
    Eigen::VectorXd y(n);
    for (int i = 0; i < n; ++i) {
      for (int k = 0; k < 5; ++k) C(i, k) = g(rng);
      N(i, 0) = 1.0;
      y(i) = 3.0 + g(rng);  // the constant is nuisance
    }
    SelectionOptions o;
    o.alpha = 0.05;
    o.require_bic = false;
    if (!stepwiseSelect(y, N, C, o).selected.empty()) ++false_pos;
  }
  EXPECT_LE(false_pos, 20);  // expected 10 of 200 at alpha 0.05
}

// Two real effects with different sizes, nuisance intercept: both found, biggest first.
TEST(Stats, StepwiseTwoEffectsOrderAndNuisance) {
  const int n = 1000;
  std::mt19937 rng(7);
  std::normal_distribution<double> g(0, 1);
  Eigen::MatrixXd C(n, 4), N(n, 1);
  Eigen::VectorXd y(n);
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < 4; ++k) C(i, k) = g(rng);
    C(i, 3) = 1.0;  // a candidate identical to the nuisance: fully absorbed
    N(i, 0) = 1.0;
    y(i) = 1.0 + 0.8 * C(i, 2) + 0.3 * C(i, 0) + g(rng);
  }
  const SelectionResult r = stepwiseSelect(y, N, C);
  ASSERT_EQ(r.selected.size(), 2u);
  EXPECT_EQ(r.selected[0], 2);
  EXPECT_EQ(r.selected[1], 0);
  EXPECT_NEAR(r.joint.coef(1), 0.8, 0.1);
  EXPECT_NEAR(r.joint.coef(2), 0.3, 0.1);
  bool saw = false;
  for (const auto& t : r.steps[0].tests)
    if (t.index == 3) {
      saw = true;
      EXPECT_NEAR(t.absorbed_nuisance, 1.0, 1e-9);
      EXPECT_EQ(t.lr, 0.0);
    }
  EXPECT_TRUE(saw);
}
