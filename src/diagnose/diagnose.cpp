// The diagnosis pipeline: re-simulate, associate, regress, fit, re-simulate with the fit.
// Steps: observations.cpp (1, associate), name_fit.cpp (2-4, name and fit), resimulate.cpp
// (5, before/after); the scene built from the recording (no world file) is in scene_map.cpp.
#include "spinradar/diagnose/diagnose.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "diagnose_steps.hpp"
#include "spinradar/diagnose/chirp_doppler.hpp"

namespace spinradar::diagnose {

double Observation::radialVelocity() const {
  // Ray direction in the sensor frame for a clockwise azimuth: (cos, -sin).
  return vx * std::cos(azimuth) - vy * std::sin(azimuth);
}

namespace {

// The catalogue stage (steps 1-5 of docs/diagnose.md) on the stamps as given.
DiagnoseReport catalogue(const DiagnoseInput& in, const DiagnoseOptions& opt) {
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

}  // namespace

ChirpDopplerOptions chirpOptionsFor(const sim::PhysicsConfig& base) {
  ChirpDopplerOptions o;
  if (base.doppler > 0) o.beta = base.doppler;  // the base model's beta turns beta|v| into |v|
  return o;
}

namespace {

bool baseHasBursts(const sim::PhysicsConfig& base) {
  const auto it = base.extra.find("stamp_bursts");
  if (it == base.extra.end() || it->is_null()) return false;
  return !(it->is_boolean() && !it->get<bool>());
}

}  // namespace

DiagnoseReport diagnose(const DiagnoseInput& in, const DiagnoseOptions& opt) {
  return opt.timing ? diagnoseRecording(in, opt, true) : catalogue(in, opt);
}

DiagnoseReport diagnoseRecording(const DiagnoseInput& in, const DiagnoseOptions& opt,
                                 bool with_world, const std::string& split) {
  const auto t_start = std::chrono::steady_clock::now();
  TimingReport timing = analyseStamps(in.scans, in.sensor.rotation_hz, opt.timing_options);
  timing.chirp_doppler = chirpDopplerSummary(in.scans, chirpOptionsFor(in.base));
  DiagnoseOptions o = opt;
  o.timing = false;
  auto run = [&](const DiagnoseInput& x) {
    return with_world ? catalogue(x, o) : diagnoseWithoutWorld(x, o, split);
  };
  DiagnoseReport rep;
  if (timing.bursts && !baseHasBursts(in.base)) {
    // Bursty stamps are arrival times: the catalogue stage works on the fitted firing times.
    DiagnoseInput fixed = in;
    fixed.scans = correctedStamps(in.scans, timing);
    timing.notes.push_back("The catalogue stage used the uniform firing times fitted from the "
                           "stamps, not the recorded (bursty) stamps.");
    rep = run(fixed);
  } else {
    if (baseHasBursts(in.base))
      timing.notes.push_back("The base physics already renders stamp bursts (" +
                             in.base.extra["stamp_bursts"].dump() +
                             "): compare its size and spacing with the fit above.");
    rep = run(in);
  }
  // Rotation jitter with nominal stamps: without motion distortion the simulator renders the
  // whole scan from the pose at instant_fraction of the (stretched) sweep.
  const double sweep = timing.period_mean > 0 ? timing.period_mean : 1.0 / in.sensor.rotation_hz;
  const double tau_fixed =
      in.base.motion_distortion ? -1.0 : opt.conventions.instant_fraction * sweep;
  // Residuals for the jitter fit: real minus re-simulated with the kept catalogue effects
  // (exact, so peak-interpolation biases cancel as in the catalogue stage); the linear fit's
  // residuals only when nothing was re-simulated. Returns the re-simulation lost are left out.
  std::vector<Observation> jobs;
  const bool resim = !rep.after_e_r.empty();
  for (size_t i = 0; i < rep.obs.size(); ++i) {
    Observation o = rep.obs[i];
    if (resim) {
      o.fit_r = rep.after_e_r.back()[i];
      o.fit_az = rep.after_e_az.back()[i];
      if (!std::isfinite(o.fit_r) || !std::isfinite(o.fit_az)) continue;
    }
    if (!with_world) {
      // Without a world the catalogue regressors are map-aware (the mapped position moves
      // with a parameter because the map scans were placed under it). A scan's own stretch
      // does not move the map (map scans have their own, independent stretches), so its
      // regressor is the direct one: the prediction's change when this scan's pose is shifted
      // in time, d(range, azimuth)/d(body pose) * body velocity (timestamp offset +dt moves
      // the true time by -dt).
      const int to = static_cast<int>(Effect::TimestampOffset);
      o.dr[to] = -(o.nr[0] * o.vx + o.nr[1] * o.vy + o.nr[2] * o.yaw_rate);
      o.daz[to] = -(o.naz[0] * o.vx + o.naz[1] * o.vy + o.naz[2] * o.yaw_rate);
    }
    jobs.push_back(o);
  }
  analyseJitter(jobs, rep.scans, rep.sigma_r, rep.sigma_az,
                detail::rangeNoiseFloor(in.sensor), detail::azimuthNoiseFloor(in.sensor),
                tau_fixed, opt.target_nuisance, timing, opt.timing_options);
  double offset = 0, offset_sd = 0;
  for (const auto& e : rep.effects)
    if (e.effect == Effect::TimestampOffset) {
      offset = e.value;
      offset_sd = std::max(e.stddev, 1e-12);
    }
  adviseTiming(timing, offset, offset_sd);
  rep.timing = std::move(timing);
  if (!rep.timing.findings.empty()) rep.mismatch_found = true;
  rep.runtime_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return rep;
}

}  // namespace spinradar::diagnose
