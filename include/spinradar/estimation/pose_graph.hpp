// A small planar pose graph over [x, y, yaw] nodes (node 0 held), solved by Gauss-Newton,
// with a leave-one-out consistency screen of chosen edges (issue 19, keyframe_graph).
#pragma once

#include <vector>

#include <Eigen/Core>

namespace spinradar {

/// A measured pose of node b relative to node a (a < b): z = [x, y, yaw] of b in a's frame,
/// with its covariance C (3x3).
struct PoseGraphEdge {
  int a = 0, b = 0;
  Eigen::Vector3d z = Eigen::Vector3d::Zero();
  Eigen::Matrix3d C = Eigen::Matrix3d::Identity();
};

/// Solves the graph from the initial poses x (node 0 held; nodes without edges stay as
/// given): residual of an edge r = [R(-yaw_a)(t_b - t_a) - z_t; yaw_b - yaw_a - z_yaw],
/// weighted by C^-1. Edges with skip[e] true are left out (skip may be empty). Sigma, if
/// given, receives the covariance of the free nodes 1..n-1 (3(n-1) square). False when the
/// system is singular or not finite (x then unchanged).
bool solvePoseGraph(std::vector<Eigen::Vector3d>& x, const std::vector<PoseGraphEdge>& edges,
                    const std::vector<bool>& skip, Eigen::MatrixXd* Sigma);

/// keyframe_graph's largest window: keyframe_graph <= 10 keyframes and the new one.
constexpr int kPoseGraphMaxNodes = 11;

/// Buffers solvePoseGraph reuses from call to call (the keyframe tracker keeps one).
struct PoseGraphScratch {
  std::vector<Eigen::Vector3d> y;
  std::vector<char> reached;
};

/// As above, but only the last node's 3x3 block of Sigma (last_cov, if given) is returned, and a graph
/// of at most kPoseGraphMaxNodes nodes is solved without heap allocation (its matrices are
/// bounded-size, on the stack; the vectors are scratch's, grown once): the keyframe
/// estimator's hot path makes none after warm-up (test_keyframe_allocations). Same solution.
bool solvePoseGraph(std::vector<Eigen::Vector3d>& x, const std::vector<PoseGraphEdge>& edges,
                    const std::vector<bool>& skip, Eigen::Matrix3d* last_cov,
                    PoseGraphScratch& scratch);

/// Leave-one-out consistency of edge e with the rest of the graph: the graph solved without
/// e (and without the edges already skipped) predicts e's measurement; returns the innovation's
/// chi-square r^T (C_e + J Sigma J^T)^-1 r (3 dof), or a negative value when the graph without
/// e cannot be solved or does not constrain both of e's nodes.
double leaveOneOutChi2(const std::vector<Eigen::Vector3d>& x0,
                       const std::vector<PoseGraphEdge>& edges, const std::vector<bool>& skip,
                       int e);

/// Screens the candidate edges one at a time: the candidate with the largest leave-one-out
/// chi-square above `gate` is marked in skip, and the screen repeats over the others until
/// none exceeds it. Returns how many were marked.
int screenEdges(const std::vector<Eigen::Vector3d>& x0, const std::vector<PoseGraphEdge>& edges,
                const std::vector<int>& candidates, double gate, std::vector<bool>& skip);

}  // namespace spinradar
