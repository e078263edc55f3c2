// The frame-to-frame prior a keyframe test hands the tracker on a synthetic drive: the true
// step and velocity with Gaussian errors of the covariance it states (an honest prior).
#pragma once

#include <cstdint>
#include <random>

#include <Eigen/Core>

#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/motion_estimate.hpp"
#include "support/synthetic_scene.hpp"

namespace spinradar::testing {

struct PriorNoise {
  double xy = 0.02;                ///< m
  double yaw = 0.1 * M_PI / 180.0;  ///< rad
  double v = 0.02;                 ///< m/s
  double w = 0.001;                ///< rad/s
};

/// Draws, scan by scan, the pair step k-1 -> k (identity for k = 0) and the body velocity v,
/// each with errors of its stated covariance (one generator and one normal distribution for
/// the whole drive, so a seed gives one sequence).
class NoisyPrior {
 public:
  explicit NoisyPrior(uint32_t seed, const PriorNoise& s = {}) : rng_(seed), s_(s) {}
  MotionEstimate operator()(const SyntheticScene& scene, int k, const Eigen::Vector3d& v) {
    MotionEstimate pair;
    pair.ok = true;
    pair.T_12 = Eigen::Matrix3d::Identity();
    if (k > 0)
      pair.T_12 = scene.relative(k - 1, k) *
                  se2::exp(Eigen::Vector3d(s_.xy * n_(rng_), s_.xy * n_(rng_), s_.yaw * n_(rng_)));
    pair.T_12_cov = Eigen::Vector3d(s_.xy * s_.xy, s_.xy * s_.xy, s_.yaw * s_.yaw).asDiagonal();
    pair.velocity = v + Eigen::Vector3d(s_.v * n_(rng_), s_.v * n_(rng_), s_.w * n_(rng_));
    pair.velocity_cov = Eigen::Vector3d(s_.v * s_.v, s_.v * s_.v, s_.w * s_.w).asDiagonal();
    return pair;
  }

 private:
  std::mt19937 rng_;
  std::normal_distribution<double> n_{0.0, 1.0};
  PriorNoise s_;
};

}  // namespace spinradar::testing
