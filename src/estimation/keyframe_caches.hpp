#pragma once
// Buffers of KeyframeTracker that hold work done once and read many times at a keyframe
// switch (issue 19, fifteenth round); each is reused, no allocation after warm-up.
#include <cstddef>
#include <limits>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "spinradar/estimation/nearest_point_grid.hpp"
#include "spinradar/features/matcher.hpp"

#include "proximity_bound.hpp"

namespace spinradar {

/// The anchors of the tracked scan's keypoints in one keyframe map (proximity_bound.hpp):
/// dropped for a new scan (track()) and when another map is swapped in.
struct ProximityCache {
  int map = -1;  ///< the map the anchors are in (KeyframeTracker's map ids)
  std::vector<ProximityAnchor> anchors;
  /// Anchors for map `map_id` and n keypoints: kept when they are that map's already.
  void use(int map_id, size_t n) {
    if (map == map_id && anchors.size() == n) return;
    map = map_id;
    if (anchors.capacity() < n) anchors.reserve(n + n / 2);
    anchors.assign(n, ProximityAnchor{});
  }
  void clear() { map = -1; }
};

/// The solve's per-match term that depends only on the keyframe point and the floor (its
/// Cartesian covariance, cartesianCovariance(q, ..., floor)): computed once per solve and
/// floor instead of in every Gauss-Newton iteration, the same call so the same bits.
struct SolveTermCache {
  std::vector<Eigen::Matrix2d> cov_q;
  std::vector<double> floor;  ///< the floor cov_q[m] holds; NaN: not yet computed
  /// An inlier's terms in the latest Gauss-Newton iteration, which the pass after the last
  /// iteration (residual scales, acceleration sensitivities) reads instead of recomputing
  /// them at the same point (the same values: issue 19, sixteenth speed round).
  struct Last {
    Eigen::Matrix<double, 6, 2> JtW;
    Eigen::Matrix2d S;
    Eigen::Vector2d e, g, ccpc;  ///< ccpc: the scan point rotated into the keyframe (radial)
  };
  std::vector<Last> last;
  void reset(size_t n) {
    if (floor.capacity() < n) {
      floor.reserve(n + n / 2);
      cov_q.reserve(n + n / 2);
      last.reserve(n + n / 2);
    }
    floor.assign(n, std::numeric_limits<double>::quiet_NaN());
    cov_q.resize(n);
    last.resize(n);
  }
};

/// The screen of a past keyframe's descriptor registration (keyframe_screen.cpp): the scan's
/// keypoints moved by the prediction, a grid over them, the keyframe rows split by whether a
/// moved keypoint lies within the first gate, their descriptors and matches.
struct DescriptorScreen {
  std::vector<Eigen::Vector2d> moved;
  NearestPointGrid grid;
  std::vector<int> near_rows, far_rows;
  cv::Mat desc_storage;
  std::vector<Match> near_matches, far_matches;
};

}  // namespace spinradar
