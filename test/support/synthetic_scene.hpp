#pragma once
// Test helper (not the product simulator): point landmarks in a plane observed by a spinning
// radar on a vehicle with known, piecewise-constant body velocity. Each landmark is seen at
// the azimuth whose beam sweeps over it, with that azimuth's timestamp, so scans carry the
// motion distortion of a real sensor. Optional range/azimuth noise, Doppler range shift,
// clutter keypoints and outlier matches. Descriptors: a fixed random 32-byte code per
// landmark, so brute-force matching finds the true pairs.
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "spinradar/core/feature_frame.hpp"
#include "spinradar/core/lie.hpp"
#include "spinradar/features/matcher.hpp"

namespace spinradar {
namespace testing {

struct SceneOptions {
  int azimuths = 400;
  double period = 0.25;            ///< s per rotation
  int64_t t0_ns = 1'000'000'000;   ///< start of scan 0
  int landmarks = 800;
  double min_range = 5.0, max_range = 120.0;  ///< landmark placement around the start
  double visible_range = 150.0;
  double range_sigma = 0.0;        ///< m, Gaussian range noise
  double azimuth_sigma = 0.0;      ///< rad, Gaussian azimuth noise
  /// m, Gaussian position noise across the beam at every range (a real return's scattering
  /// centre on an extended object; issue 19's tangential floor)
  double tangential_sigma = 0.0;
  bool quantize_azimuth = false;   ///< report the row's angle instead of the true bearing
  double beta = 0.0;               ///< s, injected Doppler shift: r_apparent = r - beta u
  int clutter = 0;                 ///< random keypoints per scan that match nothing
  uint32_t seed = 1;
  /// s: velocities[k] holds over [k period + velocity_shift, (k+1) period + velocity_shift),
  /// so that steps of the velocity fall inside a scan (0: at the scan starts).
  double velocity_shift = 0.0;
};

/// A dense scene with noisy keypoints, unmatched clutter and Doppler (beta of a CIR204-H):
/// what the estimator tests of refinement, keyframes and pair recovery run on.
inline SceneOptions clutteredDopplerScene(uint32_t seed) {
  SceneOptions o;
  o.landmarks = 1500;
  o.min_range = 5.0;
  o.max_range = 200.0;
  o.range_sigma = 0.03;
  o.azimuth_sigma = 0.002;
  o.clutter = 150;
  o.beta = 0.049;
  o.seed = seed;
  return o;
}

/// Wraps to (-pi, pi].
inline double wrapPi(double a) { return std::atan2(std::sin(a), std::cos(a)); }

class SyntheticScene {
 public:
  /// velocities[k] = body velocity [vx, vy, wz] (REP 103) during scan k; the last entry
  /// holds for all later times.
  SyntheticScene(const SceneOptions& o, std::vector<Eigen::Vector3d> velocities)
      : o_(o), vel_(std::move(velocities)), rng_(o.seed) {
    std::uniform_real_distribution<double> ur(o.min_range, o.max_range), ua(-M_PI, M_PI);
    std::uniform_int_distribution<int> ub(0, 255);
    for (int i = 0; i < o.landmarks; ++i) {
      const double r = ur(rng_), a = ua(rng_);
      landmarks_.emplace_back(r * std::cos(a), r * std::sin(a));
    }
    codes_ = cv::Mat(o.landmarks, 32, CV_8U);
    for (int i = 0; i < codes_.rows; ++i)
      for (int j = 0; j < 32; ++j) codes_.at<uint8_t>(i, j) = static_cast<uint8_t>(ub(rng_));
    // pose(0) = identity: the first segment starts at velocity_shift.
    starts_.push_back(se2::exp(o_.velocity_shift * vel_[0]));
    for (size_t k = 0; k + 1 < vel_.size(); ++k)
      starts_.push_back(starts_.back() * se2::exp(o_.period * vel_[k]));
  }

  const SceneOptions& options() const { return o_; }
  const std::vector<Eigen::Vector2d>& landmarks() const { return landmarks_; }
  std::vector<Eigen::Vector2d>& landmarks() { return landmarks_; }

  double scanStart(int k) const { return k * o_.period; }  ///< s since t0
  int64_t toNs(double t) const { return o_.t0_ns + static_cast<int64_t>(std::llround(t * 1e9)); }

  Eigen::Vector3d velocityAt(double t) const {
    int k = static_cast<int>(std::floor((t - o_.velocity_shift) / o_.period));
    k = std::max(0, std::min<int>(k, static_cast<int>(vel_.size()) - 1));
    return vel_[k];
  }

  /// T_world_sensor(t), world = sensor frame at t0.
  Eigen::Matrix3d pose(double t) const {
    int k = static_cast<int>(std::floor((t - o_.velocity_shift) / o_.period));
    k = std::max(0, std::min<int>(k, static_cast<int>(vel_.size()) - 1));
    return starts_[k] * se2::exp((t - k * o_.period - o_.velocity_shift) * vel_[k]);
  }

  /// True relative pose T_12 between the reference frames of scans k1 and k2.
  Eigen::Matrix3d relative(int k1, int k2) const {
    return se2::inverse(pose(scanStart(k1))) * pose(scanStart(k2));
  }

  /// Clockwise bearing of landmark p from the sensor at time t.
  double bearing(const Eigen::Vector2d& p, double t) const {
    const Eigen::Matrix3d Ti = se2::inverse(pose(t));
    const Eigen::Vector2d q = Ti.topLeftCorner<2, 2>() * p + Ti.topRightCorner<2, 1>();
    return std::atan2(-q.y(), q.x());
  }

