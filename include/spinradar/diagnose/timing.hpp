#pragma once
// Timing stage of the diagnosis (issue 10): what the per-azimuth stamps of a recording say
// about the sensor's timing, and which timing model a user should adopt.
//
// From the stamps alone (no world, no trajectory):
//  - stamp bursts: rows stamped in packets (packet arrival times, Oxford/MulRan) instead of
//    uniformly at the firing times. The gaps between consecutive stamps are searched for a
//    periodic pattern (packet size B, per-scan phase); the pattern is tested against the null
//    of uniform stamps with noise (z of the gap step, Bonferroni over every (B, phase) tried)
//    and fitted by least squares on the stamps themselves:
//      stamp(i) = c_k + last(i) * dt_k + (i - first(i)) * spacing
//    (the simulator's model, physics.hpp). The delay after the packet's last row is not
//    identifiable from stamps (it is a constant timestamp offset: c_k = t0_k + delay).
//  - rotation period per scan: slope of the (burst-corrected) stamps against the azimuth
//    index, tested for equality across scans (Wald chi^2, K - 1 dof).
// From the residuals of associated targets (world + trajectory, after the catalogue fit):
//  - rotation jitter with nominal stamps: each scan's true firing times stretch by (1 + e_k);
//    the per-scan regressor is -tau * d(position)/d(timestamp offset). The e_k are fitted
//    jointly, tested for equality (Wald chi^2) and their spread estimated by the method of
//    moments (random-effects variance).
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "spinradar/core/polar_scan.hpp"

namespace spinradar::diagnose {

struct Observation;

/// One timing effect found (or tested) in the recording.
struct TimingFinding {
  std::string name;        ///< stamp_bursts, rotation_period_variation, rotation_jitter, ...
  std::string parameter, unit;
  double value = 0, stddev = 0;
  double significance = 0; ///< |z| equivalent of the test's p-value
  double p = 1;
  int scans = 0;           ///< scans that support it
  std::string evidence;    ///< how strong, in words (few scans = weak)
  nlohmann::json details = nlohmann::json::object();
};

struct TimingOptions {
  double alpha = 0.001;          ///< level of each timing test (Bonferroni inside the searches)
  int max_burst = 64;            ///< largest packet size tried
  double stamp_quantum = 1e-6;   ///< s, noise floor of one stamp (Navtech stamps are in us)
  double min_burst_step = 5e-6;  ///< s, smallest gap step worth naming (practical floor)
  double min_period_variation = 1e-4;  ///< relative, smallest period spread worth naming
  double outlier_sigma = 5.0;    ///< jitter fit: residuals beyond this many robust sigmas
};

struct TimingReport {
  int scans = 0, rows = 0;
  int rows_per_rotation = 0;
  double row_interval = 0;            ///< s, mean firing interval (fitted)
  std::string stamp_model = "uniform";  ///< "uniform" or "bursts"
  // Stamp bursts.
  bool bursts = false;
  int burst_size = 0;
  double burst_size_agreement = 0;    ///< fraction of detected packets of exactly that size
  double burst_spacing = 0, burst_spacing_sd = 0;  ///< s between stamps in a packet
  double burst_gap = 0;               ///< s, mean stamp step at a packet boundary
  double burst_z = 0, burst_p = 1;
  std::vector<int> burst_phase;       ///< per scan: row index of the first packet boundary
  double stamp_rms_uniform = 0;       ///< s, stamps minus the best uniform fit (per-scan lines)
  double stamp_rms_model = 0;         ///< s, stamps minus the chosen model
  // Rotation period per scan from the stamps.
  std::vector<double> period, period_sd;  ///< s per scan
  std::vector<double> start_gap;      ///< s, first-firing-time differences of consecutive scans
  double start_gap_mean = 0, start_gap_rel_std = 0;  ///< per rotation (skipped scans divided out)
  double period_mean = 0, period_rel_std = 0, period_rel_std_sd = 0;
  double period_chi2 = 0, period_p = 1;
  int period_dof = 0;
  // Rotation jitter from target residuals (when a world/trajectory diagnosis ran).
  bool jitter_tested = false;
  std::vector<double> stretch, stretch_sd;  ///< per scan: e_k (fraction of the period)
  double jitter_std = 0, jitter_std_sd = 0, jitter_chi2 = 0, jitter_p = 1;
  int jitter_dof = 0;
  std::vector<TimingFinding> findings;
  /// In-scan Doppler of alternating chirps (chirpDopplerSummary; null when chirps do not
  /// alternate). Not a timing effect, but like the stamps it needs no world or trajectory.
  nlohmann::json chirp_doppler;
  std::vector<std::string> advice;    ///< the timing model to use, in words
  std::vector<std::string> notes;

  nlohmann::json toJson() const;
  std::string summaryMarkdown() const;
};

/// Stamp analysis of a recording (scans in time order). `rotation_hz` (> 0) is only used to
/// report the nominal period next to the fitted one. Throws std::runtime_error when a scan has
/// fewer than 8 valid rows.
TimingReport analyseStamps(const std::vector<PolarScan>& scans, double rotation_hz = 0,
                           const TimingOptions& opt = {});

/// The scans with every row's stamp replaced by the uniform firing-time model fitted by
/// analyseStamps (only when it found bursts; otherwise returned unchanged).
std::vector<PolarScan> correctedStamps(const std::vector<PolarScan>& scans,
                                       const TimingReport& timing);

/// Rotation jitter from the residuals of associated targets (after the catalogue fit).
/// `sigma_r`, `sigma_az` whiten range and azimuth residuals (re-estimated robustly, not below
/// `floor_r`, `floor_az`: the precision of a peak fit); `tau_fixed` < 0 uses each
/// observation's tau (motion distortion on), otherwise that time for every row (the scan is
/// rendered from one pose). `target_nuisance`: each target's mean residual is removed (targets
/// refitted as nuisance; then the spread is a lower bound). A map built from the recording
/// does not need it: its scans have their own stretches. Outliers (5 robust sigmas) are set
/// aside after the per-scan fit. Fills the jitter fields and adds a finding when significant.
void analyseJitter(const std::vector<Observation>& obs, int scans, double sigma_r,
                   double sigma_az, double floor_r, double floor_az, double tau_fixed,
                   bool target_nuisance, TimingReport& timing,
                   const TimingOptions& opt = {});

/// Adds the advice (which timing model to use) from the findings and the catalogue's fitted
/// timestamp offset (`offset_s`, `offset_sd`; offset_sd <= 0: not found).
void adviseTiming(TimingReport& timing, double offset_s, double offset_sd);

}  // namespace spinradar::diagnose
