#pragma once
// Shared setup of the appearance-stage tests: a sensor reaching all four range bands and
// options for quick renders.
#include "../../src/diagnose/appearance_detail.hpp"
#include "spinradar/diagnose/appearance.hpp"
#include "spinradar/sim/realism.hpp"
#include "spinradar/sim/sensor_config.hpp"

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

namespace spinradar::diagnose::testing {

/// 2300 bins x 0.0438 m = 100 m: all four bands (2.5-10, 10-25, 25-50, 50-100 m).
inline sim::SensorConfig hundredMetreSensor() {
  sim::SensorConfig s;
  s.bins = 2300;
  return s;
}

/// All four bands with some clutter and noise texture for the range curves to act on.
inline sim::SensorConfig curveSensor() {
  sim::SensorConfig s = hundredMetreSensor();
  s.clutter_density = 0.1;
  s.noise_texture_db = 2.0;
  return s;
}

/// Three scans per render keep each stage to a few seconds.
inline AppearanceOptions quickAppearanceOptions() {
  AppearanceOptions o;
  o.scans = 3;
  return o;
}

/// "parameter=value " for every named finding of the report (empty: nothing named).
inline std::string namedFindings(const AppearanceReport& rep) {
  std::string named;
  for (const auto& f : rep.findings)
    if (f.named) named += f.parameter + "=" + std::to_string(f.value) + " ";
  return named;
}

/// The catalogue stage alone, short: realism, clutter, near STC, curves and hold-out are
/// tested elsewhere (test_appearance_bands.cpp).
inline AppearanceOptions catalogueOnlyOptions() {
  AppearanceOptions o = quickAppearanceOptions();
  o.iterations = 2;
  o.realism = false;
  o.fit_clutter = false;
  o.fit_near_stc = false;
  o.relinearise = false;
  o.holdout = false;
  o.curve_iterations = 0;
  return o;
}

/// The held-out check as the appearance stage runs it after a fit that gave `fitted` back
/// exactly (the sensor given, not fitted): realism of both parts, the fitted sensor rendered
/// in the fit part's own scene, the worst held-out gap and detail::holdoutSceneCheck on top.
inline AppearanceReport holdoutCheck(const std::vector<PolarScan>& fit,
                                     const std::vector<PolarScan>& holdout,
                                     const sim::SensorConfig& fitted) {
  AppearanceOptions opt = quickAppearanceOptions();
  opt.scene = "recording";
  opt.scene_scans = std::make_shared<const std::vector<PolarScan>>(fit);
  AppearanceReport rep;
  rep.fitted = fitted;
  rep.realism_real = sim::computeRealism(fit, "fit part");
  rep.realism_holdout = sim::computeRealism(holdout, "held out");
  rep.realism_after = sim::computeRealism(renderReference(fitted, {}, opt, opt.seed + 1), "after");
  for (const auto& [name, gap] : fittedBandGaps(rep.realism_after, rep.realism_holdout))
    rep.worst_holdout_after = std::max(rep.worst_holdout_after, gap);
  detail::holdoutSceneCheck(fit, holdout, opt, rep);
  return rep;
}

}  // namespace spinradar::diagnose::testing
