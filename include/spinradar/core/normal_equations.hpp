#pragma once
// One Gauss-Newton step of the estimators: solve A dx = b for a symmetric A that must be
// positive definite (too few or degenerate constraints are a failed step, not a guess).
#include <Eigen/Cholesky>
#include <Eigen/Core>

namespace spinradar {

/// false when A is not positive definite or the step is not finite; dx is then unspecified.
template <int N>
bool solveNormalEquations(const Eigen::Matrix<double, N, N>& A,
                          const Eigen::Matrix<double, N, 1>& b, Eigen::Matrix<double, N, 1>& dx) {
  const Eigen::LDLT<Eigen::Matrix<double, N, N>> ldlt(A);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) return false;
  dx = ldlt.solve(b);
  return dx.allFinite();
}

}  // namespace spinradar
