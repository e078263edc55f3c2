#pragma once
// How far apart two keyframe maps sit under the pose that relates them (issue 19, eighteenth
// round): a least-squares rigid fit (2-D Kabsch from running sums, no buffers) of the old
// map's nearest points onto the new map's, formed twice (pairs again under the corrected
// pose). The keyframe map averaging (keyframe_map.cpp) leaves an old map out when the fit
// moves it far: then the chained pose between the two keyframes is off, and averaging would
// hand half of that error on to the new map.
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/nearest_point_grid.hpp"

namespace spinradar {

/// pts: the new map (its frame); old_pts and old_grid (built on old_pts): the old map (its
/// frame); T_on: the new frame in the old one. Pairs are nearest old points within gate.
/// Returns the number of pairs of the last pass; correction: [x, y, yaw] of the fitted pose
/// of the new frame in the old one relative to T_on (zero when fewer than min_pairs pairs).
inline int mapMisalignment(const std::vector<Eigen::Vector2d>& pts,
                           const std::vector<Eigen::Vector2d>& old_pts,
                           const NearestPointGrid& old_grid, const Eigen::Matrix3d& T_on0,
                           double gate, int min_pairs, Eigen::Vector3d& correction) {
  correction.setZero();
  Eigen::Matrix3d T_on = T_on0;
  int m = 0;
  for (int pass = 0; pass < 2; ++pass) {
    const Eigen::Matrix2d R = T_on.topLeftCorner<2, 2>();
    const Eigen::Vector2d t = T_on.topRightCorner<2, 1>();
    Eigen::Vector2d sp = Eigen::Vector2d::Zero(), sq = Eigen::Vector2d::Zero();
    Eigen::Matrix2d spq = Eigen::Matrix2d::Zero();
    m = 0;
    for (const Eigen::Vector2d& p : pts) {
      const int j = old_grid.nearest(R * p + t, gate);
      if (j < 0) continue;
      const Eigen::Vector2d q = R.transpose() * (old_pts[static_cast<size_t>(j)] - t);
      sp += p;
      sq += q;
      spq += q * p.transpose();
      ++m;
    }
    if (m < min_pairs) return m;
    const Eigen::Vector2d mp = sp / m, mq = sq / m;
    const Eigen::Matrix2d H = spq - m * mq * mp.transpose();  // sum (q - mq)(p - mp)^T
    const double a = std::atan2(H(0, 1) - H(1, 0), H(0, 0) + H(1, 1));  // rotates q onto p
    Eigen::Matrix3d S = se2::fromXyYaw(Eigen::Vector3d(0.0, 0.0, a));  // old (new frame) -> new
    S.topRightCorner<2, 1>() = mp - S.topLeftCorner<2, 2>() * mq;
    T_on = T_on * se2::inverse(S);
  }
  correction = se2::toXyYaw(se2::inverse(T_on0) * T_on);
  return m;
}

}  // namespace spinradar
