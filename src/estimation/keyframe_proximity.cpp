// Pairing the tracked scan's keypoints with a keyframe map (KeyframeTracker): by descriptors
// and by proximity to a predicted pose. Split from keyframe_map.cpp (making the map).
//
// Two shortcuts at keyframe switches, both exact (the same pairs, so the same poses; issue
// 19, fifteenth round):
//  - the scan after a switch is matched against the keyframe made from the previous scan,
//    whose descriptors are that scan's: the pair's matches (offerPairMatches) are those;
//  - the proximity ICP pairs every keypoint with its nearest keyframe point again after each
//    solve, mostly finding what it found before: anchors from a wide search decide those
//    queries without the grid (proximity_bound.hpp).
#include <cmath>

#include "approx_se2_exp.hpp"
#include "keyframe_caches.hpp"
#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/keyframe_tracker.hpp"

namespace spinradar {

namespace {
/// m: anchors are laid with a search this wide at least (wider than the re-association
/// gates, 0.3 and 0.6 m, so that the ICP's small moves stay provable).
constexpr double kAnchorRadius = 1.0;
}  // namespace

struct KeyframeCaches {
  ProximityCache proximity;
  SolveTermCache solve;
  DescriptorScreen screen;
};

KeyframeCachesPtr::KeyframeCachesPtr() : p_(new KeyframeCaches) {}
KeyframeCachesPtr::~KeyframeCachesPtr() = default;
KeyframeCachesPtr::KeyframeCachesPtr(const KeyframeCachesPtr&) : p_(new KeyframeCaches) {}
KeyframeCachesPtr& KeyframeCachesPtr::operator=(const KeyframeCachesPtr&) {
  p_->proximity.clear();  // they only save work: a copy starts without
  return *this;
}

SolveTermCache& KeyframeTracker::solveTerms() { return caches_->solve; }
DescriptorScreen& KeyframeTracker::descriptorScreen() { return caches_->screen; }

void KeyframeTracker::offerPairMatches(int64_t prev_stamp_ns, int64_t cur_stamp_ns, double nndr,
                                       const std::vector<Match>& matches) {
  offered_ = &matches;
  offered_prev_ns_ = prev_stamp_ns;
  offered_cur_ns_ = cur_stamp_ns;
  offered_nndr_ = nndr;
}

void KeyframeTracker::beginScan(const FeatureFrame& cur, double nndr) {
  // The pair's matches are this scan's against the keyframe when that keyframe was made from
  // the scan they were matched with, in the last track() (so its descriptors are that scan's).
  const bool pair_is_key = !exhaustive_ && has_key_ && key_fresh_ && offered_ != nullptr &&
                           offered_prev_ns_ == key_stamp_ && offered_cur_ns_ == cur.stamp_ns &&
                           offered_nndr_ == nndr;
  pair_matches_ = pair_is_key ? offered_ : nullptr;
  fresh_map_id_ = key_map_id_;
  offered_ = nullptr;  // for this scan only
  key_fresh_ = false;
  cacheDirections(cur);
}

void KeyframeTracker::cacheDirections(const FeatureFrame& cur) {
  const size_t n = cur.keypoints.size();
  if (cur_dirs_.capacity() < n) cur_dirs_.reserve(n + n / 2);
  cur_dirs_.resize(n);
  for (size_t i = 0; i < n; ++i)
    cur_dirs_[i] = {std::cos(cur.keypoints[i].azimuth), -std::sin(cur.keypoints[i].azimuth)};
  caches_->proximity.clear();  // a new scan: new queries
}

void KeyframeTracker::addMatch(size_t key_index, const FeatureFrame& cur, size_t i, double tau) {
  qx_.push_back(key_pts_[key_index].x());
  qy_.push_back(key_pts_[key_index].y());
  key_tau_m_.push_back(key_tau_[key_index]);
  px_.push_back(cur.keypoints[i].x);
  py_.push_back(cur.keypoints[i].y);
  ux_.push_back(cur_dirs_[i].x());
  uy_.push_back(cur_dirs_[i].y());
  tau_.push_back(tau);
}

void KeyframeTracker::pairByDescriptors(const FeatureFrame& cur, double c, double nndr) {
  // The keyframe made from the previous scan (its descriptors copied from it), offered the
  // pair's matches of that scan and this one at the same ratio: they are this matching's.
  if (pair_matches_ != nullptr && key_map_id_ == fresh_map_id_)
    matches_.assign(pair_matches_->begin(), pair_matches_->end());
  else if (!screened_)  // screenPastDescriptors() left this matching in matches_
    matchDescriptors(key_desc_, cur.descriptors, nndr, matches_);
  screened_ = false;
  qx_.clear(); qy_.clear(); px_.clear(); py_.clear(); ux_.clear(); uy_.clear(); tau_.clear();
  key_tau_m_.clear();
  for (const Match& m : matches_) {
    const Keypoint& k = cur.keypoints[m.i2];
    addMatch(static_cast<size_t>(m.i1), cur, static_cast<size_t>(m.i2),
             1e-9 * static_cast<double>(k.stamp_ns - cur.stamp_ns) - c);
  }
}

void KeyframeTracker::associateByProximity(const FeatureFrame& cur, const Eigen::Matrix3d& T_pred,
                                           const Eigen::Vector3d& xi, double c, double gate) {
  qx_.clear(); qy_.clear(); px_.clear(); py_.clear(); ux_.clear(); uy_.clear(); tau_.clear();
  key_tau_m_.clear();
  hold_floor_ = true;  // nearest-point pairs within a gate: their spread is not the returns'
  const size_t n = cur.keypoints.size();
  if (qx_.capacity() < n) {  // rare: a scan with more keypoints than the keyframe's headroom
    for (auto* v : {&qx_, &qy_, &px_, &py_, &ux_, &uy_, &tau_, &key_tau_m_}) v->reserve(n + n / 2);
    in_.reserve(n + n / 2);
    dirs_.reserve(n + n / 2);
  }
  if (cur_dirs_.size() != n) cacheDirections(cur);  // track() caches them; kept in step here too
  ProximityCache& cache = caches_->proximity;
  cache.use(key_map_id_, n);
  const double radius = std::max(gate, kAnchorRadius);
  const double beta = config_.beta;
  // Keypoints of one stamp (a row; with azimuth peaks each has its own) share the motion
  // M = T_pred exp(tau xi): its top two rows, written out (Eigen's 3x3 temporaries stalled on
  // store forwarding; the same sums in the same order, so the same bits).
  double M[2][3] = {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}};
  double row_tau = 0.0;
  bool have_M = false;
  // A query an anchor may decide is first moved with the series exponential (approx_se2_exp.hpp):
  // its error, 1e-15 per entry of E, moves the query by under 1e-14 (1 + |p| + |v| + |t|) m
  // with rounding; 1e-13 of that is the slack. Undecided, it is moved again with se2::exp.
  const double t_abs = std::abs(T_pred(0, 2)) + std::abs(T_pred(1, 2));
  double Ms[2][3], Es[2][3];
  double series_tau = 0.0;
  bool have_Ms = false;  ///< Ms holds the series motion of series_tau
  for (size_t i = 0; i < n; ++i) {
    const Keypoint& k = cur.keypoints[i];
    const double tau = 1e-9 * static_cast<double>(k.stamp_ns - cur.stamp_ns) - c;
    const double ux = cur_dirs_[i].x(), uy = cur_dirs_[i].y();
    const double d = beta * (ux * xi(0) + uy * xi(1));
    const double px = k.x + d * ux, py = k.y + d * uy;
    ProximityAnchor& a = cache.anchors[i];
    int best_j = kUndecided;
    if (!exhaustive_ && a.sep >= 0.0 && (!have_M || tau != row_tau)) {
      const Eigen::Vector3d v = tau * xi;
      if ((have_Ms && tau == series_tau) || seriesExp2x3(v, Es)) {
        if (!have_Ms || tau != series_tau) {
          for (int r = 0; r < 2; ++r)
            for (int col = 0; col < 3; ++col)
              Ms[r][col] = T_pred(r, 0) * Es[0][col] + T_pred(r, 1) * Es[1][col] + (col == 2 ? T_pred(r, 2) : 0.0);
          series_tau = tau;
          have_Ms = true;
        }
        const Eigen::Vector2d qs(Ms[0][0] * px + Ms[0][1] * py + Ms[0][2],
                                 Ms[1][0] * px + Ms[1][1] * py + Ms[1][2]);
        const double slack =
            1e-13 * (1.0 + std::abs(px) + std::abs(py) + std::abs(v(0)) + std::abs(v(1)) + t_abs);
        best_j = boundedNearest(a, qs, gate, key_pts_, slack);
      }
    }
    if (best_j == kUndecided) {
      if (!have_M || tau != row_tau) {
        const Eigen::Matrix3d E = se2::exp(tau * xi);
        for (int r = 0; r < 2; ++r)
          for (int col = 0; col < 3; ++col)
            M[r][col] = T_pred(r, 0) * E(0, col) + T_pred(r, 1) * E(1, col) + T_pred(r, 2) * E(2, col);
        row_tau = tau;
        have_M = true;
      }
      const Eigen::Vector2d qh(M[0][0] * px + M[0][1] * py + M[0][2],
                               M[1][0] * px + M[1][1] * py + M[1][2]);
      best_j = exhaustive_ ? key_grid_.nearest(qh, gate) : boundedNearest(a, qh, gate, key_pts_);
      if (best_j == kUndecided) {  // search, and anchor the next queries here
        int wide = -1;
        double second2 = 0.0;
        best_j = key_grid_.nearest(qh, gate, radius, wide, second2);
        const bool finite = std::isfinite(qh.x()) && std::isfinite(qh.y());
        a = ProximityAnchor{qh.x(), qh.y(), finite && second2 >= 0.0 ? std::sqrt(second2) : -1.0, wide};
      }
    }
    if (best_j >= 0) addMatch(static_cast<size_t>(best_j), cur, i, tau);
  }
}

}  // namespace spinradar
