#pragma once
// Doppler range correction (Burnett et al. 2021, Sec. III-C). A sensor moving with radial
// velocity u towards a target sees a positive Doppler shift that lowers the beat frequency,
// so the apparent range is r_true - beta u; we correct by r += beta u, beta = f_t/(df/dt).
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "spinradar/core/feature_frame.hpp"
#include "spinradar/features/matcher.hpp"
#include "spinradar/estimation/mc_ransac.hpp"
#include "spinradar/estimation/motion_estimate.hpp"

namespace spinradar {

/// Sensor velocity projected on the beam of clockwise azimuth phi. In REP 103 the beam unit
/// vector is (cos phi, -sin phi), so u = vx cos phi - vy sin phi (the paper's
/// vx cos phi + vy sin phi is the same quantity in its y-right frame).
inline double beamVelocity(const Eigen::Vector3d& velocity, double azimuth) {
  return velocity(0) * std::cos(azimuth) - velocity(1) * std::sin(azimuth);
}

/// r += beta u for every keypoint, moving (x, y) along the beam by the same amount.
/// `velocity` is the sensor body velocity [vx, vy, wz] (REP 103).
void dopplerCorrect(std::vector<Keypoint>& keypoints, const Eigen::Vector3d& velocity, double beta);

/// Copying variant: out = corrected in (out's capacity is reused).
void dopplerCorrect(const std::vector<Keypoint>& in, const Eigen::Vector3d& velocity, double beta,
                    std::vector<Keypoint>& out);

/// The mc_doppler estimator: MC-RANSAC on the raw keypoints, then rounds of "Doppler-correct
/// both scans with the current velocity, Gauss-Newton refit on the inliers". The raw
/// estimate is biased by the uncorrected shift (measured 0.17 m/s at 15 m/s, 15 deg/s);
/// each round shrinks the velocity error by ~100x (a velocity error dv leaves a range error
/// beta dv), so two rounds reach 1e-4 m/s; we stop when a round moves the velocity by less
/// than kDopplerTolerance, after at most kDopplerRounds.
/// k1c/k2c receive the corrected keypoints (caller-owned buffers, reused).
constexpr int kDopplerRounds = 3;
constexpr double kDopplerTolerance = 1e-4;  ///< m/s

bool estimateMcDoppler(McRansac& mc, const std::vector<Keypoint>& k1,
                       const std::vector<Keypoint>& k2, const std::vector<Match>& matches,
                       int64_t ref1_ns, int64_t ref2_ns, double beta,
                       std::vector<Keypoint>& k1c, std::vector<Keypoint>& k2c,
                       MotionEstimate& out);

}  // namespace spinradar
