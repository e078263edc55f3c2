// The diagnosis pipeline: re-simulate, associate, regress, fit, re-simulate with the fit.
// Steps: observations.cpp (1, associate), name_fit.cpp (2-4, name and fit), resimulate.cpp
// (5, before/after); the scene built from the recording (no world file) is in scene_map.cpp.
#include "spinradar/diagnose/diagnose.hpp"

#include <chrono>
#include <cmath>
#include <stdexcept>

#include "diagnose_steps.hpp"

namespace spinradar::diagnose {

double Observation::radialVelocity() const {
  // Ray direction in the sensor frame for a clockwise azimuth: (cos, -sin).
  return vx * std::cos(azimuth) - vy * std::sin(azimuth);
}

DiagnoseReport diagnose(const DiagnoseInput& in, const DiagnoseOptions& opt) {
  const auto t_start = std::chrono::steady_clock::now();
  DiagnoseReport rep;
  rep.base = in.base;
  rep.scans = static_cast<int>(in.scans.size());
  if (in.scans.empty()) throw std::runtime_error("diagnose: the recording holds no scans");

  std::vector<Effect> cands;
  for (Effect e : allEffects())
    if (!(e == Effect::MotionDistortion && in.base.motion_distortion)) cands.push_back(e);
  for (Effect e : cands) rep.effect_names_tested.push_back(effectName(e));

  // 1. Predict, re-simulate with the base physics, measure both, build regressors.
  const detail::Association as = detail::associateObservations(in, opt, cands, rep);
  // 2-4. Scales and outliers (two passes), stepwise selection, joint fit, notes.
  detail::nameAndFitEffects(in, opt, cands, rep);
  // 5. Re-simulate with the effects added one at a time; residual statistics per step.
  detail::resimulateWithEffects(in, opt, as, rep);
  rep.locate = locateResiduals(rep.obs, false);
  rep.runtime_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return rep;
}

}  // namespace spinradar::diagnose
