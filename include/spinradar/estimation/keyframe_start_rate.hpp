#pragma once
// EstimatorConfig::start_rate_pair_weight (issue 19, docs/sensor_columns/round16_turn_heading.md):
// the published heading of the scan right after a keyframe switch made in a turn, blended
// with the scan-to-scan pair estimate's.
//
// Why: the first scan registered to a new keyframe has a one-scan baseline to it, and in turns
// the registrations under-rotate (about 0.3 % of the turned angle, round 15); the pair
// estimate's (MC-RANSAC / Doppler refit) yaw increment over the same step does not depend on
// the keyframe. So for that scan the published yaw increment from the previous published pose
// (the new keyframe's) is (1 - w) the keyframe estimate's + w the pair's; the position stays
// the keyframe estimate's. Only the published pose: relativePose() keeps the registration's
// own (what one registration measured), so for that scan the published pose is not the
// keyframe's times relativePose(); the covariance stays the keyframe estimate's; should the
// scan itself become a keyframe, it is made at the blended pose (under keyframe_graph the
// window's solved pose replaces it).
#include <Eigen/Core>

#include "spinradar/core/params.hpp"

namespace spinradar {

/// |pair yaw rate| (rad/s) at the switching scan above which a switch counts as made in a
/// turn: the truth turning faster than 3 deg/s is what round 15 called a turn.
constexpr double kStartRateTurnRate = 3.0 * 3.14159265358979323846 / 180.0;

/// T_w: the published pose of a scan (T_w_prev the previous scan's, pair_T_12 the pair step
/// between them), blended with weight cfg.start_rate_pair_weight when after_switch (the
/// previous scan became the keyframe) and |switch_pair_yaw_rate| (the pair's at that scan)
/// exceeds kStartRateTurnRate. Weight 0: T_w untouched.
void blendStartRate(const EstimatorConfig& cfg, bool after_switch, double switch_pair_yaw_rate,
                    const Eigen::Matrix3d& T_w_prev, const Eigen::Matrix3d& pair_T_12,
                    Eigen::Matrix3d& T_w);

}  // namespace spinradar
