// EstimatorConfig::keyframe_graph (issue 19): a sliding-window pose graph of keyframes.
//
// Why: with glint (scattering centres that move from scan to scan) every registration of a
// scan to its keyframe carries an independent heading error (~0.15 deg with ~40 pairs under
// 0.14 m glint), and the keyframe chain adds one at every switch: a random walk. A better
// pairwise registration cannot remove it; averaging over several keyframes can. So a scan
// that becomes the keyframe is registered against each keyframe of the window (the last
// keyframe_graph keyframes: the current one by track()'s own registration, the earlier ones
// by registerToPast with weak and proximity registrations allowed, each gated by chi-square
// against the chained prediction), and the window is solved as a pose graph: nodes are the
// keyframes' mid-scan world poses over [x, y, yaw], edges every registration between two of
// them with its [x, y, yaw] covariance (the current keyframe's and the earlier ones' kept
// from when they were made), the oldest node held. The new keyframe takes its solved pose;
// the earlier nodes' solved poses serve the predictions of later windows only (published
// poses stay causal: nothing already published is changed). Its covariance stays the chained
// one (see the end of solveGraph).
// Extra registrations only at keyframe switches. Measured (drift, cost, variants):
// docs/sensor_columns/round11_keyframe_graph.md.
#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Dense>

#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/keyframe_tracker.hpp"
#include "spinradar/estimation/pose_graph.hpp"

