#pragma once
// How strong the descriptor registration is between scans g apart (g = 1..max_gap: the age of
// a keyframe), measured against the simulator's truth (issue 19, tenth round): keypoints per
// scan, keypoints found again (a keypoint of the older scan within `truth_radius` under the
// true poses), descriptor matches after the ratio test, true matches among them and the share
// of pairs with fewer true matches than the keyframe tracker's inlier minimum (weak; a rigid
// RANSAC on the same matches keeps 3-10 % fewer inliers than there are true matches, measured
// on the matrix recordings); keypoints, repeatable keypoints and true matches per range band.
// Runs the real front end (FeatureExtractor, matchDescriptors) with the given parameters.
#include <string>
#include <vector>

#include "spinradar/core/params.hpp"
#include "spinradar/core/polar_scan.hpp"
#include "spinradar/sim/scene.hpp"

namespace spinradar::diagnose {

struct RepeatabilityOptions {
  int max_gap = 5;             ///< scans apart, 1..max_gap
  double truth_radius = 0.5;   ///< m: two keypoints are one return when the truth puts them this close
  int weak_inliers = 30;       ///< KeyframeTracker::kMinInliers: fewer true matches = weak
  std::vector<double> band_edges{10.0, 20.0, 35.0, 60.0};  ///< m, range bands (last: beyond)
  void validate() const;  ///< throws std::invalid_argument naming the option
};

struct GapFigures {
  int pairs = 0;               ///< scan pairs measured at this gap
  double repeatable = 0;       ///< per pair: keypoints of the newer scan found again in the older one
  double matches = 0;          ///< per pair: descriptor matches (ratio test)
  double true_matches = 0;     ///< per pair: matches the truth confirms
  double weak_share = 0;       ///< pairs with fewer than weak_inliers true matches / pairs
  std::vector<double> band_repeatable, band_true;  ///< per pair, per range band
};

struct Repeatability {
  int scans = 0;
  double keypoints = 0;        ///< per scan
  double feature_ms = 0;       ///< per scan: detect + Cartesian + describe (wall time)
  std::vector<double> band_keypoints;  ///< per scan, per range band
  std::vector<GapFigures> gaps;        ///< gaps[g - 1]
};

/// Feed scans in time order with add(); result() at any time. `truth`: the sensor pose on the
/// scans' clock (a simulated recording's trajectory.csv; row stamps are seconds on it).
class RepeatabilityMeter {
 public:
  RepeatabilityMeter(const PipelineConfig& config, sim::Trajectory truth, RepeatabilityOptions options = {});
  ~RepeatabilityMeter();
  RepeatabilityMeter(const RepeatabilityMeter&) = delete;
  RepeatabilityMeter& operator=(const RepeatabilityMeter&) = delete;
  void add(const PolarScan& scan);
  Repeatability result() const;

 private:
  struct Impl;
  Impl* impl_;
};

/// Share (0..1) of a gap's true matches that lie beyond range band edge `edge` (bands after
/// band_edges[edge]; edge 2 of 2.5,10,25,50,100 = beyond 25 m): the far-structure realism figure
/// (docs/city_scene_far_structure.md). 0 without true matches; throws std::out_of_range for an
/// edge past the bands.
double trueShareBeyond(const GapFigures& g, size_t edge);

/// The figures as a markdown table (one row per gap, with the true-match share beyond each band
/// edge) plus the range-band line.
std::string repeatabilityTable(const Repeatability& r, const RepeatabilityOptions& options);

}  // namespace spinradar::diagnose
