#pragma once
// map -> odom from a map localization (localizer_nodelet.cpp): the localizer gives the radar's
// pose in the map at a scan's reference time, the odometry gives the base's pose in odom at
// (about) the same time; T_map_odom = T_map_radar (T_odom_base T_base_radar)^-1. ROS-free so
// it can be tested without a master.
#include <cstdint>
#include <deque>

#include <Eigen/Core>

#include "spinradar/core/lie.hpp"

namespace spinradar_ros {

inline Eigen::Matrix3d mapToOdom(const Eigen::Matrix3d& T_map_radar,
                                 const Eigen::Matrix3d& T_odom_base,
                                 const Eigen::Matrix3d& T_base_radar) {
  return T_map_radar * spinradar::se2::inverse(T_odom_base * T_base_radar);
}

/// Recent odometry poses (T_odom_base by stamp, in arrival order = time order), interpolated
/// on SE(2) at a query time. Bounded: the oldest entries are dropped past `capacity`.
class OdomHistory {
 public:
  explicit OdomHistory(size_t capacity = 200) : capacity_(capacity) {}

  /// Out-of-order stamps (bag loops, time jumps back) restart the history.
  void add(int64_t stamp_ns, const Eigen::Matrix3d& T_odom_base) {
    if (!entries_.empty() && stamp_ns <= entries_.back().stamp_ns) entries_.clear();
    entries_.push_back({stamp_ns, T_odom_base});
    while (entries_.size() > capacity_) entries_.pop_front();
  }
  void clear() { entries_.clear(); }
  bool empty() const { return entries_.empty(); }
  int64_t latest() const { return entries_.empty() ? 0 : entries_.back().stamp_ns; }

  /// T_odom_base at `stamp_ns`: interpolated between the bracketing entries; an exact stamp
  /// is returned as is. False when the stamp lies outside the history (more than
  /// `tolerance_ns` before the first or after the last entry: then the nearest is used).
  bool at(int64_t stamp_ns, Eigen::Matrix3d& T, int64_t tolerance_ns = 0) const {
    if (entries_.empty()) return false;
    if (stamp_ns <= entries_.front().stamp_ns) {
      T = entries_.front().T;
      return entries_.front().stamp_ns - stamp_ns <= tolerance_ns;
    }
    if (stamp_ns >= entries_.back().stamp_ns) {
      T = entries_.back().T;
      return stamp_ns - entries_.back().stamp_ns <= tolerance_ns;
    }
    size_t i = entries_.size() - 1;
    while (entries_[i - 1].stamp_ns > stamp_ns) --i;  // recent queries: search from the end
    const Entry& a = entries_[i - 1];
    const Entry& b = entries_[i];
    const double s = static_cast<double>(stamp_ns - a.stamp_ns) /
                     static_cast<double>(b.stamp_ns - a.stamp_ns);
    namespace se2 = spinradar::se2;
    T = a.T * se2::exp(s * se2::log(se2::inverse(a.T) * b.T));
    return true;
  }

 private:
  struct Entry {
    int64_t stamp_ns;
    Eigen::Matrix3d T;
  };
  size_t capacity_;
  std::deque<Entry> entries_;
};

}  // namespace spinradar_ros
