// The keyframe map of KeyframeTracker: taking a scan as the keyframe (its points
// Doppler-corrected and moved to its mid-scan reference). Pairing a scan's keypoints with it:
// keyframe_proximity.cpp. Split from keyframe_tracker.cpp (the registration and the
// covariances) to keep files small.
#include <algorithm>
#include <cmath>

#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/doppler.hpp"
#include "spinradar/estimation/keyframe_tracker.hpp"
#include "spinradar/estimation/undistort.hpp"
#include "map_agreement.hpp"

namespace spinradar {

double KeyframeTracker::rowQuantization(const FeatureFrame& f) {
  int same_row = 0, same_angle = 0;
  double step = 0.0;
  const std::vector<Keypoint>& k = f.keypoints;
  for (size_t i = 1; i < k.size(); ++i) {
    if (k[i].azimuth_index == k[i - 1].azimuth_index) {
      ++same_row;
      same_angle += k[i].azimuth == k[i - 1].azimuth;
    } else if (step == 0.0 && k[i].azimuth_index == k[i - 1].azimuth_index + 1) {
      step = std::abs(se2::wrapAngle(k[i].azimuth - k[i - 1].azimuth));
    }
  }
  return same_row >= 20 && same_angle >= 0.9 * same_row ? step : 0.0;
}

void KeyframeTracker::makeKeyframe(const FeatureFrame& f, const Eigen::Vector3d& xi, double c,
                                   const Eigen::Matrix3d& T_w, const Eigen::Matrix3d& P) {
  // The keyframe's points as a static map: Doppler-corrected and moved to its reference
  // time with its own velocity. Headroom so that later keyframes rarely reallocate.
  const size_t n = f.keypoints.size();
  if (tmp_kps_.capacity() < n) tmp_kps_.reserve(n + n / 2);
  if (key_pts_.capacity() < n) key_pts_.reserve(n + n / 2);
  if (key_tau_.capacity() < n) key_tau_.reserve(n + n / 2);
  if (matches_.capacity() < n) {  // at most one match per keyframe row
    const size_t c = n + n / 2;
    matches_.reserve(c);
    for (auto* v : {&qx_, &qy_, &px_, &py_, &ux_, &uy_, &tau_, &key_tau_m_}) v->reserve(c);
    in_.reserve(c);
    dirs_.reserve(c);
  }
  dopplerCorrect(f.keypoints, xi, config_.beta, tmp_kps_);
  const int64_t ref_ns = f.stamp_ns + static_cast<int64_t>(std::llround(1e9 * c));
  undistortPoints(tmp_kps_, xi, ref_ns, key_pts_);
  averageWithSubmap(T_w * se2::exp(c * xi));  // its mid-scan world pose
  key_grid_.build(key_pts_);  // for the proximity search (associateByProximity)
  key_tau_.resize(n);
  for (size_t i = 0; i < n; ++i)
    key_tau_[i] = 1e-9 * static_cast<double>(f.keypoints[i].stamp_ns - ref_ns);
  const cv::Mat& d = f.descriptors;
  if (d.empty()) {
    key_desc_ = cv::Mat();
  } else {
    if (key_desc_storage_.rows < d.rows || key_desc_storage_.cols != d.cols ||
        key_desc_storage_.type() != d.type())
      key_desc_storage_.create(std::max(d.rows + d.rows / 2, 64), d.cols, d.type());
    key_desc_ = key_desc_storage_.rowRange(0, d.rows);
    d.copyTo(key_desc_);
  }
  T_wj_ = T_w;
  P_j_ = P;
  key_c_ = c;
  key_xi_ = xi;
  key_stamp_ = f.stamp_ns;
  key_map_id_ = ++map_ids_;  // a new map: anchors of the old one no longer hold
  key_fresh_ = true;
  T_jprev_.setIdentity();
  C_jprev_.setZero();
  C_jprev_pub_.setZero();
  key_inliers_ = 0;
  has_key_ = true;
  ++switches_;
}

// Why (issue 19, docs/sensor_columns/round08_glint.md): every scan registered to a
// keyframe shares the scatter (glint) of its map's returns, and the keyframe switch hands it
// on. The mean of a return's positions in the last N keyframes (moved into the new keyframe's
// frame with the chained poses) scatters sqrt(N) less and ties the new map to the earlier
// ones. Measured (400 scans, azimuth peaks, N = 3): city_glint0.14 0.39 -> 0.17 %,
// city_oxford_glint0.14 1.06 -> 0.53 %, but city_narrow layout 2 0.14 -> 0.75 % and
// city_wide layout 1 0.13 -> 0.23 %: an option, off by default.
void KeyframeTracker::averageWithSubmap(const Eigen::Matrix3d& M_w) {
  const int k = config_.submap_keyframes;
  if (k <= 1) return;
  const size_t slots = static_cast<size_t>(k - 1), n = key_pts_.size();
  if (submap_.size() != slots) {
    submap_.assign(slots, SubmapFrame{});
    submap_count_ = submap_next_ = 0;
  }
  avg_sum_.assign(key_pts_.begin(), key_pts_.end());
  avg_n_.assign(n, 1);
  for (size_t s = 0; s < submap_count_; ++s) {
    const SubmapFrame& o = submap_[s];
    // Averaged under the chained poses (which ties the new map to the earlier ones), but not
    // where the two maps disagree: a chained pose error (a turn entry's keyframe 1-2 deg off)
    // would be averaged into the new map, half of it, and handed on.
    const Eigen::Matrix3d T_on = se2::inverse(o.M_w) * M_w;
    if (!submapAgrees(o, T_on)) continue;
    const Eigen::Matrix2d R = T_on.topLeftCorner<2, 2>();
    const Eigen::Vector2d t = T_on.topRightCorner<2, 1>();
    for (size_t i = 0; i < n; ++i) {
      const int best_j = o.grid.nearest(R * key_pts_[i] + t, kSubmapGate);
      if (best_j < 0) continue;
      avg_sum_[i] += R.transpose() * (o.pts[static_cast<size_t>(best_j)] - t);
      ++avg_n_[i];
    }
  }
  SubmapFrame& slot = submap_[submap_next_];
  slot.pts.assign(key_pts_.begin(), key_pts_.end());
  slot.grid.build(slot.pts);
  slot.M_w = M_w;
  submap_next_ = (submap_next_ + 1) % slots;
  submap_count_ = std::min(submap_count_ + 1, slots);
  for (size_t i = 0; i < n; ++i) key_pts_[i] = avg_sum_[i] / avg_n_[i];
}

// o agrees when the fit of its points onto the new map's (map_agreement.hpp) moves it by at
// most kSubmapAgreeYaw and kSubmapAgreeShift, or when there are fewer than kSubmapMinPairs
// pairs to tell (then averaged as the pairs fall).
bool KeyframeTracker::submapAgrees(const SubmapFrame& o, const Eigen::Matrix3d& T_on) const {
  Eigen::Vector3d d;
  if (mapMisalignment(key_pts_, o.pts, o.grid, T_on, kSubmapGate, kSubmapMinPairs, d) <
      kSubmapMinPairs)
    return true;
  return std::abs(d(2)) <= kSubmapAgreeYaw && d.head<2>().norm() <= kSubmapAgreeShift;
}

}  // namespace spinradar
