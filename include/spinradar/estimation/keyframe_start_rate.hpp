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

/// Whether the scan after a keyframe switch is blended: the switching scan's pair yaw rate
/// (rad/s) over kStartRateTurnRate, and that rate times the scan period dt (s) at most
/// cfg.keyframe_angle. Above it one scan alone turns further than the switch angle (the
/// keyframe_angle_fast regime, round 15: out_and_back_v2's U-turn at up to 86 deg/s, the city
/// turns under 40); there the pair estimate is made under the turn's largest distortion and
/// blending it made the U-turn's exit 0.3-0.6 deg worse (round 16).
bool startRateBlends(const EstimatorConfig& cfg, double switch_pair_yaw_rate, double dt);

/// T_w: the published pose of a scan (T_w_prev the previous scan's, pair_T_12 the pair step
/// between them, dt the scan period), blended with weight cfg.start_rate_pair_weight when
/// after_switch (the previous scan became the keyframe) and startRateBlends(). Weight 0: T_w
/// untouched.
void blendStartRate(const EstimatorConfig& cfg, bool after_switch, double switch_pair_yaw_rate,
                    double dt, const Eigen::Matrix3d& T_w_prev, const Eigen::Matrix3d& pair_T_12,
                    Eigen::Matrix3d& T_w);

}  // namespace spinradar
