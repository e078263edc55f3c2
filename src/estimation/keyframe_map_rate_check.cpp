// KeyframeTracker::mapRateBias: the yaw_rate_map_check (issue 19, nineteenth round).
#include <cmath>

#include "spinradar/estimation/keyframe_tracker.hpp"

namespace spinradar {

// A registration's yaw rate follows the keyframe map's: the map was moved to its mid-scan
// time with the keyframe's velocity, and an error e of that yaw rate bends it so that every
// scan registered to it comes out about e off (issue 19, docs/sensor_columns/
// round19_map_rate_bias.md: a keyframe made at a turn entry, its map 0.1 rad/s off, then
// registrations 0.12-0.19 rad/s under the pair's for the whole steady turn; taken as motion,
// each published pose moved by up to 1.3 deg and the next keyframes' maps inherited it). A
// yaw-rate step inside a scan shows in one registration first; a map's error shows again in
// the next one against the same keyframe. So: the registered-minus-pair difference within
// kRegisteredYawRateGap of the previous scan's against this keyframe is the map's.
bool KeyframeTracker::mapRateBias(double offset) {
  const bool repeat = has_rate_offset_ && rate_offset_key_ == key_stamp_ &&
                      std::abs(offset - rate_offset_) < kRegisteredYawRateGap;
  has_rate_offset_ = true;
  rate_offset_ = offset;
  rate_offset_key_ = key_stamp_;
  return repeat;
}

}  // namespace spinradar
