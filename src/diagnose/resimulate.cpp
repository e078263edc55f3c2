// Step 5 of the diagnosis: re-simulate the recording with the fitted effects added one at a
// time and measure the same peaks (residual figures before/after, ablation).
#include <array>
#include <map>
#include <sstream>

#include "diagnose_steps.hpp"

namespace spinradar::diagnose::detail {
namespace {

void demeanByTarget(const std::vector<Observation>& obs, std::vector<double>& er,
                    std::vector<double>& eaz, const std::vector<bool>& use) {
  std::map<int, std::array<double, 3>> acc;
  for (size_t i = 0; i < obs.size(); ++i) {
    if (!use[i] || !std::isfinite(er[i])) continue;
    auto& a = acc[obs[i].target];
    a[0] += er[i];
    a[1] += eaz[i];
    a[2] += 1;
  }
  for (size_t i = 0; i < obs.size(); ++i) {
    auto it = acc.find(obs[i].target);
    if (it == acc.end() || !std::isfinite(er[i])) continue;
    er[i] -= it->second[0] / it->second[2];
    eaz[i] -= it->second[1] / it->second[2];
  }
}

}  // namespace

// Renders the scan whose recorded first stamp is that of `real` under `physics` and measures
// every view's peak in it.
std::vector<Measured> measureSimulated(const sim::Simulator& sim, const PolarScan& real,
                                       const ScanGeometry& geo_real,
                                       const std::vector<const Observation*>& views,
                                       const std::vector<Gate>& gates, const DiagnoseInput& in,
                                       const DiagnoseOptions& opt, const sim::World* world) {
  const sim::World& w = world ? *world : in.world;
  const sim::PhysicsConfig& ph = sim.physics();
  const double t0 = geo_real.firstStamp() - ph.timestamp_offset;
  PolarScan s = sim.renderScanAt(t0);
  s.range_offset = real.range_offset;  // both read with the recording's bin convention
  s.range_resolution = real.range_resolution;
  const ScanGeometry geo = ScanGeometry::fromScan(s);
  std::vector<Measured> out(views.size());
  for (size_t i = 0; i < views.size(); ++i) {
    const Prediction p = predictTarget(w.targets[views[i]->target], geo, in.trajectory, ph,
                                       opt.conventions);
    if (!p.ok) continue;
    const auto pk = measurePeak(s, geo, p.range, p.azimuth, gates[i], opt.peaks);
    if (!pk) continue;
    out[i] = {true, pk->range, pk->azimuth};
  }
  return out;
}

// With target positions as nuisance (demean), residual figures are taken after removing each
// target's mean residual (what refitting its position would absorb).
ResidualStats residualStats(bool demean, const std::vector<Observation>& obs,
                            std::vector<double> er, std::vector<double> eaz,
                            const std::vector<bool>& use, double sweep) {
  if (demean) demeanByTarget(obs, er, eaz, use);
  ResidualStats s;
  double sp = 0, sr = 0, sa = 0;
  for (size_t i = 0; i < obs.size(); ++i) {
    if (!use[i] || !std::isfinite(er[i])) continue;
    const double et = obs[i].range * eaz[i];
    sp += er[i] * er[i] + et * et;
    sr += er[i] * er[i];
    sa += eaz[i] * eaz[i];
    ++s.n;
  }
  if (s.n == 0) return s;
  s.position_rms = std::sqrt(sp / s.n);
  s.range_rms = std::sqrt(sr / s.n);
  s.azimuth_rms = std::sqrt(sa / s.n);
  s.time_rms = s.azimuth_rms / (2.0 * M_PI) * sweep;
  return s;
}

void resimulateWithEffects(const DiagnoseInput& in, const DiagnoseOptions& opt,
                           const Association& as, DiagnoseReport& rep, const MapModel* map) {
  const std::vector<ScanGeometry>& geos = as.geos;
  const std::vector<std::vector<int>>& obs_of_scan = as.obs_of_scan;
  const std::vector<Gate>& gate_of_obs = as.gate_of_obs;
  const double sweep = as.sweep;
  const double floor_r = rangeNoiseFloor(in.sensor);
  const double floor_a = azimuthNoiseFloor(in.sensor);
  std::vector<bool> use(rep.obs.size());
  for (size_t i = 0; i < rep.obs.size(); ++i) use[i] = rep.obs[i].inlier;
  {
    std::vector<double> r0, a0;
    for (const auto& o : rep.obs) {
      r0.push_back(o.e_r);
      a0.push_back(o.e_az);
    }
    rep.before = residualStats(opt.target_nuisance, rep.obs, r0, a0, use, sweep);
  }
  rep.after = rep.before;
  if (opt.resimulate_after && !rep.effects.empty()) {
    // Ablation: each effect is kept only if switching it on in the simulator lowers the
    // re-simulated residual; a selection the re-simulation does not confirm (a linearisation
    // artefact of a larger effect) is reported in the notes instead.
    sim::PhysicsConfig confirmed = in.base;
    std::vector<double> prev_er(rep.obs.size()), prev_ea(rep.obs.size());
    for (size_t i = 0; i < rep.obs.size(); ++i) {
      prev_er[i] = rep.obs[i].e_r;
      prev_ea[i] = rep.obs[i].e_az;
    }
    std::vector<EffectResult> kept;
    auto addEffect = [](const sim::PhysicsConfig& ph, const EffectResult& r) {
      return r.effect == Effect::MotionDistortion ? withEffect(ph, r.effect, r.change > 0.5 ? 1 : 0)
                                                  : withEffect(ph, r.effect, r.change);
    };
    // Re-simulates with `ph` and measures the residuals against the previous step's.
    struct Trial {
      std::vector<double> er_j, ea_j, er_s, ea_s;
      ResidualStats before, after;
      bool improved() const { return after.position_rms < before.position_rms; }
    };
    auto trial = [&](const sim::PhysicsConfig& ph) {
      Trial t;
      // Without a world file the map is re-placed under the trial physics first.
      const sim::World world = map && map->remap ? map->remap(ph) : in.world;
      sim::Simulator s(world, in.trajectory, in.sensor, ph, opt.seed);
      t.er_j.assign(rep.obs.size(), NAN);
      t.ea_j.assign(rep.obs.size(), NAN);
      for (size_t k = 0; k < in.scans.size(); ++k) {
        std::vector<const Observation*> ptrs;
        std::vector<Gate> gates;
        for (int i : obs_of_scan[k]) {
          ptrs.push_back(&rep.obs[i]);
          gates.push_back(gate_of_obs[i]);
        }
        if (ptrs.empty()) continue;
        const auto m = measureSimulated(s, in.scans[k], geos[k], ptrs, gates, in, opt, &world);
        for (size_t q = 0; q < ptrs.size(); ++q) {
          if (!m[q].ok) continue;
          const int i = obs_of_scan[k][q];
          t.er_j[i] = rep.obs[i].real_r - m[q].range;
          t.ea_j[i] = se2::wrapAngle(rep.obs[i].real_az - m[q].azimuth);
        }
      }
      // Observations the re-simulation lost count with their base residual (conservative);
      // peaks that jumped to another return (beyond outlier_sigma of this step's robust
      // scale) are left out of this step's before and after figures alike.
      t.er_s = t.er_j;
      t.ea_s = t.ea_j;
      std::vector<double> rr, ra;
      for (size_t i = 0; i < t.er_s.size(); ++i) {
        if (!std::isfinite(t.er_s[i])) {
          t.er_s[i] = rep.obs[i].e_r;
          t.ea_s[i] = rep.obs[i].e_az;
        }
        if (use[i]) {
          rr.push_back(t.er_s[i]);
          ra.push_back(t.ea_s[i]);
        }
      }
      const double sr_j = noiseScale(rr, floor_r), sa_j = noiseScale(ra, floor_a);
      std::vector<bool> use_j = use;
      for (size_t i = 0; i < t.er_s.size(); ++i)
        if (std::fabs(t.er_s[i]) > opt.outlier_sigma * sr_j ||
            std::fabs(t.ea_s[i]) > opt.outlier_sigma * sa_j)
          use_j[i] = false;
      t.after = residualStats(opt.target_nuisance, rep.obs, t.er_s, t.ea_s, use_j, sweep);
      t.before = residualStats(opt.target_nuisance, rep.obs, prev_er, prev_ea, use_j, sweep);
      return t;
    };
    auto accept = [&](const sim::PhysicsConfig& ph, const Trial& t, EffectResult rj) {
      rj.residual_rms_before = t.before.position_rms;
      rj.residual_rms_after = t.after.position_rms;
      rj.range_rms_before = t.before.range_rms;
      rj.range_rms_after = t.after.range_rms;
      rj.azimuth_rms_before = t.before.azimuth_rms;
      rj.azimuth_rms_after = t.after.azimuth_rms;
      confirmed = ph;
      prev_er = t.er_s;
      prev_ea = t.ea_s;
      rep.after_step.push_back(t.after);
      rep.after_e_r.push_back(t.er_j);
      rep.after_e_az.push_back(t.ea_j);
      kept.push_back(rj);
    };
    for (size_t j = 0; j < rep.effects.size(); ++j) {
      const EffectResult& rj = rep.effects[j];
      const sim::PhysicsConfig ph = addEffect(confirmed, rj);
      const Trial t = trial(ph);
      if (t.improved()) {
        accept(ph, t, rj);
        continue;
      }
      // Confounded effects can only help together (e.g. a latency and a Doppler shift whose
      // range signatures are opposite): try this one with every later selected effect at once.
      if (j + 1 < rep.effects.size()) {
        sim::PhysicsConfig ph_all = ph;
        for (size_t q = j + 1; q < rep.effects.size(); ++q) ph_all = addEffect(ph_all, rep.effects[q]);
        const Trial ta = trial(ph_all);
        if (ta.improved()) {
          for (size_t q = j; q < rep.effects.size(); ++q) accept(ph_all, ta, rep.effects[q]);
          std::ostringstream n;
          n << "effects from " << rj.name << " on were confirmed together: switched on alone "
            << rj.name << " did not lower the residual, all of them at once did ("
            << ta.before.position_rms << " -> " << ta.after.position_rms << " m).";
          rep.notes.push_back(n.str());
          break;
        }
      }
      std::ostringstream n;
      n << rj.name << " (" << rj.value << " +- " << rj.stddev << " " << rj.unit << ", z "
        << rj.significance << ") passed the regression test but switching it on in the "
        << "simulator did not lower the residual (" << t.before.position_rms << " -> "
        << t.after.position_rms << " m); not reported as an effect.";
      rep.notes.push_back(n.str());
    }
    rep.effects.clear();
    for (const EffectResult& r : kept) {
      // Practical significance: an effect under half a bin (or row) that lowers the re-simulated
      // residual by under 5 % is negligible, whatever its z (kept in the fitted physics).
      const double drop = r.residual_rms_before > 0
                              ? 1.0 - r.residual_rms_after / r.residual_rms_before : 0.0;
      double size = -1;  // in bins or rows; -1 = no resolution scale for this effect
      std::string unit;
      if (r.effect == Effect::RangeOffset) {
        size = std::fabs(r.change) / in.sensor.range_resolution, unit = "bins";
      } else if (r.effect == Effect::AzimuthOffset) {
        size = std::fabs(r.change) * in.sensor.azimuths / (2 * M_PI), unit = "rows";
      } else if (r.effect == Effect::TimestampOffset) {
        size = std::fabs(r.change) * in.sensor.rotation_hz * in.sensor.azimuths, unit = "rows of time";
        const double half = 0.5 / in.sensor.rotation_hz;
        if (!in.base.motion_distortion && std::fabs(std::fabs(r.change) - half) < 0.1 * half) {
          std::ostringstream n;
          n << "The fitted timestamp offset (" << r.change << " s) is half a rotation on a model "
            << "without motion distortion: it is the scan-pose-time convention (the pose of a scan "
            << "taken at its first azimuth vs mid-sweep; physics \"scan_pose_time\"), not a latency.";
          rep.notes.push_back(n.str());
        }
      }
      if (size >= 0 && size < 0.5 && drop < 0.05) {
        std::ostringstream n;
        n << r.name << " = " << r.value << " +- " << r.stddev << " " << r.unit << " (z "
          << r.significance << ") is negligible: " << size << " " << unit << ", residual "
          << r.residual_rms_before << " -> " << r.residual_rms_after << " m (" << 100 * drop
          << " % drop); statistically significant, practically nothing.";
        rep.notes.push_back(n.str());
        continue;
      }
      rep.effects.push_back(r);
    }
    rep.fitted = confirmed;
    rep.mismatch_found = !rep.effects.empty();
    if (!rep.after_step.empty()) {
      std::vector<bool> all = use;
      rep.after = residualStats(opt.target_nuisance, rep.obs, prev_er, prev_ea, all, sweep);
    }
  } else {
    // No re-simulation: the linear model's residuals stand in for the "after" figures.
    std::vector<double> fr, fa;
    for (const auto& o : rep.obs) {
      fr.push_back(o.fit_r);
      fa.push_back(o.fit_az);
    }
    rep.after = residualStats(opt.target_nuisance, rep.obs, fr, fa, use, sweep);
    for (auto& r : rep.effects) {
      r.residual_rms_before = rep.before.position_rms;
      r.residual_rms_after = rep.after.position_rms;
    }
  }
}

}  // namespace spinradar::diagnose::detail
