#pragma once
// Realism figures of polar scans, to compare simulated scans with real ones side by side:
// intensity histogram shape, range profile, clutter texture (azimuth/range autocorrelation)
// and detections per scan with the pipeline's detectors.
#include <string>
#include <utility>
#include <vector>

#include "spinradar/core/params.hpp"
#include "spinradar/core/polar_scan.hpp"

namespace spinradar::sim {

struct RealismOptions {
  double min_range = 2.5;    ///< m; cells outside [min_range, max_range] are ignored
  double max_range = 100.0;  ///< m (the shortest real sample, RADIATE, reaches 100 m)
  bool detect = true;        ///< run the Cen2018 and CFAR detectors
  DetectorConfig detector;   ///< settings for both detectors (method field is overridden)
};

struct RealismStats {
  std::string name;
  int scans = 0;
  double zero_fraction = 0;      ///< share of cells equal to 0
  double mean = 0;               ///< mean count
  double q50 = 0, q90 = 0, q99 = 0, q999 = 0, max = 0;  ///< count quantiles
  double bright_fraction = 0;    ///< share of cells >= 40 counts
  double band_mean[4] = {0, 0, 0, 0};  ///< mean count at 2.5-10, 10-25, 25-50, 50-100 m
  double azimuth_corr = 0;       ///< correlation of neighbouring azimuths (lag 1 row)
  double range_corr_short = 0;   ///< correlation at a range lag of 0.25 m
  double range_corr_long = 0;    ///< correlation at a range lag of 1 m
  double detections_cen = -1;    ///< Cen2018 keypoints per scan (-1 = not run)
  double detections_cfar = -1;   ///< CA-CFAR keypoints per scan (-1 = not run)
  /// Per range band (kBandEdges): q90 count, plain CA-CFAR cells and Cen2018 keypoints per scan.
  double band_q90[4] = {0, 0, 0, 0};
  double band_cacfar[4] = {0, 0, 0, 0};
  double band_cen[4] = {-1, -1, -1, -1};
  /// Per range band: mean of the lower half of the counts (the receiver noise side; the
  /// appearance stage's range-curve fit needs it to tell noise from clutter, not a realism gap).
  double band_floor[4] = {0, 0, 0, 0};
  /// Per range band: share of the counts at code 0 (0-1; native codes: amplitude under 2, the
  /// receiver noise against the first quantiser step). Unlike band_floor it keeps moving with
  /// the noise level when more than half the counts are zero (MulRan's fit: 59 % zeros,
  /// recording 30-40 %; docs/diagnose_chirps.md).
  double band_zero[4] = {0, 0, 0, 0};
  double cacfar = 0;              ///< plain CA-CFAR cells per scan, all bands
  /// Mean count of the cells beyond max_range to the last bin (Oxford: 100-165 m), -1 when the
  /// scans end there: not a realism gap, the evidence of the returns' far slope
  /// (AppearanceOptions::fit_far_slope; docs/diagnose_far_band.md).
  double beyond_mean = -1;
  double beyond_q90 = -1;  ///< q90 count of the same cells (the returns' side; the mean: noise too)
};

/// Range bands of the per-band figures (m).
constexpr double kBandEdges[5] = {2.5, 10, 25, 50, 100};

/// A plain cell-averaging CFAR on the linear power of one row (count = dB): cells whose power
/// exceeds 12 dB over the mean of 16 training bins each side (4 guard bins each side), as an
/// independent reader of a scan would run it. Counts the flagged cells per band into `per_band`.
void countPlainCaCfar(const PolarScan& scan, double min_range, double max_range,
                      double per_band[4]);

/// Relative gap |sim - real| / real of the per-band figures (mean, q90, CA-CFAR, Cen2018),
/// 16 values; the worst one is what "within 15 %" is checked against.
std::vector<double> bandGaps(const RealismStats& sim, const RealismStats& real);

RealismStats computeRealism(const std::vector<PolarScan>& scans, const std::string& name,
                            const RealismOptions& options = {});

/// Loads the real samples found in `realdata_dir` (Oxford, MulRan, Boreas-RT, RADIATE), each as
/// (name, scans). Missing samples are skipped; unreadable ones throw.
std::vector<std::pair<std::string, std::vector<PolarScan>>> loadRealSamples(
    const std::string& realdata_dir);

/// A Markdown table, one column per data set (with the per-band rows).
std::string formatRealismTable(const std::vector<RealismStats>& columns);

}  // namespace spinradar::sim
