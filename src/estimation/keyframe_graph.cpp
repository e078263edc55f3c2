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
// poses stay causal: nothing already published is changed). Its covariance: the window's
// marginal relative to the held node, compounded onto that node's own.
// Extra registrations only at keyframe switches. Measured (drift, cost, variants):
// docs/sensor_columns/round11_keyframe_graph.md.
#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Dense>

#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/keyframe_tracker.hpp"

namespace spinradar {

namespace {

constexpr int kGraphIterations = 5;
/// The extra registrations' covariances are taken this many times over: against keyframes
/// up to keyframe_graph switches back their errors are not all independent of the chain's
/// (the same map points, the same undistortion), and weighed as given they pulled the narrow
/// and dense-clutter columns off (keyframe_graph 6, 1 -> 2: city_oxford 0.237 -> 0.210 %,
/// city_mulran 0.168 -> 0.152; 4 lost city_oxford_glint0.14 0.42 -> 0.53).
constexpr double kGraphEdgeInflation = 2.0;

double wrap(double a) { return std::atan2(std::sin(a), std::cos(a)); }

}  // namespace

bool KeyframeTracker::solveGraph(const FeatureFrame& cur, double c, const Eigen::Matrix3d& T_jk,
                                 const Eigen::Matrix3d& C_jk, Eigen::Matrix3d& M_k,
                                 Eigen::Matrix3d& P_m) {
  if (past_count_ == 0) return false;
  const Eigen::Matrix3d M_j = T_wj_ * se2::exp(key_c_ * key_xi_);
  // Extra registrations against past_[i], predicted along the chain (as fuseWithPast).
  Eigen::Matrix3d X, C;
  se2::compoundXyYaw(se2::inverse(past_[0].M_w) * M_j, key_rel_cov_, T_jk, C_jk, X, C);
  for (size_t i = 0; i < past_count_; ++i) {
    if (i > 0) {
      Eigen::Matrix3d X_i, C_i;
      se2::compoundXyYaw(se2::inverse(past_[i].M_w) * past_[i - 1].M_w, past_[i - 1].C_rel, X, C,
                         X_i, C_i);
      X = X_i;
      C = C_i;
    }
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
  const int n = static_cast<int>(past_count_) + 2;
  std::vector<int64_t> stamp(n);
  std::vector<Eigen::Vector3d> x(n);
  std::vector<const std::vector<GraphEdge>*> edges(n);
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
  // Gauss-Newton over the free nodes 1..n-1 (node 0 held): residual of an edge a -> b,
  // r = [R(-yaw_a) (t_b - t_a) - z_t; yaw_b - yaw_a - z_yaw], weighted by C^-1.
  const int m = 3 * (n - 1);
  Eigen::MatrixXd H(m, m);
  Eigen::VectorXd g(m);
  bool ok = false;
  for (int it = 0; it < kGraphIterations; ++it) {
    H.setZero();
    g.setZero();
    for (int b = 1; b < n; ++b) {
      for (const GraphEdge& e : *edges[b]) {
        int a = -1;
        for (int q = 0; q < b; ++q)
          if (stamp[q] == e.to) a = q;
        if (a < 0) continue;  // to a keyframe that left the window
        const double ca = std::cos(x[a](2)), sa = std::sin(x[a](2));
        Eigen::Matrix2d Ri;
        Ri << ca, sa, -sa, ca;
        const Eigen::Vector2d d = Ri * (x[b].head<2>() - x[a].head<2>());
        const Eigen::Vector3d z = se2::toXyYaw(e.Z);
        Eigen::Vector3d r;
        r << d - z.head<2>(), wrap(x[b](2) - x[a](2) - z(2));
        Eigen::Matrix3d Jb = Eigen::Matrix3d::Zero(), Ja = Eigen::Matrix3d::Zero();
        Jb.topLeftCorner<2, 2>() = Ri;
        Jb(2, 2) = 1.0;
        Ja.topLeftCorner<2, 2>() = -Ri;
        Ja(0, 2) = d.y();
        Ja(1, 2) = -d.x();
        Ja(2, 2) = -1.0;
        const Eigen::Matrix3d W = e.C.ldlt().solve(Eigen::Matrix3d::Identity());
        const int ib = 3 * (b - 1), ia = 3 * (a - 1);
        H.block<3, 3>(ib, ib) += Jb.transpose() * W * Jb;
        g.segment<3>(ib) += Jb.transpose() * W * r;
        if (a > 0) {
          H.block<3, 3>(ia, ia) += Ja.transpose() * W * Ja;
          H.block<3, 3>(ia, ib) += Ja.transpose() * W * Jb;
          H.block<3, 3>(ib, ia) += Jb.transpose() * W * Ja;
          g.segment<3>(ia) += Ja.transpose() * W * r;
        }
      }
    }
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(H);
    if (ldlt.info() != Eigen::Success) return false;
    const Eigen::VectorXd dx = -ldlt.solve(g);
    if (!dx.allFinite()) return false;
    for (int k = 1; k < n; ++k) x[k] += dx.segment<3>(3 * (k - 1));
    ok = true;
    if (dx.cwiseAbs().maxCoeff() < 1e-9) break;
  }
  if (!ok) return false;
  // The new node's covariance relative to the held node (world axes -> the held node's).
  const Eigen::MatrixXd Sigma = H.ldlt().solve(Eigen::MatrixXd::Identity(m, m));
  Eigen::Matrix3d G = Eigen::Matrix3d::Identity();
  const double c0 = std::cos(x[0](2)), s0 = std::sin(x[0](2));
  G.topLeftCorner<2, 2>() << c0, s0, -s0, c0;
  Eigen::Matrix3d C_rel = G * Sigma.bottomRightCorner<3, 3>() * G.transpose();
  C_rel = 0.5 * (C_rel + C_rel.transpose());
  if (!C_rel.allFinite()) return false;
  const Eigen::Matrix3d M_0 = se2::fromXyYaw(x[0]);
  const Eigen::Matrix3d P_0 = past_[past_count_ - 1].P_m;
  se2::compoundXyYaw(M_0, P_0, se2::inverse(M_0) * se2::fromXyYaw(x[n - 1]), C_rel, M_k, P_m);
  // The earlier nodes take their solved poses (for later predictions and windows).
  for (size_t i = 0; i + 1 < past_count_; ++i)
    past_[i].M_w = se2::fromXyYaw(x[past_count_ - 1 - i]);
  T_wj_ = se2::fromXyYaw(x[n - 2]) * se2::exp(-key_c_ * key_xi_);
  return true;
}

}  // namespace spinradar
