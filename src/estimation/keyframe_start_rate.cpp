// EstimatorConfig::start_rate_pair_weight: see keyframe_start_rate.hpp (why) and
// docs/sensor_columns/round16_turn_heading.md (the variants measured).
#include "spinradar/estimation/keyframe_start_rate.hpp"

#include <cmath>

#include "spinradar/core/lie.hpp"

namespace spinradar {

bool startRateBlends(const EstimatorConfig& cfg, double switch_pair_yaw_rate, double dt) {
  const double rate = std::abs(switch_pair_yaw_rate);
  return rate > kStartRateTurnRate && rate * dt <= cfg.keyframe_angle;
}

void blendStartRate(const EstimatorConfig& cfg, bool after_switch, double switch_pair_yaw_rate,
                    double dt, const Eigen::Matrix3d& T_w_prev, const Eigen::Matrix3d& pair_T_12,
                    Eigen::Matrix3d& T_w) {
  const double w = cfg.start_rate_pair_weight;
  if (w <= 0.0 || !after_switch || !startRateBlends(cfg, switch_pair_yaw_rate, dt)) return;
  // The two yaw increments over the same step (scan start to scan start).
  const Eigen::Matrix3d step = se2::inverse(T_w_prev) * T_w;
  const double d_key = std::atan2(step(1, 0), step(0, 0));
  const double d_pair = std::atan2(pair_T_12(1, 0), pair_T_12(0, 0));
  // Rotated about the scan's own position: the position stays the keyframe estimate's.
  T_w = T_w * se2::exp(Eigen::Vector3d(0.0, 0.0, w * se2::wrapAngle(d_pair - d_key)));
}

}  // namespace spinradar
