#pragma once
// Grey-box residual regression: stepwise selection of candidate physics effects with
// Frisch-Waugh-Lovell orthogonalisation against nuisance regressors, LM and likelihood-ratio
// tests, BIC, Holm correction and VIF / correlation confounding diagnostics.
// Everything works on whitened data (unit noise variance expected; scale is re-estimated).
#include <string>
#include <vector>

#include <Eigen/Core>

namespace spinradar::diagnose {

/// Survival function of the chi-square distribution with k degrees of freedom.
double chi2Sf(double x, int k);
/// Two-sided normal p-value of |z|.
double normalTwoSidedP(double z);

/// Residual of y after least-squares projection onto the columns of X (X may have 0 cols).
Eigen::VectorXd orthogonalise(const Eigen::MatrixXd& X, const Eigen::VectorXd& y);

/// Absorbed fraction 1 - |x_perp|^2 / |x|^2 of x by the column space of X.
double absorbedFraction(const Eigen::MatrixXd& X, const Eigen::VectorXd& x);

/// Variance inflation factors of the columns of X (after removing the nuisance space N).
Eigen::VectorXd vif(const Eigen::MatrixXd& N, const Eigen::MatrixXd& X);

/// Holm step-down: which of the p-values are rejected at family-wise level alpha.
std::vector<bool> holm(const std::vector<double>& p, double alpha);

/// Ordinary least squares with covariance sigma^2 (X^T X)^-1 (sigma^2 from the residuals).
struct OlsFit {
  Eigen::VectorXd coef;
  Eigen::MatrixXd cov;
  Eigen::VectorXd resid;
  double rss = 0;
  double sigma2 = 0;
};
OlsFit ols(const Eigen::MatrixXd& X, const Eigen::VectorXd& y);

/// One candidate's test against the current model.
struct CandidateTest {
  int index = -1;             ///< candidate column
  double coef = 0;            ///< added-variable coefficient (parameter change)
  double stddev = 0;
  double z = 0;
  double lm = 0;              ///< n R^2 of the auxiliary regression (chi2_1)
  double lr = 0;              ///< n ln(RSS0 / RSS1) (chi2_1)
  double p = 1;               ///< p-value of the LR statistic
  double delta_bic = 0;       ///< BIC(with) - BIC(without); < 0 favours the effect
  double absorbed = 0;        ///< by nuisance + already selected effects
  double absorbed_nuisance = 0;  ///< by the nuisance regressors alone
};

/// A step of the forward selection: the chosen candidate, all tests at that step, and the
/// candidates whose orthogonalised regressors are nearly collinear with the chosen one.
struct SelectionStep {
  CandidateTest chosen;
  std::vector<CandidateTest> tests;  ///< every remaining candidate at this step
  double holm_threshold = 0;         ///< alpha / (remaining candidates)
  bool accepted = false;
  std::vector<int> confounded;       ///< candidates with |corr(x_k_perp, x_j_perp)| > corr_max
  std::vector<double> confounded_corr;
  double rss_before = 0, rss_after = 0;
};

struct SelectionOptions {
  double alpha = 0.001;            ///< family-wise level (Holm across the candidates)
  double corr_max = 0.9487;        ///< |corr| above which two effects are confounded (VIF > 10)
  bool require_bic = true;         ///< also require delta BIC < 0
  double min_abs_z = 0.0;          ///< optional practical floor
};

struct SelectionResult {
  std::vector<SelectionStep> steps;  ///< the accepted steps, then the first rejected one
  std::vector<int> selected;         ///< candidate columns, most significant first
  OlsFit joint;                      ///< final fit of [nuisance, selected]
  Eigen::VectorXd joint_vif;         ///< VIF of the selected effects in the joint fit
  Eigen::MatrixXd corr;              ///< correlation of all candidates orthogonalised on N
  int n = 0;
};

/// Forward stepwise selection over the candidate columns of C (y, N, C whitened).
SelectionResult stepwiseSelect(const Eigen::VectorXd& y, const Eigen::MatrixXd& N,
                               const Eigen::MatrixXd& C, const SelectionOptions& opt = {});

/// Robust scale: 1.4826 * median absolute deviation about the median.
double robustSigma(const std::vector<double>& v);

}  // namespace spinradar::diagnose