namespace spinradar {

namespace {

/// The extra registrations' covariances are taken this many times over: against keyframes
/// up to keyframe_graph switches back their errors are not all independent of the chain's
/// (the same map points, the same undistortion), and weighed as given they pulled the narrow
/// and dense-clutter columns off (keyframe_graph 6, 1 -> 2: city_oxford 0.237 -> 0.210 %,
/// city_mulran 0.168 -> 0.152; 4 lost city_oxford_glint0.14 0.42 -> 0.53).
constexpr double kGraphEdgeInflation = 2.0;

}  // namespace

bool KeyframeTracker::solveGraph(const FeatureFrame& cur, double c, const Eigen::Matrix3d& T_jk,
                                 const Eigen::Matrix3d& C_jk, Eigen::Matrix3d& M_k) {
  if (past_count_ == 0) return false;
  const Eigen::Matrix3d M_j = T_wj_ * se2::exp(key_c_ * key_xi_);
  // Extra registrations against past_[i], predicted along the chain (as fuseWithPast).
  Eigen::Matrix3d X, C;
  for (size_t i = 0; i < past_count_; ++i) {
    predictAgainstPast(i, T_jk, C_jk, X, C);
    Eigen::Matrix3d T_b, C_b;
    if (!registerToPast(cur, past_[i], c, X, C, T_b, C_b, true)) {
      ++fusions_rejected_;
      continue;
    }
    const Eigen::Matrix3d La = se2::leftPerturbationToXyYaw(X).inverse();
    const Eigen::Matrix3d Lb = se2::leftPerturbationToXyYaw(T_b).inverse();
    const Eigen::Vector3d d = se2::log(T_b * se2::inverse(X));
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(La * C * La.transpose() + Lb * C_b * Lb.transpose());
    if (ldlt.info() != Eigen::Success || d.dot(ldlt.solve(d)) > kFusionChi2) {
      ++fusions_rejected_;
      continue;
    }
    ++fusions_accepted_;
    new_edges_.push_back(GraphEdge{past_[i].stamp, T_b, kGraphEdgeInflation * C_b});
  }
  if (new_edges_.size() < 2) return false;  // the chain only: nothing to average
  // Nodes, oldest first: past_[count - 1] .. past_[0], the current keyframe, the new one.
  // (graph_: buffers kept from switch to switch, no allocation after warm-up.)
  const int n = static_cast<int>(past_count_) + 2;
  std::vector<int64_t>& stamp = graph_.stamp;
  std::vector<Eigen::Vector3d>& x = graph_.x;
  std::vector<const std::vector<GraphEdge>*>& edges = graph_.edges;
  stamp.resize(n);
  x.resize(n);
  edges.resize(n);
  for (size_t i = 0; i < past_count_; ++i) {
    const int k = static_cast<int>(past_count_ - 1 - i);
    stamp[k] = past_[i].stamp;
    x[k] = se2::toXyYaw(past_[i].M_w);
    edges[k] = &past_[i].edges;
  }
  stamp[n - 2] = key_stamp_;
  x[n - 2] = se2::toXyYaw(M_j);
  edges[n - 2] = &key_edges_;
  stamp[n - 1] = cur.stamp_ns;
  x[n - 1] = se2::toXyYaw(M_j * T_jk);
  edges[n - 1] = &new_edges_;
  std::vector<PoseGraphEdge>& pg = graph_.pg;
  std::vector<int>& candidates = graph_.candidates;  // the new keyframe's extra edges
  std::vector<int>& new_index = graph_.new_index;
  pg.clear();
  candidates.clear();
  new_index.clear();
  for (int b = 1; b < n; ++b) {
    for (size_t k = 0; k < edges[b]->size(); ++k) {
      const GraphEdge& e = (*edges[b])[k];
      int a = -1;
      for (int q = 0; q < b; ++q)
        if (stamp[q] == e.to) a = q;
      if (a < 0) continue;  // to a keyframe that left the window
      if (b == n - 1 && k > 0) {
        candidates.push_back(static_cast<int>(pg.size()));
        new_index.push_back(static_cast<int>(k));
      }
      pg.push_back(PoseGraphEdge{a, b, se2::toXyYaw(e.Z), e.C});
    }
  }
  // keyframe_graph_screen: each extra edge of the new keyframe against the window without it
  // (pose_graph.cpp); an edge the rest of the window contradicts (chi-square, 99 %, 3 dof) is
  // dropped, the worst first, and not kept for later windows. Off: on the turn entry it was
  // meant for the edges agree within their covariances (round11 doc), and it lost the glint gain.
  std::vector<bool>& skip = graph_.skip;
  skip.clear();
  const int dropped =
      config_.keyframe_graph_screen ? screenEdges(x, pg, candidates, kFusionChi2, skip) : 0;
  if (dropped > 0) {
    std::vector<GraphEdge>& kept = graph_.kept;
    kept.clear();
    for (size_t k = 0; k < new_edges_.size(); ++k) {
      bool drop = false;
      for (size_t q = 0; q < candidates.size(); ++q)
        if (new_index[q] == static_cast<int>(k) && skip[candidates[q]]) drop = true;
      if (!drop) kept.push_back(new_edges_[k]);
    }
    new_edges_.swap(kept);
    graph_edges_dropped_ += dropped;
    fusions_accepted_ -= dropped;
    fusions_rejected_ += dropped;
    if (new_edges_.size() < 2) return false;
  }
  // The solved poses only: the new keyframe keeps its chained covariance.
  // The window's marginal would treat the edges as independent, and they are not (the same
  // map points, the same undistortion): published, it made the accumulated pose
  // over-confident (test_keyframe_covariance, NEES mean against 3 expected: tight_turns peaks
  // 2.89 without the graph -> 8.79, city layout 2 rows 2.34 -> 7.73; the chained one with the
  // graph's poses 3.29 and 2.17).
  if (!solvePoseGraph(x, pg, skip, nullptr, graph_.solve)) return false;
  M_k = se2::fromXyYaw(x[n - 1]);
  // keyframe_graph_step: the window's heading correction is a rotation about its held oldest
  // node, so it moves the new keyframe sideways by the correction times up to ~60 m, a step in
  // the published positions. Where the chain's heading is already good (narrow-beam and
  // narrow-PSF models) those corrections are mostly noise: against the truth, keyframe steps on
  // straights 0.6-0.8 -> 2.2 cm rms sideways (city_narrow layout 1, city_boreas_rt, seed 1).
  // So the solved window is moved (translated: a change of gauge, its relative poses and
  // headings unchanged) until the current keyframe sits at its published position: the new
  // keyframe takes the window's step from there and the window's heading, and the earlier
  // nodes stay consistent with both for later windows (leaving them where they were solved
  // lost city_oxford_glint0.14 +11 %). Seeds 1-3: docs/sensor_columns/round13_graph_losses.md.
  const bool shift = config_.keyframe_graph_step;
  if (shift) {
    const Eigen::Vector2d d = M_j.topRightCorner<2, 1>() - x[n - 2].head<2>();
    for (int k = 0; k < n; ++k) x[k].head<2>() += d;
    M_k = se2::fromXyYaw(x[n - 1]);
  }
  // The earlier nodes take their solved poses (for later predictions and windows).
  for (size_t i = 0; i + (shift ? 0 : 1) < past_count_; ++i)  // the held one too when moved
    past_[i].M_w = se2::fromXyYaw(x[past_count_ - 1 - i]);
  T_wj_ = se2::fromXyYaw(x[n - 2]) * se2::exp(-key_c_ * key_xi_);
  return true;
}

// EstimatorConfig::keyframe_graph_rate. Within a scan the yaw rate trades against the yaw (a
// scan undistorted with one constant rate while the rate ramps has no single mid-scan pose),
// so the chained registration's mid-scan pose and its velocity (where the registration's own
// yaw rate is used, xi_key = xi) have correlated errors, and the scan-start pose it is
// published at (mid-scan moved back by c xi) is better than either: at a turn entry of
// city_narrow layout 2 (23.75 s, 25 -> 36 deg/s inside the scan) the mid-scan yaw was -0.51
// deg off and the published one -0.02. The graph corrected the mid-scan yaw (+0.006) but not
// the rate, and the published pose went +0.55 deg off and stayed so (the keyframe map was
// undistorted with that rate). So the velocity takes the correction that goes with the graph's
// pose correction under the registration's joint covariance (Gaussian conditioning of xi on the
// relative pose, left perturbation): dxi = C_xi,T C_T,T^-1 delta. Where the pair velocity
// is used its cross terms are zero (track()): no change. The keyframe's map and published
// pose follow. Published yaw error at that turn entry 0.55 -> 0.06 deg (worst over t = 23.5-28
// s 1.33 -> 0.45, no graph 0.98; sim_test_keyframe_graph_turn_entry); drift (keyframe+peaks,
// window 6, seeds 1-3): docs/sensor_columns/round12_graph_rate.md.
Eigen::Vector3d KeyframeTracker::graphVelocityCorrection(const Eigen::Matrix3d& T_jk,
                                                         const Eigen::Matrix3d& E_j,
                                                         const Eigen::Matrix3d& M_k,
                                                         const Eigen::Matrix<double, 6, 6>& Cd) const {
  // T_wj_ holds the current keyframe's solved pose (solveGraph), so this is the solved
  // relative pose; delta its left perturbation from the chained registration's.
  const Eigen::Matrix3d T_solved = se2::inverse(T_wj_ * E_j) * M_k;
  const Eigen::Vector3d delta = se2::log(T_solved * se2::inverse(T_jk));
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(Cd.topLeftCorner<3, 3>());
  if (ldlt.info() != Eigen::Success || !delta.allFinite()) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d dxi = Cd.bottomLeftCorner<3, 3>() * ldlt.solve(delta);
  return dxi.allFinite() ? dxi : Eigen::Vector3d::Zero();
}

}  // namespace spinradar