  /// Observes scan k: keypoints, their landmark ids (-1 = clutter) and descriptors.
  FeatureFrame observe(int k, std::vector<int>* ids = nullptr) {
    FeatureFrame f;
    const double t0 = scanStart(k), dt_az = o_.period / o_.azimuths;
    const double dphi = 2.0 * M_PI / o_.azimuths;
    f.stamp_ns = toNs(t0);
    std::normal_distribution<double> nr(0.0, 1.0);
    std::vector<int> lid;
    for (int i = 0; i < static_cast<int>(landmarks_.size()); ++i) {
      // Root of g(t) = bearing_unwrapped(t) - 2 pi (t - t0)/period: the beam sweeps over it.
      const double b0 = bearing(landmarks_[i], t0);
      const double phi0 = b0 < 0 ? b0 + 2 * M_PI : b0;
      auto g = [&](double t) {
        return phi0 + wrapPi(bearing(landmarks_[i], t) - b0) - 2 * M_PI * (t - t0) / o_.period;
      };
      double lo = t0, hi = t0 + o_.period;
      if (g(hi) > 0.0) continue;  // swept past during this rotation: seen in the next one
      for (int it = 0; it < 50; ++it) {
        const double mid = 0.5 * (lo + hi);
        (g(mid) > 0.0 ? lo : hi) = mid;
      }
      const int a = std::min(o_.azimuths - 1, static_cast<int>(std::floor((lo - t0) / dt_az)));
      const double t = t0 + a * dt_az;  // the row's timestamp
      const Eigen::Matrix3d Ti = se2::inverse(pose(t));
      const Eigen::Vector2d q = Ti.topLeftCorner<2, 2>() * landmarks_[i] + Ti.topRightCorner<2, 1>();
      const double r_true = q.norm();
      if (r_true > o_.visible_range || r_true < 1.0) continue;
      double az = std::atan2(-q.y(), q.x());
      if (o_.quantize_azimuth) az = a * dphi;
      az += o_.azimuth_sigma * nr(rng_);
      if (o_.tangential_sigma > 0.0) az += o_.tangential_sigma / r_true * nr(rng_);
      const Eigen::Vector3d v = velocityAt(t);
      const double u = v(0) * std::cos(az) - v(1) * std::sin(az);
      const double r = r_true - o_.beta * u + o_.range_sigma * nr(rng_);
      Keypoint kp;
      kp.range = r;
      kp.azimuth = az < 0 ? az + 2 * M_PI : az;
      kp.x = r * std::cos(az);
      kp.y = -r * std::sin(az);
      kp.stamp_ns = toNs(t);
      kp.power = 1.f;
      kp.azimuth_index = a;
      kp.bin = static_cast<float>(r / 0.0438 - 0.5);
      f.keypoints.push_back(kp);
      lid.push_back(i);
    }
    std::uniform_real_distribution<double> ur(3.0, o_.visible_range), ua(0.0, 2 * M_PI);
    std::uniform_int_distribution<int> ub(0, 255);
    for (int c = 0; c < o_.clutter; ++c) {
      Keypoint kp;
      kp.range = ur(rng_);
      kp.azimuth_index = std::min(o_.azimuths - 1, static_cast<int>(ua(rng_) / dphi));
      kp.azimuth = kp.azimuth_index * dphi;
      kp.x = kp.range * std::cos(kp.azimuth);
      kp.y = -kp.range * std::sin(kp.azimuth);
      kp.stamp_ns = toNs(t0 + kp.azimuth_index * dt_az);
      f.keypoints.push_back(kp);
      lid.push_back(-1);
    }
    f.descriptors = cv::Mat(static_cast<int>(lid.size()), 32, CV_8U);
    for (int r = 0; r < f.descriptors.rows; ++r) {
      for (int j = 0; j < 32; ++j) {
        f.descriptors.at<uint8_t>(r, j) =
            lid[r] >= 0 ? codes_.at<uint8_t>(lid[r], j) : static_cast<uint8_t>(ub(rng_));
      }
    }
    if (ids) *ids = lid;
    return f;
  }

  /// True matches between two observations (by landmark id); a fraction `outliers` of them
  /// get a wrong partner drawn at random from the second scan.
  std::vector<Match> matches(const std::vector<int>& ids1, const std::vector<int>& ids2,
                             double outliers, std::vector<bool>* is_outlier = nullptr) {
    std::vector<int> where(landmarks_.size(), -1);
    for (size_t j = 0; j < ids2.size(); ++j)
      if (ids2[j] >= 0) where[ids2[j]] = static_cast<int>(j);
    std::vector<Match> out;
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    std::uniform_int_distribution<int> pick(0, static_cast<int>(ids2.size()) - 1);
    if (is_outlier) is_outlier->clear();
    for (size_t i = 0; i < ids1.size(); ++i) {
      if (ids1[i] < 0 || where[ids1[i]] < 0) continue;
      Match m;
      m.i1 = static_cast<int>(i);
      m.i2 = where[ids1[i]];
      bool bad = u01(rng_) < outliers;
      if (bad) {
        int j = pick(rng_);
        while (j == m.i2) j = pick(rng_);
        m.i2 = j;
      }
      out.push_back(m);
      if (is_outlier) is_outlier->push_back(bad);
    }
    return out;
  }

 private:
  SceneOptions o_;
  std::vector<Eigen::Vector3d> vel_;
  std::mt19937 rng_;
  std::vector<Eigen::Vector2d> landmarks_;
  cv::Mat codes_;
  std::vector<Eigen::Matrix3d> starts_;  ///< pose at the start of each velocity segment
};

}  // namespace testing
}  // namespace spinradar
