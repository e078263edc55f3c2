#pragma once
// A cheap SE(2) exponential for bounds only (issue 19, sixteenth speed round). The proximity
// association (keyframe_proximity.cpp) moves every keypoint by its own exp(tau xi) (with
// azimuth peaks each keypoint has its own time), and most queries are then decided by an
// anchor (proximity_bound.hpp), which only needs the query to within a known slack: a Taylor
// series instead of sin, cos and two divisions. The queries an anchor does not decide are
// computed again with se2::exp, so the pairs (and the poses) are the same to the bit.
#include <cmath>

#include <Eigen/Core>

namespace spinradar {

/// |theta| up to which seriesExp2x3 holds its error bound.
constexpr double kSeriesMaxAngle = 0.5;

/// The top two rows of exp(v^) for |v(2)| <= kSeriesMaxAngle, each entry within 1e-15 (plus
/// 1e-15 times |v|) of se2::exp(v)'s (the first omitted terms are below 1e-17); false (E
/// untouched) for larger or non-finite angles.
inline bool seriesExp2x3(const Eigen::Vector3d& v, double E[2][3]) {
  const double t = v(2);
  if (!(std::abs(t) <= kSeriesMaxAngle)) return false;
  const double t2 = t * t;
  // a = sin(t)/t and b = (1 - cos t)/t (se2::vCoefficients), through t^12 and t^13.
  const double a = 1.0 + t2 * (-1.0 / 6 + t2 * (1.0 / 120 + t2 * (-1.0 / 5040 + t2 * (1.0 / 362880 +
                   t2 * (-1.0 / 39916800 + t2 * (1.0 / 6227020800.0))))));
  const double b = t * (0.5 + t2 * (-1.0 / 24 + t2 * (1.0 / 720 + t2 * (-1.0 / 40320 + t2 * (1.0 / 3628800 +
                   t2 * (-1.0 / 479001600.0 + t2 * (1.0 / 87178291200.0)))))));
  const double s = t * a, c = 1.0 - t * b;
  E[0][0] = c;
  E[0][1] = -s;
  E[0][2] = a * v(0) - b * v(1);
  E[1][0] = s;
  E[1][1] = c;
  E[1][2] = b * v(0) + a * v(1);
  return true;
}

}  // namespace spinradar
