#pragma once
// Internals of the appearance stage (src/diagnose/appearance_*.cpp).
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "spinradar/diagnose/appearance.hpp"

namespace spinradar::diagnose::detail {

enum class Kind { Level, Slope, Width, Density, Range };

/// A smooth sensor parameter of the appearance catalogue and its finite-difference step.
struct AppearanceParam {
  std::string effect, key, unit;
  double sim::SensorConfig::*field;
  double step, lo, hi;
  Kind kind;
  int block;                 ///< parameters of one block are solved together
  std::vector<int> figures;  ///< indices into figureVector() this block is fitted to
};

const std::vector<AppearanceParam>& appearanceParams();

/// floor[4], mean[4], bright[4], cfar[4], beam width, range width.
constexpr int kFigures = 18;
Eigen::VectorXd figureVector(const AppearanceFigures& f);
Eigen::VectorXd figureSe(const AppearanceFigures& f);
/// Standard error of figures(a) - figures(b): paired by replicate when both hold the same
/// number of replicates (same route), otherwise from the two standard errors.
Eigen::VectorXd differenceSe(const AppearanceFigures& a, const AppearanceFigures& b);

/// Moves the noise floor and receiver gain of `cur` straight to the recording's level when the
/// gaps exceed what the fit's trust region covers (notes say so); figuresOf re-simulates.
void alignLevels(const AppearanceFigures& real, sim::SensorConfig& cur,
                 const std::function<AppearanceFigures(const sim::SensorConfig&)>& figuresOf,
                 std::vector<std::string>& notes, bool hold_gain = false);
/// Fills rep.locate from rep.real / rep.before.
void locateAppearance(AppearanceReport& rep);
/// Realism figures of the recording and of the reference re-simulated before/after the fit.
void realismBeforeAfter(const std::vector<PolarScan>& real, const std::vector<PolarScan>& holdout,
                        const AppearanceOptions& opt, AppearanceReport& rep);

/// Renders rep.fitted with the fit part's and the held-out part's own scenes and classifies
/// each held-out figure (appearance_holdout.cpp); the markdown section and JSON of it.
void holdoutSceneCheck(const std::vector<PolarScan>& fit, const std::vector<PolarScan>& holdout,
                       const AppearanceOptions& opt, AppearanceReport& rep);
std::string holdoutSceneMarkdown(const AppearanceReport& rep);
nlohmann::json holdoutSceneJson(const AppearanceReport& rep);

bool physicsHasGhosts(const sim::PhysicsConfig& p);
AppearanceFinding makeFinding(const std::string& effect, const std::string& param,
                              const std::string& unit, double base, double value, double sd,
                              double size, const std::string& size_unit, bool practical,
                              double z_min);

/// A figure of the texture, its standard error from the replicates (scan quarters) and the
/// replicates themselves (recordings of the same route are compared replicate by replicate).
struct TextureFigure {
  double value = NAN, se = 0;
  std::vector<double> replicates;
};
/// Range correlation of the counts at `lag` bins over 10-100 m (row means removed), in
/// appearance_texture.cpp.
TextureFigure rangeCorrelation(const std::vector<PolarScan>& scans, int lag);
/// Fits noise_texture_bins (whole bins) to the range correlation beyond the range spread; sets
/// it in `cur` when named. Not identifiable without a noise texture.
AppearanceFinding fitTextureLength(const std::vector<PolarScan>& real, sim::SensorConfig& cur,
                                   const sim::PhysicsConfig& phys, const AppearanceOptions& opt,
                                   std::vector<std::string>& notes);

/// Near-range leakage (appearance_leakage.cpp): fits leakage_db (and shortens leakage_range
/// so the leak is down to the noise by 2.5 m) to the real near excess; when named, sets it in
/// `cur` and re-renders `fig_cur`.
AppearanceFinding fitLeakage(const AppearanceFigures& real, const sim::SensorConfig& sensor,
                             sim::SensorConfig& cur, const sim::PhysicsConfig& phys,
                             const AppearanceOptions& opt, AppearanceFigures& fig_cur,
                             std::vector<std::string>& notes);

/// Code set of the counts (appearance_texture.cpp): a recording with every code among 1-30
/// against a model with the native Navtech set is a rescaled product: native_codes = 0 in `cur`
/// and power_scale started from the spread of the noise side (refined with the range curves).
AppearanceFinding fitCodeSet(const std::vector<PolarScan>& real, const AppearanceFigures& fr,
                             const AppearanceFigures& model, sim::SensorConfig& cur,
                             const sim::PhysicsConfig& phys, const AppearanceOptions& opt,
                             std::vector<std::string>& notes);

/// Mean -6 dB range width (bins) of strong isolated returns at 10-100 m on even and odd rows,
/// their ratio odd / even and its standard error (appearance_chirp.cpp).
struct ParityWidths {
  double even = NAN, odd = NAN, ratio = NAN, se = 0, se_even = 0, se_odd = 0;
  int n_even = 0, n_odd = 0;
};
ParityWidths parityRangeWidths(const std::vector<PolarScan>& scans, double counts_per_db,
                               double sigma_bins);
/// Alternating chirps of unequal range resolution: fits range_psf_odd_ratio to the recording's
/// odd / even width ratio on re-simulations; when it is named, range_psf_sigma_bins (the even
/// rows') is fitted with it from the even rows' width, replacing the catalogue's finding. Findings
/// go to `findings`; true when both were set in `cur`. Runs after the catalogue, before the
/// range curves.
bool fitAlternatingChirps(const std::vector<PolarScan>& real, sim::SensorConfig& cur,
                          const sim::PhysicsConfig& phys, const AppearanceOptions& opt,
                          std::vector<AppearanceFinding>& findings,
                          std::vector<std::string>& notes);

/// With the recording's own scene: the findings of notIdentifiableWithOwnScene parameters are
/// never named (verdict "not identifiable"), and a note says why (appearance_scene.cpp).
void markOwnSceneFindings(std::vector<AppearanceFinding>& findings,
                          std::vector<std::string>& notes);

/// Glint terms (physics glint_across, glint_along, azimuth_jitter; glint_terms.hpp) of the
/// scans `real` (pairs `stride` rotations apart; the reference pairs too) against cur/phys: their
/// findings and a note with the spread before/after go to `rep`; the named ones are set in the
/// sensor's physics (`cur.physics`, what a calibrated sensor file carries), the others removed.
void appendGlint(const std::vector<PolarScan>& real, sim::SensorConfig& cur,
                 sim::PhysicsConfig& phys, const AppearanceOptions& opt, AppearanceReport& rep,
                 int stride = 1);

}  // namespace spinradar::diagnose::detail
