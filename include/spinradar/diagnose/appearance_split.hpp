#pragma once
// How the appearance stage splits a recording into a fit part and a held-out part (issue 20,
// docs/diagnose_holdout.md, "tenth round"), and the real halves' own difference under a split:
// the noise floor of the held-out check, measured on the real scans alone.
#include <cmath>
#include <string>
#include <vector>

#include "spinradar/core/polar_scan.hpp"

namespace spinradar::diagnose {

/// A fit / held-out split of a recording.
///   "contiguous": several scans: the first half (rounded up) fit, the rest held out; one scan:
///                 azimuth quarters 0 and 2 fit, 1 and 3 held out (the ninth round's split).
///   "scans":      every other scan: scans 0, 2, 4, ... fit, 1, 3, 5, ... held out (needs 2 scans).
///   "blocks:N":   in every scan, azimuth blocks of N rows alternate: blocks 0, 2, 4, ... (rows
///                 0..N-1, 2N..3N-1, ...) fit, 1, 3, 5, ... held out. N even (each block holds as
///                 many even as odd rows: Boreas-RT alternates its chirp between even and odd
///                 rows, docs/diagnose_chirps.md), 2 <= N <= azimuths / 2.
///   "auto":       chosen per recording by the rule of kDefaultHoldoutSplit (chooseHoldoutSplit).
struct HoldoutSplit {
  enum Kind { kContiguous, kScans, kBlocks, kAuto } kind = kAuto;
  int block_rows = 20;  ///< rows per block (kBlocks)
  std::string name() const;
};

/// The default split: "auto". Rule (docs/diagnose_holdout.md, tenth round): of the candidates
/// (kAutoCandidates) that fit the recording, whose blocks are at least kMinBlockRows rows and
/// whose parts each find every missing row a quarter turn away in their own rows (the own scene,
/// appearance_scene.cpp, lends rows that way), the one with the smallest real halves'
/// difference (largest of the 12 fitted figures at 10-100 m). Measured on the real scans only,
/// never on sim-vs-real gaps (`spinradar diagnose --appearance-split-survey` shows every
/// candidate).
inline constexpr const char* kDefaultHoldoutSplit = "auto";
inline constexpr const char* kAutoCandidates[] = {"contiguous", "scans",    "blocks:16", "blocks:20",
                                                  "blocks:24",  "blocks:32", "blocks:40", "blocks:50"};
/// Smallest block the rule admits (rows of a 400-row scan): the beam is 2-3 rows, the
/// appearance stage's isolated peaks look 0.1 rad (6-7 rows) to each side, so blocks of 16 rows
/// or more keep the parts' figures independent (Cen2018 and CA-CFAR work along range in a row).
inline constexpr int kMinBlockRows = 16;

/// Parses a split name ("contiguous", "scans", "blocks:N"); throws std::invalid_argument naming
/// the text and the reason.
HoldoutSplit parseHoldoutSplit(const std::string& text);

/// Splits `scans` by `split`. The held-out rows of the fit part (and the fit rows of the held-out
/// part) are masked through PolarScan::valid AND zeroed, so no code path of the fit can read a
/// held-out count, even one that ignores the mask. Realism counts stay per full rotation.
/// Throws std::invalid_argument when the split does not fit the recording ("scans" on one scan,
/// blocks larger than half a scan).
void splitHoldout(const std::vector<PolarScan>& scans, std::vector<PolarScan>& fit,
                  std::vector<PolarScan>& holdout, const HoldoutSplit& split);

/// The real halves' own difference under one split: for each of the 12 fitted figures (mean,
/// q90, plain CA-CFAR cells, Cen2018 keypoints at 10-25, 25-50, 50-100 m) |held out - fit| / fit
/// on the real scans, the largest of them, and its spread: over the same pattern with its grid
/// turned, and over the same blocks (whole scans for "contiguous" / "scans" with several scans)
/// assigned to the parts at random, half each.
struct SplitHalves {
  std::string split;
  int blocks_per_part = 0;
  std::vector<std::pair<std::string, double>> figures;  ///< the 12 relative differences
  double largest = 0;
  std::string largest_figure;
  double floor_median = 0, floor_p90 = 0;  ///< of the largest, over random assignments
  /// Of the largest, over the same alternating pattern turned by 0, 2, 4, ... rows through one
  /// period (row splits only; NaN for whole-scan splits): the split's own spread.
  double offset_median = NAN, offset_p90 = NAN;
  bool even_odd_balanced = true;           ///< every scan's parts hold as many even as odd rows
};

/// Whether `split` is admitted by the rule on `scans` (fits, blocks >= kMinBlockRows, rows lent
/// a quarter turn away), and the reason when not.
bool admittedSplit(const HoldoutSplit& split, const std::vector<PolarScan>& scans,
                   std::string* why = nullptr);

/// The split the rule picks for `scans` (never kAuto); `halves` gets its real halves' largest
/// difference.
HoldoutSplit chooseHoldoutSplit(const std::vector<PolarScan>& scans, double* halves = nullptr);

/// Measures SplitHalves for each of `splits` on `scans` (detectors run once per 2-row group; the
/// figures are exact sums of the groups, as sim::computeRealism over the split parts). "auto" is
/// resolved first. permutations = 0: no spread (neither random nor turned grid).
std::vector<SplitHalves> surveySplits(const std::vector<PolarScan>& scans,
                                      const std::vector<HoldoutSplit>& splits,
                                      int permutations = 200, uint64_t seed = 1);

/// The survey as a markdown table.
std::string splitSurveyMarkdown(const std::vector<SplitHalves>& rows);

}  // namespace spinradar::diagnose
