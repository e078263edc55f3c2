#pragma once
// The anisotropic glint of the appearance catalogue: the spread of returns matched between
// consecutive scans (matched_spread.hpp) split into three physics terms fitted separately:
//   glint_across (m)      constant across the beam,
//   azimuth_jitter (deg)  across the beam, growing with range (a per-row beam angle error),
//   glint_along (m)       along the beam.
// Model, per range band b with the recording's mean range r_b (variances add):
//   across_b^2 = base_b^2 + G * glint_across^2 + J * r_b^2 * azimuth_jitter^2
//   along_b^2  = base_along_b^2 + A * glint_along^2
// base: the reference scene rendered with the sensor model at the three terms 0; G, A and J from
// two probe renders of the same scene (glint 0.15 m across and along; jitter 0.2 deg), so the
// measurement's own efficiency (peak interpolation, matching gate) is in the gains. The squares are
// linear in the figures: weighted least squares over the bands, non-negative, with covariance.
// A term is named when significant (z >= z_min) and practically large: at least half a range bin
// (glint) or half an azimuth row (jitter), or a residual drop of 5 % or more on its spread figure
// (rms over bands of recording - model, with against without the term).
#include <array>
#include <map>
#include <string>
#include <vector>

#include "spinradar/core/polar_scan.hpp"
#include "spinradar/diagnose/glint_fit.hpp"
#include "spinradar/diagnose/matched_spread.hpp"
#include "spinradar/sim/physics.hpp"
#include "spinradar/sim/sensor_config.hpp"

namespace spinradar::diagnose {

inline GlintOptions withSegments(int n) {
  GlintOptions o;
  o.segments = n;
  return o;
}

struct GlintTermsOptions {
  GlintOptions ref = withSegments(6);  ///< reference scene, scans, segments, seed, scene_sd, spread
  double probe_glint = 0.15;    ///< m, across and along, of the glint probe render
  double probe_jitter = 0.2;    ///< deg, of the jitter probe render
  int min_matches = 20;         ///< per band, in the recording and the reference
  double z_min = 4.0;
  double half_unit = 0.5;       ///< practical size: this share of a range bin / azimuth row
  double drop_min = 0.05;       ///< practical size: this relative residual drop
};

struct GlintTerm {
  std::string key, unit;        ///< physics key, "m" or "deg"
  double value = 0, stddev = 0, z = 0;
  double size = 0;              ///< against the resolution, in size_unit
  std::string size_unit;        ///< "bins" (range bins) or "rows" (azimuth rows)
  double drop = 0;              ///< relative residual drop it buys on its spread figure
  bool named = false;
  std::string verdict;          ///< "mismatch", "negligible", "not significant", "not identifiable"
};

struct GlintTermsFit {
  bool measured = false;        ///< the recording has at least one pair of distinct scans
  MatchedSpread real, base, probe_glint, probe_jitter, after;
  double gain_across = 0, gain_along = 0;  ///< G, A (spread^2 per glint^2)
  double gain_jitter = 0;                  ///< J (spread^2 per (range * jitter in rad)^2)
  GlintTerm across, along, jitter;
  /// Model across / along per band at the fitted terms and without any (recording's ranges).
  std::array<double, 4> model_across{}, model_along{}, model0_across{}, model0_along{};
  /// The named terms, as physics keys (what a calibrated sensor carries).
  std::map<std::string, double> named() const;
};

/// Fits the three terms of `recording` (consecutive scans) against the model sensor/physics.
/// The sensor's own appearance physics (SensorConfig::physics) is set aside: the fit gives the
/// terms' total values. `after` is the reference rendered with the named terms.
GlintTermsFit fitGlintTerms(const std::vector<PolarScan>& recording, const sim::SensorConfig& sensor,
                            const sim::PhysicsConfig& physics, const GlintTermsOptions& opt = {});

/// Markdown: the three terms, and the spread across / along per band, recording vs the model
/// before (terms 0) and after (named terms).
std::string glintTermsTable(const GlintTermsFit& f);

}  // namespace spinradar::diagnose
