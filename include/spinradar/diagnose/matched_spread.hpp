#pragma once
// Spread of returns matched between consecutive scans, across the beam (tangential) and along it
// (radial), per range band, on a recording alone. Real scans spread 0.13-0.20 m across the beam
// at every range where the simulator without glint gives 0.05-0.08 m (issues 19, 20): the
// scattering centre of extended objects moves along their surface as the aspect changes.
// Returns: local maxima of the counts (sub-cell by parabolic interpolation in range and
// azimuth), the strongest fraction of each band. Motion: given, or estimated per pair by a
// coarse correlation search then point-to-point ICP (diagnose may not use the estimation part).
#include <array>
#include <ostream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "spinradar/core/polar_scan.hpp"

namespace spinradar::diagnose {

struct SpreadOptions {
  double keep_fraction = 0.004;  ///< strongest share of each band's cells that may be a return
  double min_range = 2.5;        ///< m
  double gate = 1.0;             ///< m, final mutual nearest-neighbour gate
  double search = 4.0;           ///< m, half width of the coarse translation search
  double search_yaw_deg = 4.0;   ///< half width of the coarse yaw search
  int icp_iterations = 30;
  /// Pairs are scans this many rotations apart (1: consecutive; 2: the fit part of the appearance
  /// stage's "scans" split, every other scan). A reference for such pairs must use the same gap.
  int stride = 1;
};

/// One range band (sim::kBandEdges: 2.5-10, 10-25, 25-50, 50-100 m).
struct SpreadBand {
  double tangential = 0, radial = 0;        ///< robust std (1.4826 MAD) of the matched difference, m
  double tangential_se = 0, radial_se = 0;  ///< standard errors, m
  int matches = 0;
  double range = 0;  ///< mean range of the matched returns, m
};

struct MatchedSpread {
  std::array<SpreadBand, 4> band{};
  SpreadBand all;        ///< pooled over every band
  int pairs = 0;         ///< consecutive pairs aligned
  int returns = 0;       ///< returns per scan (mean)
  /// Per pair: pooled tangential spread (replicates; their scatter gives `all.tangential_se`).
  std::vector<double> pair_tangential;
  /// Per pair: pose of scan i+1 in the frame of scan i, as used (given or estimated).
  std::vector<Eigen::Matrix3d> motions;
};

/// Returns of one scan in its sensor frame (x forward, y left), metres, with their range.
std::vector<Eigen::Vector2d> spreadReturns(const PolarScan& scan, const SpreadOptions& opt = {});

/// Spread of the returns matched between scans i and i+1. `motions`, when not null, holds the
/// pose of scan i+1 in the frame of scan i for each pair (size scans - 1); otherwise it is
/// estimated. Only consecutive scans are a pair: later, by at most 1.6 rotations when the row
/// stamps span the rotation (not masked copies of one scan, not scans spread over a route); with
/// opt.stride k > 1, later by k - 0.6 to k + 0.6 rotations.
MatchedSpread measureMatchedSpread(const std::vector<PolarScan>& scans,
                                   const std::vector<Eigen::Matrix3d>* motions = nullptr,
                                   const SpreadOptions& opt = {});

/// Pose of scan b in the frame of scan a from their returns (coarse search + ICP), starting at
/// `init`.
Eigen::Matrix3d alignReturns(const std::vector<Eigen::Vector2d>& a,
                             const std::vector<Eigen::Vector2d>& b, const Eigen::Matrix3d& init,
                             const SpreadOptions& opt = {});

/// Markdown table of matched spreads per range band (across / along the beam, m): the header,
/// then one row per spread, in the stream's current number format.
void writeSpreadTableHeader(std::ostream& os);
void writeSpreadTableRow(std::ostream& os, const std::string& name, const MatchedSpread& m);

}  // namespace spinradar::diagnose
