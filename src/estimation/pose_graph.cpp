// Planar pose graph and its leave-one-out edge screen (pose_graph.hpp). Why the screen: in
// keyframe_graph a new keyframe's registration against an older keyframe of the window is
// gated only against the chained prediction, whose covariance grows with every switch back,
// so a registration off by a fraction of a degree passes and pulls the new keyframe off
// (city_narrow layout 2, turn entry at t = 24 s: 0.65 deg against 0.07 without the graph).
// The rest of the window constrains the same relative pose far tighter than the chain alone;
// testing each edge against the graph without it catches what the chain gate lets through.
#include "spinradar/estimation/pose_graph.hpp"

#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Dense>

#include "spinradar/core/lie.hpp"

namespace spinradar {

namespace {

constexpr int kIterations = 5;

/// Residual of edge e at x and its Jacobians with respect to nodes a and b.
Eigen::Vector3d residual(const std::vector<Eigen::Vector3d>& x, const PoseGraphEdge& e,
                         Eigen::Matrix3d& Ja, Eigen::Matrix3d& Jb) {
  const Eigen::Vector3d& xa = x[e.a];
  const Eigen::Vector3d& xb = x[e.b];
  const double ca = std::cos(xa(2)), sa = std::sin(xa(2));
  Eigen::Matrix2d Ri;
  Ri << ca, sa, -sa, ca;
  const Eigen::Vector2d d = Ri * (xb.head<2>() - xa.head<2>());
  Eigen::Vector3d r;
  r << d - e.z.head<2>(), se2::wrapAngle(xb(2) - xa(2) - e.z(2));
  Jb.setZero();
  Jb.topLeftCorner<2, 2>() = Ri;
  Jb(2, 2) = 1.0;
  Ja.setZero();
  Ja.topLeftCorner<2, 2>() = -Ri;
  Ja(0, 2) = d.y();
  Ja(1, 2) = -d.x();
  Ja(2, 2) = -1.0;
  return r;
}

/// Gauss-Newton over the free nodes 1..n-1 with matrices of type Mat (dynamic, or bounded-size
/// for the allocation-free path) and vectors Vec; scratch's vectors are reused.
template <class Mat, class Vec>
bool gaussNewton(std::vector<Eigen::Vector3d>& x, const std::vector<PoseGraphEdge>& edges,
                 const std::vector<bool>& skip, PoseGraphScratch& scratch, Mat* Sigma) {
  const int n = static_cast<int>(x.size());
  if (n < 2) return false;
  const int m = 3 * (n - 1);
  std::vector<Eigen::Vector3d>& y = scratch.y;
  y.assign(x.begin(), x.end());
  std::vector<char>& reached = scratch.reached;
  Mat H(m, m);
  Vec g(m), dx(m);
  for (int it = 0; it < kIterations; ++it) {
    H.setZero();
    g.setZero();
    // Nodes no edge reaches are held by a unit prior (they keep their given pose).
    reached.assign(n, 0);
    for (size_t k = 0; k < edges.size(); ++k) {
      if (!skip.empty() && skip[k]) continue;
      const PoseGraphEdge& e = edges[k];
      if (e.a < 0 || e.b <= e.a || e.b >= n) continue;
      Eigen::Matrix3d Ja, Jb;
      const Eigen::Vector3d r = residual(y, e, Ja, Jb);
      const Eigen::Matrix3d W = e.C.ldlt().solve(Eigen::Matrix3d::Identity());
      const int ib = 3 * (e.b - 1), ia = 3 * (e.a - 1);
      reached[e.b] = 1;
      H.template block<3, 3>(ib, ib) += Jb.transpose() * W * Jb;
      g.template segment<3>(ib) += Jb.transpose() * W * r;
      if (e.a > 0) {
        reached[e.a] = 1;
        H.template block<3, 3>(ia, ia) += Ja.transpose() * W * Ja;
        H.template block<3, 3>(ia, ib) += Ja.transpose() * W * Jb;
        H.template block<3, 3>(ib, ia) += Jb.transpose() * W * Ja;
        g.template segment<3>(ia) += Ja.transpose() * W * r;
      }
    }
    for (int k = 1; k < n; ++k)
      if (!reached[k])
        H.template block<3, 3>(3 * (k - 1), 3 * (k - 1)) += Eigen::Matrix3d::Identity();
    const Eigen::LDLT<Mat> ldlt(H);
    if (ldlt.info() != Eigen::Success) return false;
    dx = -ldlt.solve(g);
    if (!dx.allFinite()) return false;
    for (int k = 1; k < n; ++k) y[k] += dx.template segment<3>(3 * (k - 1));
    if (dx.cwiseAbs().maxCoeff() < 1e-9) break;
  }
  if (Sigma) {
    *Sigma = H.ldlt().solve(Mat::Identity(m, m));
    if (!Sigma->allFinite()) return false;
  }
  x = y;
  return true;
}

}  // namespace

bool solvePoseGraph(std::vector<Eigen::Vector3d>& x, const std::vector<PoseGraphEdge>& edges,
                    const std::vector<bool>& skip, Eigen::MatrixXd* Sigma) {
  PoseGraphScratch scratch;
  return gaussNewton<Eigen::MatrixXd, Eigen::VectorXd>(x, edges, skip, scratch, Sigma);
}

bool solvePoseGraph(std::vector<Eigen::Vector3d>& x, const std::vector<PoseGraphEdge>& edges,
                    const std::vector<bool>& skip, Eigen::Matrix3d* last_cov,
                    PoseGraphScratch& scratch) {
  constexpr int kMaxDof = 3 * (kPoseGraphMaxNodes - 1);
  using SmallMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxDof, kMaxDof>;
  using SmallVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxDof, 1>;
  if (static_cast<int>(x.size()) > kPoseGraphMaxNodes) {  // larger: on the heap
    Eigen::MatrixXd Sigma;
    if (!gaussNewton<Eigen::MatrixXd, Eigen::VectorXd>(x, edges, skip, scratch,
                                                       last_cov ? &Sigma : nullptr))
      return false;
    if (last_cov) *last_cov = Sigma.bottomRightCorner<3, 3>();
    return true;
  }
  SmallMat Sigma;
  if (!gaussNewton<SmallMat, SmallVec>(x, edges, skip, scratch, last_cov ? &Sigma : nullptr))
    return false;
  if (last_cov) *last_cov = Sigma.bottomRightCorner<3, 3>();
  return true;
}

double leaveOneOutChi2(const std::vector<Eigen::Vector3d>& x0,
                       const std::vector<PoseGraphEdge>& edges, const std::vector<bool>& skip,
                       int e) {
  const int n = static_cast<int>(x0.size());
  std::vector<bool> s = skip;
  s.resize(edges.size(), false);
  s[e] = true;
  // Both of e's nodes must be tied to the held node by the other edges (else nothing to test).
  std::vector<bool> tied(n, false);
  tied[0] = true;
  for (bool grew = true; grew;) {
    grew = false;
    for (size_t k = 0; k < edges.size(); ++k) {
      if (s[k]) continue;
      const int a = edges[k].a, b = edges[k].b;
      if (a < 0 || b >= n || tied[a] == tied[b]) continue;
      tied[a] = tied[b] = true;
      grew = true;
    }
  }
  const PoseGraphEdge& E = edges[e];
  if (!tied[E.a] || !tied[E.b]) return -1.0;
  std::vector<Eigen::Vector3d> x = x0;
  Eigen::MatrixXd Sigma;
  if (!solvePoseGraph(x, edges, s, &Sigma)) return -1.0;
  Eigen::Matrix3d Ja, Jb;
  const Eigen::Vector3d r = residual(x, E, Ja, Jb);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(3, Sigma.rows());
  J.block<3, 3>(0, 3 * (E.b - 1)) = Jb;
  if (E.a > 0) J.block<3, 3>(0, 3 * (E.a - 1)) = Ja;
  const Eigen::Matrix3d S = E.C + J * Sigma * J.transpose();
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(S);
  if (ldlt.info() != Eigen::Success) return -1.0;
  const double chi2 = r.dot(ldlt.solve(r));
  return std::isfinite(chi2) ? chi2 : -1.0;
}

int screenEdges(const std::vector<Eigen::Vector3d>& x0, const std::vector<PoseGraphEdge>& edges,
                const std::vector<int>& candidates, double gate, std::vector<bool>& skip) {
  skip.resize(edges.size(), false);
  int marked = 0;
  for (;;) {
    int worst = -1;
    double worst_chi2 = gate;
    for (int e : candidates) {
      if (e < 0 || e >= static_cast<int>(edges.size()) || skip[e]) continue;
      const double chi2 = leaveOneOutChi2(x0, edges, skip, e);
      if (chi2 > worst_chi2) {
        worst_chi2 = chi2;
        worst = e;
      }
    }
    if (worst < 0) return marked;
    skip[worst] = true;
    ++marked;
  }
}

}  // namespace spinradar
