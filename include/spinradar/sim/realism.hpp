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
};

RealismStats computeRealism(const std::vector<PolarScan>& scans, const std::string& name,
                            const RealismOptions& options = {});

/// Loads the real samples found in `realdata_dir` (Oxford, MulRan, Boreas-RT, RADIATE), each as
/// (name, scans). Missing samples are skipped; unreadable ones throw.
std::vector<std::pair<std::string, std::vector<PolarScan>>> loadRealSamples(
    const std::string& realdata_dir);

/// A Markdown table, one column per data set.
std::string formatRealismTable(const std::vector<RealismStats>& columns);

}  // namespace spinradar::sim
