// The series SE(2) exponential of the proximity association's first pass
// (src/estimation/approx_se2_exp.hpp) holds the error bound the association's slack is built
// on: each entry within 1e-15 (rotation) and 1e-15 (1 + |v|) (translation) of se2::exp's, and
// it declines angles beyond kSeriesMaxAngle and non-finite ones.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "../../src/estimation/approx_se2_exp.hpp"
#include "spinradar/core/lie.hpp"

using namespace spinradar;

TEST(ApproxSe2Exp, WithinItsBoundOfTheClosedForm) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  double worst_rot = 0.0, worst_trans = 0.0;
  for (int k = 0; k < 200000; ++k) {
    // Angles over the whole range, many tiny ones (the closed form's series branch), and
    // translations of millimetres to tens of metres.
    const double t = k % 4 == 0 ? 1e-4 * unit(rng) : kSeriesMaxAngle * unit(rng);
    const double scale = std::pow(10.0, -3.0 + 4.5 * (0.5 + 0.5 * unit(rng)));
    const Eigen::Vector3d v(scale * unit(rng), scale * unit(rng), t);
    double E[2][3];
    ASSERT_TRUE(seriesExp2x3(v, E));
    const Eigen::Matrix3d X = se2::exp(v);
    for (int r = 0; r < 2; ++r) {
      for (int c = 0; c < 2; ++c) worst_rot = std::max(worst_rot, std::abs(E[r][c] - X(r, c)));
      worst_trans = std::max(worst_trans, std::abs(E[r][2] - X(r, 2)) / (1.0 + v.head<2>().norm()));
    }
  }
  EXPECT_LE(worst_rot, 1e-15);
  EXPECT_LE(worst_trans, 1e-15);
  EXPECT_GT(worst_rot, 0.0);  // not the same formula: the bound is what is relied on
}

TEST(ApproxSe2Exp, DeclinesLargeAndNonFiniteAngles) {
  double E[2][3] = {{7.0, 7.0, 7.0}, {7.0, 7.0, 7.0}};
  EXPECT_FALSE(seriesExp2x3(Eigen::Vector3d(1.0, 0.0, kSeriesMaxAngle * 1.0001), E));
  EXPECT_FALSE(seriesExp2x3(Eigen::Vector3d(1.0, 0.0, -3.0), E));
  EXPECT_FALSE(seriesExp2x3(Eigen::Vector3d(1.0, 0.0, std::numeric_limits<double>::quiet_NaN()), E));
  EXPECT_FALSE(seriesExp2x3(Eigen::Vector3d(1.0, 0.0, std::numeric_limits<double>::infinity()), E));
  EXPECT_EQ(E[0][0], 7.0);  // untouched
  EXPECT_TRUE(seriesExp2x3(Eigen::Vector3d(1.0, 0.0, kSeriesMaxAngle), E));
}
