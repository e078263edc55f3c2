// A keyframe drive through the glint landmark field (glint_scene.hpp) against its truth: the
// figures the keyframe fusion and pose-graph tests compare with the option on and off.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>

#include <Eigen/Cholesky>

#include "support/glint_scene.hpp"
#include "support/noisy_prior.hpp"
#include "support/synthetic_scene.hpp"
#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/keyframe_tracker.hpp"

namespace spinradar::testing {

struct GlintDrive {
  double heading_rms = 0.0;      ///< rad, accumulated heading error over the drive
  double key_heading_rms = 0.0;  ///< rad, the same at the scans that became keyframes
  double nees = 0.0;             ///< mean e^T P^-1 e over [x, y, yaw] (honest: ~3)
  double heading_nees = 0.0;     ///< mean e_yaw^2 / P_yaw (honest: ~1)
  int switches = 0, fused = 0, refused = 0;
};

/// `scans` scans at 6 m/s turning at 0.15 rad/s (a 40 m circle) with `cfg` (beta forced to 0);
/// the frame-to-frame prior is the truth with Gaussian errors of its stated covariance.
inline GlintDrive glintDrive(uint32_t seed, double glint, EstimatorConfig cfg, int scans = 120) {
  const SceneOptions o = glintSceneOptions(seed, glint);
  const Eigen::Vector3d v(6.0, 0.0, 0.15);
  SyntheticScene scene(o, {v});
  cfg.beta = 0.0;
  KeyframeTracker kt(cfg);
  NoisyPrior prior(seed + 7);
  Eigen::Matrix3d T_w = Eigen::Matrix3d::Identity(), P = Eigen::Matrix3d::Zero();
  GlintDrive run;
  double sum2 = 0.0, key2 = 0.0;
  int keys = 0;
  for (int k = 0; k < scans; ++k) {
    const FeatureFrame f = scene.observe(k);
    MotionEstimate pair = prior(scene, k, v);
    const Eigen::Matrix3d T_prev = T_w, P_prev = P;
    const int switches_was = kt.keyframeSwitches();
    kt.track(f, T_prev, P_prev, 0.8, pair, T_w, P);
    const Eigen::Vector3d t = se2::toXyYaw(scene.relative(0, k)), p = se2::toXyYaw(T_w);
    Eigen::Vector3d e = p - t;
    e(2) = std::atan2(std::sin(e(2)), std::cos(e(2)));
    sum2 += e(2) * e(2);
    if (k > 0 && kt.keyframeSwitches() != switches_was) {
      key2 += e(2) * e(2);
      ++keys;
    }
    if (k > 0) {
      run.nees += e.dot(P.ldlt().solve(e));
      run.heading_nees += e(2) * e(2) / P(2, 2);
    }
  }
  run.heading_rms = std::sqrt(sum2 / scans);
  run.key_heading_rms = keys > 0 ? std::sqrt(key2 / keys) : 0.0;
  run.nees /= scans - 1;
  run.heading_nees /= scans - 1;
  run.switches = kt.keyframeSwitches();
  run.fused = kt.fusionsAccepted();
  run.refused = kt.fusionsRejected();
  return run;
}

/// The figures a test compares over seeds: drives with the option off (`one`, `clean`) and
/// on (`two`, `clean_f`), with glint and without.
struct GlintTally {
  double sum = 0.0, sum_f = 0.0, sum_c = 0.0, sum_cf = 0.0;  ///< summed heading rms, rad
  double nees = 0.0, nees_f = 0.0, hnees_f = 0.0;             ///< the largest NEES
  int seeds = 0, lower = 0, lower_key = 0, fused = 0;

  void add(const GlintDrive& one, const GlintDrive& two, const GlintDrive& clean,
           const GlintDrive& clean_f) {
    ++seeds;
    lower += two.heading_rms < one.heading_rms;
    lower_key += two.key_heading_rms < one.key_heading_rms;
    sum += one.heading_rms;
    sum_f += two.heading_rms;
    sum_c += clean.heading_rms;
    sum_cf += clean_f.heading_rms;
    nees = std::max(nees, one.nees);
    nees_f = std::max({nees_f, two.nees, clean_f.nees});
    hnees_f = std::max({hnees_f, two.heading_nees, clean_f.heading_nees});
    fused += two.fused;
  }
  void print() const {
    const double deg = M_PI / 180.0;
    std::cout << "[ info ] summed heading rms deg, glint: " << sum / deg << " -> " << sum_f / deg
              << "; without: " << sum_c / deg << " -> " << sum_cf / deg << "; largest NEES "
              << nees << " -> " << nees_f << ", heading " << hnees_f << "\n";
  }
};

}  // namespace spinradar::testing
