// registerToPast's descriptor registration screened before its matching (issue 19, sixteenth
// speed round).
//
// Why: at a keyframe switch the scan is matched against each past keyframe of the graph
// window (five with keyframe_graph 6), and on the simulated Oxford drive those descriptor
// registrations almost never pass: 0 of 715 at kMinInliers and 8 at kMinWeakInliers in 400
// scans (the proximity ICP then registers). Their matching, a full brute-force pass over the
// keyframe's descriptors each, was the larger part of the switch's descriptor work.
//
// Exact: the solve counts at its first iteration the matches whose residual under the
// prediction (T_pred, xi) is within kPredictionGate, and fails when they are fewer than its
// minimum. A keyframe row can be such a match only if some scan keypoint, moved by the
// prediction, lies within the gate of its point; the ratio test of a row does not depend on
// the other rows. So those rows are matched first: when their matches within the gate are
// fewer than `need`, every solve the registration tries fails at its first iteration, and the
// matching of the rest is skipped. Otherwise the rest is matched too and the two merged in row
// order: the matching pairByDescriptors would have made, to the bit.
#include <cmath>

#include "approx_se2_exp.hpp"
#include "keyframe_caches.hpp"
#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/keyframe_tracker.hpp"

namespace spinradar {

namespace {

/// m: the gate is widened by this for the moved keypoints' rounding and series error (both
/// under 1e-11 m for points within 10 km).
constexpr double kScreenMargin = 1e-6;

/// Grows v to hold n with headroom (no allocation once warmed up, as the tracker's buffers).
template <class V>
void reserveFor(V& v, size_t n) {
  if (v.capacity() < n) v.reserve(n + n / 2);
}

/// Rows `rows` of `desc` into a view of `storage` (sized for all of desc's rows with headroom).
cv::Mat copyRows(const cv::Mat& desc, const std::vector<int>& rows, cv::Mat& storage) {
  const int n = static_cast<int>(rows.size());
  if (storage.rows < desc.rows || storage.cols != desc.cols || storage.type() != desc.type())
    storage.create(desc.rows + desc.rows / 2 + 1, desc.cols, desc.type());
  for (int r = 0; r < n; ++r) desc.row(rows[static_cast<size_t>(r)]).copyTo(storage.row(r));
  return storage.rowRange(0, n);
}

}  // namespace

bool KeyframeTracker::pastDescriptorsFail(const FeatureFrame& cur, const Eigen::Matrix3d& T_pred,
                                          const Eigen::Vector3d& xi, double c, double nndr,
                                          int need) {
  screened_ = false;
  if (exhaustive_ || (pair_matches_ != nullptr && key_map_id_ == fresh_map_id_) ||
      static_cast<size_t>(key_desc_.rows) != key_pts_.size())
    return false;
  DescriptorScreen& s = descriptorScreen();
  const size_t n = cur.keypoints.size();
  if (cur_dirs_.size() != n) cacheDirections(cur);
  // The scan's keypoints as the solve's first iteration moves them (residual() in
  // keyframe_solve.cpp: Doppler, exp(tau xi), T_pred), E from the series where it holds.
  const size_t rows = static_cast<size_t>(key_desc_.rows);
  reserveFor(s.moved, n);
  for (auto* v : {&s.near_rows, &s.far_rows}) reserveFor(*v, rows);
  for (auto* v : {&s.near_matches, &s.far_matches, &matches_}) reserveFor(*v, rows);
  s.moved.resize(n);
  const double beta = config_.beta;
  for (size_t i = 0; i < n; ++i) {
    const Keypoint& k = cur.keypoints[i];
    const double tau = 1e-9 * static_cast<double>(k.stamp_ns - cur.stamp_ns) - c;
    const double ux = cur_dirs_[i].x(), uy = cur_dirs_[i].y();
    const double d = beta * (ux * xi(0) + uy * xi(1));
    const Eigen::Vector2d pc(k.x + d * ux, k.y + d * uy);
    const Eigen::Vector3d v = tau * xi;
    double E[2][3];
    if (!seriesExp2x3(v, E)) {
      const Eigen::Matrix3d X = se2::exp(v);
      for (int r = 0; r < 2; ++r)
        for (int col = 0; col < 3; ++col) E[r][col] = X(r, col);
    }
    const Eigen::Vector2d g(E[0][0] * pc.x() + E[0][1] * pc.y() + E[0][2],
                            E[1][0] * pc.x() + E[1][1] * pc.y() + E[1][2]);
    s.moved[i] = T_pred.topLeftCorner<2, 2>() * g + T_pred.topRightCorner<2, 1>();
  }
  s.grid.build(s.moved);  // non-finite points are never found (the solve gates them out)
  const double reach = kPredictionGate + kScreenMargin;
  s.near_rows.clear();
  s.far_rows.clear();
  for (int j = 0; j < key_desc_.rows; ++j)
    (s.grid.nearest(key_pts_[static_cast<size_t>(j)], reach) >= 0 ? s.near_rows : s.far_rows).push_back(j);
  if (static_cast<int>(s.near_rows.size()) < need) {
    ++screen_skips_;
    return true;
  }
  matchDescriptors(copyRows(key_desc_, s.near_rows, s.desc_storage), cur.descriptors, nndr, s.near_matches);
  int within = 0;
  for (const Match& m : s.near_matches) {
    const Eigen::Vector2d e = key_pts_[static_cast<size_t>(s.near_rows[static_cast<size_t>(m.i1)])] -
                              s.moved[static_cast<size_t>(m.i2)];
    within += e.squaredNorm() <= reach * reach;
  }
  if (within < need) {
    ++screen_skips_;
    return true;
  }
  // It may pass: the rest of the matching, merged in row order as one matching emits it.
  matchDescriptors(copyRows(key_desc_, s.far_rows, s.desc_storage), cur.descriptors, nndr, s.far_matches);
  matches_.clear();
  size_t a = 0, b = 0;
  while (a < s.near_matches.size() || b < s.far_matches.size()) {
    const bool take_near =
        b == s.far_matches.size() ||
        (a < s.near_matches.size() && s.near_rows[static_cast<size_t>(s.near_matches[a].i1)] <
                                          s.far_rows[static_cast<size_t>(s.far_matches[b].i1)]);
    Match m = take_near ? s.near_matches[a++] : s.far_matches[b++];
    m.i1 = take_near ? s.near_rows[static_cast<size_t>(m.i1)] : s.far_rows[static_cast<size_t>(m.i1)];
    matches_.push_back(m);
  }
  screened_ = true;
  ++screen_splits_;
  return false;
}

}  // namespace spinradar
