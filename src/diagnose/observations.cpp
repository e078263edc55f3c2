// Step 1 of the diagnosis: predict every world target into each recorded scan, measure it in
// the recording and in the base re-simulation, and compute the regressors of each observation.
#include <algorithm>
#include <stdexcept>
#include <string>

#include "diagnose_steps.hpp"

namespace spinradar::diagnose::detail {

Association associateObservations(const DiagnoseInput& in, const DiagnoseOptions& opt,
                                  const std::vector<Effect>& cands, DiagnoseReport& rep,
                                  const MapModel* map) {
  Association as;
  std::vector<ScanGeometry>& geos = as.geos;
  std::vector<std::vector<int>>& obs_of_scan = as.obs_of_scan;
  std::vector<Gate>& gate_of_obs = as.gate_of_obs;
  double& sweep = as.sweep;
  obs_of_scan.resize(in.scans.size());
  sim::Simulator base_sim(in.world, in.trajectory, in.sensor, in.base, opt.seed);
  for (size_t k = 0; k < in.scans.size(); ++k) {
    const PolarScan& real = in.scans[k];
    geos.push_back(ScanGeometry::fromScan(real));
    const ScanGeometry& geo = geos.back();
    sweep += geo.sweep / in.scans.size();
    const auto views = targetViews(static_cast<int>(k), real, geo, in.world, in.trajectory,
                                   in.base, opt.conventions, opt.views);
    std::vector<Observation> cand_obs;
    std::vector<Gate> gates;
    for (const TargetView& v : views) {
      const auto pk = measurePeak(real, geo, v.pred.range, v.pred.azimuth, v.gate, opt.peaks);
      if (!pk) continue;
      Observation o;
      o.scan = static_cast<int>(k);
      o.target = v.target;
      o.range = v.pred.range;
      o.azimuth = v.pred.azimuth;
      o.stamp = v.pred.stamp;
      o.tau = v.pred.stamp - geo.firstStamp();
      const double t_true = v.pred.stamp - in.base.timestamp_offset;
      const Eigen::Vector3d vel = in.trajectory.bodyVelocity(t_true);
      o.vx = vel.x();
      o.vy = vel.y();
      o.yaw_rate = vel.z();
      o.yaw = in.trajectory.at(t_true).yaw;
      o.real_r = pk->range;
      o.real_az = pk->azimuth;
      const sim::Target& tg = in.world.targets[v.target];
      const double hp = 0.01, ha = 0.001;
      for (int q = 0; q < 2; ++q) {
        sim::Target moved = tg;
        (q == 0 ? moved.x : moved.y) += hp;
        const Prediction pq = predictTarget(moved, geo, in.trajectory, in.base, opt.conventions);
        o.tr[q] = (pq.range - v.pred.range) / hp;
        o.taz[q] = se2::wrapAngle(pq.azimuth - v.pred.azimuth) / hp;
      }
      for (Effect e : cands) {
        const double h = effectStep(e);
        const Prediction pe = predictTarget(tg, geo, in.trajectory, withEffect(in.base, e, h),
                                            opt.conventions);
        o.dr[static_cast<int>(e)] = (pe.range - v.pred.range) / h;
        o.daz[static_cast<int>(e)] = se2::wrapAngle(pe.azimuth - v.pred.azimuth) / h;
        if (map) {
          // The mapped position moves with the parameter too (it was placed under it).
          const Eigen::Vector2d& dp = map->dpos[v.target][static_cast<int>(e)];
          o.dr[static_cast<int>(e)] += o.tr[0] * dp.x() + o.tr[1] * dp.y();
          o.daz[static_cast<int>(e)] += o.taz[0] * dp.x() + o.taz[1] * dp.y();
        }
      }
      const PoseDelta deltas[3] = {{hp, 0, 0}, {0, hp, 0}, {0, 0, ha}};
      const double steps[3] = {hp, hp, ha};
      for (int q = 0; q < 3; ++q) {
        const Prediction pq =
            predictTarget(tg, geo, in.trajectory, in.base, opt.conventions, deltas[q]);
        o.nr[q] = (pq.range - v.pred.range) / steps[q];
        o.naz[q] = se2::wrapAngle(pq.azimuth - v.pred.azimuth) / steps[q];
      }
      cand_obs.push_back(o);
      gates.push_back(v.gate);
    }
    std::vector<const Observation*> ptrs;
    for (const auto& o : cand_obs) ptrs.push_back(&o);
    const auto sim_meas = measureSimulated(base_sim, real, geo, ptrs, gates, in, opt);
    for (size_t i = 0; i < cand_obs.size(); ++i) {
      if (!sim_meas[i].ok) continue;
      Observation o = cand_obs[i];
      o.e_r = o.real_r - sim_meas[i].range;
      o.e_az = se2::wrapAngle(o.real_az - sim_meas[i].azimuth);
      obs_of_scan[k].push_back(static_cast<int>(rep.obs.size()));
      rep.obs.push_back(o);
      gate_of_obs.push_back(gates[i]);
    }
  }
  if (rep.obs.size() < 10)
    throw std::runtime_error("diagnose: only " + std::to_string(rep.obs.size()) +
                             " target returns could be associated (need isolated point targets "
                             "of the world inside the radar's range)");
  {
    std::vector<int> t;
    for (const auto& o : rep.obs) t.push_back(o.target);
    std::sort(t.begin(), t.end());
    rep.targets_used = static_cast<int>(std::unique(t.begin(), t.end()) - t.begin());
  }
  return as;
}

}  // namespace spinradar::diagnose::detail
