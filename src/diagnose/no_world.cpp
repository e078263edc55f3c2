// Diagnosis without a world file (issue 10): the scene is mapped from one part of the
// recording (scene_map.cpp) and the rest is diagnosed against it. The mapped positions were
// placed under the physics being tested, so every regressor includes the map's own
// dependence on the parameter (map-aware regressors), the map noise is modelled per target
// (GLS), and the re-simulation re-places the map under each trial physics.
#include <array>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <Eigen/Dense>

#include "diagnose_steps.hpp"
#include "spinradar/diagnose/advice.hpp"
#include "spinradar/diagnose/diagnose.hpp"
#include "spinradar/diagnose/scene_map.hpp"

namespace spinradar::diagnose {
namespace {

// d(placed position)/d(reported range, reported azimuth) of one map peak.
Eigen::Matrix2d placementJacobian(const MapPeak& pk, const sim::Trajectory& traj,
                                  const sim::PhysicsConfig& ph) {
  const double hr = 0.01, ha = 1e-4;
  const Eigen::Vector2d p0 = placePeak(pk, traj, ph);
  MapPeak a = pk, b = pk;
  a.range += hr;
  b.azimuth += ha;
  Eigen::Matrix2d G;
  G.col(0) = (placePeak(a, traj, ph) - p0) / hr;
  G.col(1) = (placePeak(b, traj, ph) - p0) / ha;
  return G;
}

// Map-aware parts of the model: position sensitivities per effect, and the covariance of each
// mapped position from the scatter of its peaks (pooled over the map, in range and azimuth).
detail::MapModel mapModel(const SceneMap& map, const DiagnoseInput& in,
                          const std::vector<Effect>& cands) {
  detail::MapModel mm;
  const size_t nt = map.world.targets.size();
  std::array<Eigen::Vector2d, kNumEffects> zero;
  for (auto& v : zero) v = Eigen::Vector2d::Zero();
  mm.dpos.assign(nt, zero);
  for (Effect e : cands) {
    const double h = effectStep(e);
    const sim::World moved = replaceMap(map, in.trajectory, withEffect(in.base, e, h));
    for (size_t j = 0; j < nt; ++j)
      mm.dpos[j][static_cast<int>(e)] =
          Eigen::Vector2d(moved.targets[j].x - map.world.targets[j].x,
                          moved.targets[j].y - map.world.targets[j].y) / h;
  }
  std::vector<double> dr, da;
  std::vector<std::vector<Eigen::Matrix2d>> G(nt);
  for (size_t j = 0; j < nt; ++j) {
    const Eigen::Vector2d mean(map.world.targets[j].x, map.world.targets[j].y);
    const double n = static_cast<double>(map.members[j].size());
    const double dof = n > 1 ? std::sqrt(n / (n - 1)) : 1.0;
    for (const MapPeak& pk : map.members[j]) {
      G[j].push_back(placementJacobian(pk, in.trajectory, in.base));
      const Eigen::Vector2d polar =
          G[j].back().inverse() * (placePeak(pk, in.trajectory, in.base) - mean);
      dr.push_back(polar.x() * dof);
      da.push_back(polar.y() * dof);
    }
  }
  const double sr = detail::noiseScale(dr, detail::rangeNoiseFloor(in.sensor));
  const double sa = detail::noiseScale(da, detail::azimuthNoiseFloor(in.sensor));
  const Eigen::Vector2d D(sr * sr, sa * sa);
  mm.cov.assign(nt, Eigen::Matrix2d::Zero());
  for (size_t j = 0; j < nt; ++j) {
    const double n = static_cast<double>(G[j].size());
    for (const auto& g : G[j]) mm.cov[j] += g * D.asDiagonal() * g.transpose() / (n * n);
  }
  const SceneMap* mp = &map;
  const sim::Trajectory* traj = &in.trajectory;
  mm.remap = [mp, traj](const sim::PhysicsConfig& ph) { return replaceMap(*mp, *traj, ph); };
  return mm;
}

}  // namespace

namespace {

// Steps 1-5 of the diagnosis on the test scans against one map.
DiagnoseReport diagnoseAgainstMap(const DiagnoseInput& in, const DiagnoseOptions& opt,
                                  const SceneMap& map) {
  if (map.world.targets.empty())
    throw std::runtime_error("diagnose: no static returns were stable across the map scans");
  DiagnoseInput test;
  test.world = map.world;
  test.trajectory = in.trajectory;
  test.sensor = in.sensor;
  test.base = in.base;
  for (int k : map.test_scans) test.scans.push_back(in.scans[k]);
  DiagnoseOptions o = opt;
  o.target_nuisance = false;  // the map's dependence on each effect is in the regressors

  DiagnoseReport rep;
  rep.base = in.base;
  rep.scans = static_cast<int>(test.scans.size());
  std::vector<Effect> cands;
  for (Effect e : allEffects())
    if (!(e == Effect::MotionDistortion && in.base.motion_distortion)) cands.push_back(e);
  for (Effect e : cands) rep.effect_names_tested.push_back(effectName(e));
  const detail::MapModel mm = mapModel(map, test, cands);
  const detail::Association as = detail::associateObservations(test, o, cands, rep, &mm);
  detail::nameAndFitEffects(test, o, cands, rep, &mm);
  detail::resimulateWithEffects(test, o, as, rep, &mm);
  rep.locate = locateResiduals(rep.obs, false);
  // How much of each signature the map cancels (map and test views see it alike): the
  // map-aware regressor against the one a world file would give.
  for (auto& c : rep.candidates) {
    const int e = static_cast<int>(c.effect);
    double n_map = 0, n_direct = 0;
    for (const auto& ob : rep.obs) {
      if (!ob.inlier) continue;
      const Eigen::Vector2d& dp = mm.dpos[ob.target][e];
      const double mr = ob.tr[0] * dp.x() + ob.tr[1] * dp.y();
      const double ma = ob.taz[0] * dp.x() + ob.taz[1] * dp.y();
      const double r = ob.dr[e] / rep.sigma_r, a = ob.daz[e] / rep.sigma_az;
      const double r0 = (ob.dr[e] - mr) / rep.sigma_r, a0 = (ob.daz[e] - ma) / rep.sigma_az;
      n_map += r * r + a * a;
      n_direct += r0 * r0 + a0 * a0;
    }
    if (n_direct <= 0) continue;
    c.absorbed = std::clamp(1.0 - n_map / n_direct, 0.0, 1.0);
    bool found = false;
    for (const auto& r : rep.effects) found = found || r.effect == c.effect;
    if (!found && c.absorbed > 0.9) {
      // Rough smallest change this split could detect (z = 4 on the map-aware signature,
      // map noise ignored).
      const double detectable = n_map > 0 ? 4.0 / std::sqrt(n_map) : INFINITY;
      std::ostringstream n;
      n << effectName(c.effect) << ": " << std::lround(100 * c.absorbed)
        << "% of its signature is cancelled by the map (map and test scans see it alike); "
        << "with this split only a change beyond about " << detectable << " "
        << effectUnit(c.effect) << " would show. " << revealingSplit(c.effect);
      rep.notes.push_back(n.str());
    }
  }
  std::ostringstream sm;
  sm << "built from the recording: " << map.split << "; " << map.map_scans.size()
     << " map scans, " << map.test_scans.size() << " test scans, "
     << map.world.targets.size()
     << " stable point returns; regressors include the map's own dependence on each effect";
  rep.scene_model = sm.str();
  return rep;
}

}  // namespace

DiagnoseReport diagnoseWithoutWorld(const DiagnoseInput& in, const DiagnoseOptions& opt,
                                    const std::string& split) {
  const auto t_start = std::chrono::steady_clock::now();
  const SceneMap map = buildSceneMap(in.scans, in.trajectory, in.sensor, in.base, split);
  DiagnoseReport rep = diagnoseAgainstMap(in, opt, map);
  if (rep.mismatch_found) {
    // A large effect smears each target's placements under the base physics (some targets are
    // lost, some merged). Group the peaks again as placed under the fitted physics and repeat;
    // the targets are still placed under the base, so the test is the same, on a better map.
    const sim::PhysicsConfig fitted = rep.fitted;
    const SceneMap map2 =
        buildSceneMap(in.scans, in.trajectory, in.sensor, in.base, split, {}, &fitted);
    DiagnoseReport rep2 = diagnoseAgainstMap(in, opt, map2);
    std::ostringstream n;
    n << "The map's peaks were grouped a second time as placed under the first fit (";
    for (size_t i = 0; i < rep.effects.size(); ++i)
      n << (i ? ", " : "") << rep.effects[i].name << " " << rep.effects[i].value;
    n << "): " << map.world.targets.size() << " -> " << map2.world.targets.size()
      << " mapped targets, " << rep.obs.size() << " -> " << rep2.obs.size()
      << " test returns; the figures are from the second pass.";
    rep2.notes.push_back(n.str());
    rep = std::move(rep2);
  }
  rep.notes.push_back(
      "No world file: the scene was mapped from the map scans. The mapped positions move with "
      "each effect as the test predictions do, so only what the map and test viewpoints see "
      "differently is identifiable (out-and-back: range offset, Doppler, latency, motion "
      "distortion; turns of opposite sign: azimuth offset, latency; speed changes: Doppler).");
  rep.runtime_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return rep;
}

}  // namespace spinradar::diagnose
