#pragma once
// Doppler inside one scan of a radar whose chirps alternate up / down between azimuths
// (Boreas-RT, simulator physics "chirp_alternate"). An up chirp reports a scatterer at
// r - beta * u, a down chirp at r + beta * u (u = closing speed along the beam, beta =
// f_t / (df/dt)), so a row and the mean of its two neighbours (opposite chirp) see the same
// scene shifted in range by
//   s(phi) = r_down - r_up = 2 beta (vx cos phi - vy sin phi) + c
// (phi clockwise from forward, (vx, vy) the sensor velocity in its REP 103 frame, c a constant
// range bias between chirp directions). The shift is measured per row by cross-correlating
// noise-floor-free power profiles (FFT, sub-bin parabolic peak), then fitted by robust weighted
// least squares. Detection asks whether that alternating cosine is significant; a control fit
// without the sign flip (what a scan whose chirps do not alternate would show) is reported too.
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "spinradar/core/polar_scan.hpp"
#include "spinradar/sim/physics.hpp"

namespace spinradar::diagnose {

struct ChirpDopplerOptions {
  double min_range = 4.0;        ///< m: closer bins (leakage) are ignored
  double max_range = 1e9;        ///< m: farther bins are ignored
  double max_shift = 4.0;        ///< m: largest |r_down - r_up| searched (2 beta |v|)
  double floor_sigmas = 2.0;     ///< signal = power above per-bin median + this many robust SDs
  double min_floor_margin = 3.0; ///< counts: at least this far above the median
  double min_correlation = 0.3;  ///< normalised correlation peak a row needs to be used
  double alpha = 1e-6;           ///< false-alarm probability of the detection test
  double min_amplitude_bins = 1.0;  ///< detection also needs 2 beta |v| >= this many bins
  std::optional<double> beta;    ///< s: known beta -> velocity
  std::optional<double> speed;   ///< m/s: known speed -> beta
};

/// One robust fit of shift(phi) = A cos phi - B sin phi + C (metres).
struct ChirpShiftFit {
  double a = 0, b = 0, c = 0;          ///< A = 2 beta vx, B = 2 beta vy, C = chirp range bias
  double sa = 0, sb = 0, sc = 0;       ///< 1-sigma
  double cov_ab = 0;                   ///< covariance of A and B
  double chi2 = 0;                     ///< Wald statistic of (A, B) = 0 (2 dof)
  double p = 1;                        ///< its p-value
  double residual_rms = 0;             ///< m, inlier rows
  double robust_sigma = 0;             ///< m, 1.4826 MAD of the residuals
  double inflation = 1;                ///< variance factor for correlated neighbouring rows
  int inliers = 0;
  double amplitude() const;            ///< |(A, B)| = 2 beta |v| (m)
  double amplitudeSigma() const;
  nlohmann::json toJson() const;
};

struct ChirpDopplerResult {
  bool detected = false;
  std::string verdict;              ///< one line for people
  std::string chirp_source;         ///< "chirp_up" (flags in the scan) or "row_parity" (inferred)
  bool sign_ambiguous = false;      ///< row parity: even rows assumed up, so (vx, vy) may be negated
  int rows_total = 0;
  int rows_measured = 0;            ///< rows with signal whose correlation peak was usable
  int rows_used = 0;                ///< inliers of the alternating fit
  double range_resolution = 0;      ///< m per bin of the scan
  ChirpShiftFit fit;                ///< sign-corrected shifts (alternating model)
  ChirpShiftFit control;            ///< raw shifts without the sign flip (non-alternating model)
  double beta_v = 0, beta_v_sigma = 0;  ///< beta |v| = amplitude / 2 (m)
  double direction = 0;             ///< rad, atan2(vy, vx) of the motion, sensor frame (CCW)
  double direction_sigma = 0;
  std::optional<double> beta_given, speed_given;
  // Given beta:
  std::optional<double> vx, vy, speed, speed_sigma, vx_sigma, vy_sigma;
  // Given speed:
  std::optional<double> beta, beta_sigma;

  nlohmann::json toJson() const;
};

/// Throws std::invalid_argument for bad options or a scan without rows / bins.
ChirpDopplerResult estimateChirpDoppler(const PolarScan& scan, const ChirpDopplerOptions& options = {});

/// True when the scan carries chirp flags that alternate from row to row (Boreas-RT layout).
bool hasAlternatingChirps(const PolarScan& scan);

/// The in-scan Doppler check of `spinradar diagnose`: estimateChirpDoppler on every scan with
/// alternating chirp flags; null when no scan has them. Per-scan results, how many detected,
/// and the medians of beta |v| (and of the speed when options.beta is set).
/// Options for the check under a base physics (its Doppler beta, when on, gives the speed).
ChirpDopplerOptions chirpOptionsFor(const sim::PhysicsConfig& base);

nlohmann::json chirpDopplerSummary(const std::vector<PolarScan>& scans,
                                   const ChirpDopplerOptions& options = {});

}  // namespace spinradar::diagnose
