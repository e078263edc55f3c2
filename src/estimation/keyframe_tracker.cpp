#include "spinradar/estimation/keyframe_tracker.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/mc_ransac.hpp"

namespace spinradar {

KeyframeTracker::KeyframeTracker(const EstimatorConfig& config) : config_(config) {}

void KeyframeTracker::track(const FeatureFrame& cur, const Eigen::Matrix3d& T_w_prev,
                            const Eigen::Matrix3d& P_prev, double nndr, MotionEstimate& pair,
                            Eigen::Matrix3d& T_w, Eigen::Matrix3d& P) {
  const double dt = has_last_stamp_ ? 1e-9 * static_cast<double>(cur.stamp_ns - last_stamp_) : 0.25;
  last_stamp_ = cur.stamp_ns;
  has_last_stamp_ = true;
  nndr_ = nndr;
  const double c = kMidScan * scan_period_.update(cur, dt);  // mid-scan, see ScanPeriod
  // A dropped scan (or a recording read every other scan): the step is a gap (scan_period.hpp).
  const bool gap_step = has_key_ && ScanPeriod::isGap(dt, ScanPeriod::rotation(cur));
  // The pair velocity's yaw rate changed by over kRampYawAccel in the last scan (a ramp).
  const bool pair_ramp = std::abs(pair.velocity(2) - prev_pair_xi_(2)) > kRampYawAccel * dt;
  row_step_ = rowQuantization(cur);
  beginScan(cur, nndr);
  if (!has_key_) {
    se2::compoundXyYaw(T_w_prev, P_prev, pair.T_12, pair.T_12_cov, T_w, P);
    rel_key_stamp_ = cur.stamp_ns;
    rel_T_.setIdentity();
    rel_C_.setZero();
    key_xi_cov_ = pair.velocity_cov;
    makeKeyframe(cur, pair.velocity, c, T_w, P);
    key_pair_xi_ = pair.velocity;
    key_ramp_ = false;
    P_jm_ = P;
    prev_c_ = c;
    prev_xi_ = prev_pair_xi_ = pair.velocity;
    return;
  }
  // The pair step assumes a smooth velocity; its covariance does not know that the yaw rate
  // can step (turn entry and exit: measured 1-2 deg errors of that step). Inflate it by
  // white-noise acceleration over the step so the registration can overrule it there.
  Eigen::Matrix3d C_12 = pair.T_12_cov;
  C_12.diagonal() += stepModelNoise(dt);
  // The step between the previous scan's mid-scan frame and this one's.
  const Eigen::Matrix3d S =
      se2::exp(-prev_c_ * prev_xi_) * pair.T_12 * se2::exp(c * pair.velocity);
  Eigen::Matrix3d T_odo, C_odo;
  se2::compoundXyYaw(T_jprev_, C_jprev_, S, C_12, T_odo, C_odo);
  Eigen::Matrix3d T_jk = T_odo, C_jk = C_odo;
  // Published covariance of T_jk (see solve()); without a registration it follows the chain.
  Eigen::Matrix3d T_unused, C_pub;
  se2::compoundXyYaw(T_jprev_, C_jprev_pub_, S, C_12, T_unused, C_pub);
  Eigen::Matrix<double, 6, 6> cov_pub = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 6> cov_acc = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix3d xi_cov_pub = pair.velocity_cov;
  Eigen::Vector3d xi_key = pair.velocity;  // the velocity the next keyframe is undistorted with
  const bool still = pair.velocity.isZero();
  bool registered = false;
  bool weak = false;  ///< registered with fewer than kMinInliers descriptor inliers (below)
  last_inliers_ = 0;
  if (still) {
    // Standing still (the refined estimator snapped the velocity to zero): hold the pose.
    T_jk = T_jprev_;
    C_jk = C_jprev_;
    C_pub = C_jprev_pub_;
  } else {
    pairByDescriptors(cur, c, nndr);
    // The pair velocity is centred about half a scan before scan k's own; within a scan the
    // yaw rate is only weakly observable (it trades against the yaw), so this prior has to
    // stay tight: inflated for a tenth of a scan (kPriorLag), not half. Extrapolating it by
    // half a scan from the previous pair was measured worse on the city route (1.47 % /
    // 0.0055 deg/m against 0.77 % / 0.0031): it overshoots at every yaw-rate step.
    const double dl = kAccelSigma * kPriorLag * dt, da = kAngAccelSigma * kPriorLag * dt;
    const Eigen::Vector3d xi_prior = pair.velocity;
    Eigen::Matrix3d Cxi = pair.velocity_cov;
    Cxi.diagonal() += Eigen::Vector3d(dl * dl, dl * dl, da * da);
    const double hl = kAccelSigma * kHonestLag * dt, ha = kAngAccelSigma * kHonestLag * dt;
    // The acceleration over the last scan period, from the velocity change: the size of
    // what the constant-velocity model leaves out within this scan (see solve()).
    accel_ = ((pair.velocity - prev_xi_) / dt).cwiseAbs();
    Eigen::Matrix3d Cxi_honest = pair.velocity_cov;
    Cxi_honest.diagonal() += Eigen::Vector3d(hl * hl, hl * hl, ha * ha);
    // The same lag for cov_acc: seen acceleration plus the step model's noise (see solve()).
    const Eigen::Vector3d q2(kStepAccelSigma, kStepAccelSigma, kStepAngAccelSigma);
    Cxi_acc_ = pair.velocity_cov;
    Cxi_acc_.diagonal() += (accel_.cwiseAbs2() + q2.cwiseAbs2()) * std::pow(kHonestLag * dt, 2);
    fuse_xi_prior_ = xi_prior;  // for the extra registrations (keyframe_fusion.cpp)
    fuse_Cxi_ = Cxi;
    fuse_Cxi_honest_ = Cxi_honest;
    Eigen::Vector3d xi = xi_prior;
    Eigen::Matrix<double, 6, 6> cov;
    Eigen::Matrix3d T = T_odo;
    registered = solve(T_odo, C_odo, xi_prior, Cxi, Cxi_honest, T, xi, cov, cov_pub, cov_acc);
    // Pair every keypoint with the nearest keyframe point (within `gate`) under the solved
    // pose and solve again; a failed solve keeps the previous pose. The covariances stay the
    // first registration's (see the two uses below).
    auto pairAndSolveAgain = [&](double gate) {
      const Eigen::Matrix3d T_was = T;
      const Eigen::Vector3d xi_was = xi;
      Eigen::Matrix<double, 6, 6> unused_cov, unused_pub, unused_acc;
      associateByProximity(cur, T, xi, c, gate);
      if (solve(T_odo, C_odo, xi_prior, Cxi, Cxi_honest, T, xi, unused_cov, unused_pub, unused_acc))
        return true;
      T = T_was;
      xi = xi_was;
      return false;
    };
    // Descriptors failed against a keyframe turned far from this scan (ORB on the Cartesian
    // image changes with the heading): pair keypoints by proximity to the prediction. Only
    // there: on straights the descriptors fail for other reasons (few distinct returns) and
    // the prediction is the better fallback. City route layouts 0-7: 0.69-0.99 % (mean
    // 0.87 %) against 0.88-1.46 % (mean 1.08 %); tight_turns 3.9 % against 5.3 %.
    const bool proximity =
        !registered && std::abs(std::atan2(T_odo(1, 0), T_odo(0, 0))) > kProximityMinAngle;
    auto registerByProximity = [&](bool settle) {
      associateByProximity(cur, T_odo, xi_prior, c, kProximityGate);
      T = T_odo;
      xi = xi_prior;
      bool ok = solve(T_odo, C_odo, xi_prior, Cxi, Cxi_honest, T, xi, cov, cov_pub, cov_acc);
      // Pairs by proximity come from the prediction, and with row keypoints (a return on every
      // row its beam covers: arcs of points along the rotation) arcs slide along arcs, so one
      // solve keeps most of the prediction's yaw error (issue 19, tight_turns: these
      // registrations kept 69 % of the prior's yaw error, rms 0.59 deg, and carried 58 of the
      // 72 keyframe switches; azimuth peaks 4 %). So pair again under the solved pose and
      // solve until the pose settles (ICP). Drift (400 scans, row keypoints): tight_turns 0.88 ->
      // 0.25 % (kept 11 %, rms 0.19 deg); see the README for the other columns. The
      // covariances stay the first solve's (nearest-point pairs of one arc are not
      // independent, see the re-association below).
      // With proximity_settle_gate (issue 19), then on at that narrower gate until it settles
      // (not for the last resort below). Under the Oxford and MulRan models' dense clutter a
      // 0.6 m gate pairs many returns by chance, and the one re-association at 0.3 m below
      // kept their pull: the same proximity registrations, yaw error against the truth rms,
      // one re-association -> settled at 0.3 m: city_oxford layouts 1 / 2 0.125 -> 0.099 /
      // 0.110 -> 0.076 deg, city_mulran 0.065 -> 0.058 / 0.116 -> 0.091, city_narrow layout
      // 2 0.069 -> 0.063; city_wide, tight_turns, city_oxford (glint) unchanged (+-0.002);
      // city_noise14 0.076 -> 0.080. Drift: city_oxford layouts 1 / 2 0.32 / 0.25 -> 0.28 /
      // 0.18 %, but city_noise14 0.13 -> 0.18 % (one turn's keyframes fell differently): an
      // option, off by default (docs/sensor_columns/round09_weak_switches.md). With the last
      // resort settled too RADIATE consistency went 0.191 -> 0.199 deg.
      for (const double g : {kProximityRegate, settle ? config_.proximity_settle_gate : 0.0}) {
        for (int r = 0; ok && g > 0.0 && r < kProximityIterations; ++r) {
          const Eigen::Matrix3d T_was = T;
          if (!pairAndSolveAgain(g)) break;
          const Eigen::Vector3d d = se2::log(se2::inverse(T_was) * T);
          if (d.head<2>().norm() < 1e-4 && std::abs(d(2)) < 1e-5) break;
        }
      }
      return ok;
    };
    if (proximity) registered = registerByProximity(true);
    // Re-associate by proximity under the registered pose and solve again. Upright ORB picks,
    // among the rows a return spans, a match biased toward the less-rotated row: with row
    // keypoints the keyframe rows under-rotated in turns (tight_turns: -1.0 % of the turned
    // yaw in left turns, -0.4 % in right ones). The nearest keyframe point under the solved
    // pose rounds both ways. Measured (400 scans, keyframe): city_wide 0.61 -> 0.48 %,
    // tight_turns 1.31 -> 0.85 %, out_and_back_v2 1.18 -> 0.73 %, held-out city_v5 1.36 ->
    // 0.63 %; RADIATE consistency 0.236 -> 0.211 deg; worse: city_beam2.4 0.68 -> 0.88 %,
    // Oxford pairs 0.031 -> 0.042 deg (within their 0.05 deg sigma). A 0.6 m gate was worse.
    // The covariances stay the descriptor solve's: the rows of one return, each its own
    // nearest-point pair, are not independent, and counting them made the accumulated-pose
    // NEES 9.8 on a city layout (test_keyframe_row_quantization).
    // Descriptors failed narrowly where the proximity fallback does not run (a turn entry:
    // 29 inliers against 30, city_oxford t = 44 s): the pair step's prediction is 0.25-0.9 deg
    // off there, and registrations with 12-17 inliers were 0.10 deg rms off against 0.21 for
    // that prediction (12 columns pooled). Such a weak registration is kept, and the scan
    // becomes the keyframe: registering later scans to the old keyframe took the later
    // switches at worse registrations (accepting 12 inliers throughout: city_narrow 0.18 ->
    // 0.58 %, tight_turns 0.12 -> 0.19 %; docs/sensor_columns/round06_far_field_not_refound.md).
    if (!registered && !proximity) {
      T = T_odo;
      xi = xi_prior;
      min_inliers_ = kMinWeakInliers;
      weak = registered = solve(T_odo, C_odo, xi_prior, Cxi, Cxi_honest, T, xi, cov, cov_pub, cov_acc);
      min_inliers_ = kMinInliers;
      // Not even that: the scan would become the keyframe at the prediction, which is what
      // carried the most yaw into the chain at turn exits (city_oxford layout 1, t = 29.25 s:
      // -0.70 deg; the keyframe-to-scan angle 0.148 rad, just under kProximityMinAngle). Last
      // resort: the proximity ICP, kept only if the pose it finds agrees with the prediction
      // within its covariance (kLastResortChi2); the scan becomes the keyframe as after a
      // weak registration. On real RADIATE scans half a second apart (the consistency
      // column's skip runs) it walked off by 3 deg, squared distance 15.6; accepted there,
      // RADIATE consistency 0.253 -> 0.301 deg. Drift, city_oxford layouts 0 / 1 / 2: 0.22 /
      // 0.62 / 0.28 -> 0.22 / 0.32 / 0.25 % (layout 0's one such scan, squared distance 13.6,
      // stays refused); the other 9 city layouts, the other matrix columns and the real
      // Oxford pairs unchanged.
      if (!registered) {
        weak = registered = registerByProximity(false);
        if (registered) {
          const Eigen::Vector3d dy = se2::log(se2::inverse(T_odo) * T);
          const Eigen::Vector3d e(T(0, 2) - T_odo(0, 2), T(1, 2) - T_odo(1, 2), dy(2));
          if (e.dot(C_odo.ldlt().solve(e)) > kLastResortChi2) {
            weak = registered = false;
            last_inliers_ = 0;
            T = T_odo;
            xi = xi_prior;
          }
        }
      }
    }
    if (registered) pairAndSolveAgain(kReassociateGate);
    if (registered) {
      T_jk = T;
      const Eigen::Matrix3d L = se2::leftPerturbationToXyYaw(T);
      C_jk = L * cov.topLeftCorner<3, 3>() * L.transpose();
      // The keyframe's own uncertainty: its points were moved to its reference time with
      // its velocity estimate, over on average half a scan, so a velocity error dxi_j moves
      // the whole map by about exp(dt/2 dxi_j) (left perturbation in the keyframe frame).
      C_pub = L * cov_pub.topLeftCorner<3, 3>() * L.transpose();
      // The velocity the scan's frame and, should it become the keyframe, its map are moved
      // with (one for both, or the chain's mid-scan poses would not cancel). Where the yaw
      // rate changes, the registration's own: the pair velocity is centred half a scan
      // earlier and lags a 1 rad/s^2 ramp by 0.1-0.2 rad/s (tight_turns: 0.082 against 0.018
      // rad/s rms at mid-scan), and a step inside the scan shows in the registration first.
      // Elsewhere the pair velocity: a registration's yaw rate follows the keyframe map's (the
      // map was moved with it), so keyframes taken one after another passed it on and it
      // grew (city_narrow straight, 14 s: 0.02 -> 0.13 rad/s, the truth 0). Both thresholds
      // are about 10x the scan-to-scan noise on straights.
      // A keyframe taken in a ramp (turn exit) holds the ramp's velocity error in its map, and
      // a registration's yaw rate follows the map's: the scans after it, on a straight, came
      // out 0.08-0.16 rad/s off (truth 0, pair 0) and passed that on to the next keyframes
      // (city_narrow layout 2: 1 deg in the chain over 7 s). Against such a keyframe the
      // registration's yaw rate must also differ from the pair's by the gap relative to the
      // keyframe's own (registered minus pair velocity at the keyframe) to count.
      // The same across a dropped scan (a step of two periods, issue 19): every other scan,
      // most scans become keyframes after weak registrations and the offset was passed on at
      // every scan (skip_city_oxford, a straight at t = 18-21 s: -0.06 -> -0.15 rad/s, truth
      // 0). Every other scan, keyframe+peaks: skip_city_oxford 4.97 -> 2.23 %,
      // skip_city_mulran 0.66 -> 0.38, skip_city_wide 0.26 -> 0.12 (docs/dropped_scans.md).
      // Not after every keyframe at 4 Hz: city_narrow layout 2 0.14 -> 0.19 % that way.
      // Either way only when the difference is also yaw_rate_sigmas of its own standard
      // deviation (the registration's published yaw-rate variance and the pair's): within a
      // scan the yaw rate trades against the yaw, and where returns scatter across the beam
      // the registration measures it to 0.02-0.07 rad/s (real RADIATE scans). There a 2.2
      // sigma outlier (0.079 rad/s off the pair's, a skip run of the consistency column) moved
      // one published pose by 0.57 deg: RADIATE consistency 0.191 -> 0.120 deg with 4 sigma
      // (the same with 2.5-6); simulated columns the same or better (city_oxford 0.50 -> 0.25
      // %) but city_glint0.14 0.392 -> 0.397 %, city_mulran layout 1 0.244 -> 0.247 % (3
      // sigma: city_beam2.4 0.095 -> 0.098 %, 2.5: city_oxford 0.44; docs/radiate_consistency.md).
      double gap = std::abs(xi(2) - pair.velocity(2));
      if (key_ramp_ || gap_step)
        gap = std::min(gap, std::abs((xi(2) - key_xi_(2)) - (pair.velocity(2) - key_pair_xi_(2))));
      const double sd = std::sqrt(cov_pub(5, 5) + pair.velocity_cov(2, 2));
      // yaw_rate_map_check: the same difference again against the same keyframe, the pair's
      // yaw rate steady, is the keyframe map's own yaw-rate error (mapRateBias), not motion.
      const bool repeated = mapRateBias(xi(2) - pair.velocity(2));
      const bool map_bias = config_.yaw_rate_map_check && !pair_ramp && repeated;
      if ((gap > kRegisteredYawRateGap && gap > config_.yaw_rate_sigmas * sd && !map_bias) ||
          pair_ramp) {
        xi_key = xi;
        xi_cov_pub = cov_pub.bottomRightCorner<3, 3>();
      } else {  // the pair velocity's error is its own, independent of the registered pose
        for (Eigen::Matrix<double, 6, 6>* m : {&cov_pub, &cov_acc}) {
          m->topRightCorner<3, 3>().setZero();
          m->bottomLeftCorner<3, 3>().setZero();
        }
        // Its lag: the acceleration seen over the last scan plus the step model's noise.
        cov_pub.bottomRightCorner<3, 3>() = Cxi_acc_;
        cov_acc.bottomRightCorner<3, 3>() = Cxi_acc_;
      }
    }
  }
  // Back to scan-start frames for publishing: T_rel = E_j T_jk E_k^-1 (E = exp(c xi), the
  // mid-scan frame in the scan-start one). First order in the left perturbation of T_jk
  // (delta) and of xi_k (dxi): eps = Ad(E_j) delta - c Ad(T_rel) dxi.
  const Eigen::Vector3d& xi_k = xi_key;
  // Yaw-rate change since the last scan beyond what white-noise acceleration explains.
  const double dw_step = std::max(0.0, std::abs(xi_k(2) - prev_xi_(2)) - kAngAccelSigma * dt);
  const Eigen::Matrix3d E_j = se2::exp(key_c_ * key_xi_);
  const Eigen::Matrix3d T_rel = E_j * T_jk * se2::exp(-c * xi_k);
  Eigen::Matrix3d C_rel;
  const Eigen::Matrix3d Lm = se2::leftPerturbationToXyYaw(T_jk);
  // The covariance over [T_jk (left perturbation), xi_k] from a solve's (cov_pub or
  // cov_acc) with the model errors below added.
  auto withModelErrors = [&](const Eigen::Matrix<double, 6, 6>& solved) {
    Eigen::Matrix<double, 6, 6> Cd = solved;
    if (!registered) {  // only the chained pose covariance (xyYaw of T_jk) is known
      Cd.setZero();
      Cd.topLeftCorner<3, 3>() = Lm.inverse() * C_pub * Lm.inverse().transpose();
    }
    // A yaw-rate step (turn entry, exit) can fall anywhere in this scan: the yaw rate worked
    // back with is off by between 0 and the step (uniform: second moment dw^2 / 3). Without this the turn exits held NEES of 100-800 (1-1.8 deg errors
    // against 0.06-0.15 deg sigmas).
    Cd(5, 5) += dw_step * dw_step / 3.0;
    // Row keypoints: a target moves by a fractional number of rows between the keyframe and
    // this scan and every match rounds it the same way, so the registration's yaw has an
    // error common to all its points, about uniform over a row (variance step^2 / 12), which
    // averaging over points does not shrink. Measured on the city route (400 scans, keyframe
    // switches on straights): yaw error rms 0.26 deg = 0.9 deg / sqrt(12) with row keypoints,
    // 0.09 deg with azimuth peaks; the accumulated-pose NEES was 9.99 without this term.
    if (registered) Cd(2, 2) += row_step_ * row_step_ / 12.0;
    return Cd;
  };
  {
    const Eigen::Matrix3d Lr = se2::leftPerturbationToXyYaw(T_rel);
    const Eigen::Matrix<double, 6, 6> Cd = withModelErrors(cov_pub);
    Eigen::Matrix<double, 3, 6> J;
    J.leftCols<3>() = se2::adjoint(E_j);
    J.rightCols<3>() = -c * se2::adjoint(T_rel);
    // The keyframe's own uncertainty: its points were moved to its mid-scan time with its
    // velocity estimate, so a velocity error dxi_j moves the map by about exp(c_j dxi_j).
    const Eigen::Matrix3d Ce = J * Cd * J.transpose() + key_c_ * key_c_ * key_xi_cov_;
    C_rel = Lr * Ce * Lr.transpose();
  }
  se2::compoundXyYaw(T_wj_, P_j_, T_rel, C_rel, T_w, P);
  // The accumulated pose's covariance, chained at mid-scan (issue 19). The pose is
  // T_wj E_j T_jk E_k^-1 and the keyframe's own pose T_wj was T_wj' E_j' T_j'j E_j^-1, with
  // the same E_j = exp(key_c_ key_xi_): the extrapolations to scan start cancel along the
  // chain and only this scan's own (E_k^-1) is an error of the published pose. Compounding
  // the scan-start covariances (P_j_ with C_rel) counted every keyframe's extrapolation
  // twice, and kept: an over-statement that hid part of the over-confidence in turns. So the
  // chain runs over the keyframes' mid-scan poses M_j = T_wj E_j (P_jm_), with cov_acc.
  Eigen::Matrix3d P_m_next;  // M_k's, should this scan become the keyframe
  Eigen::Matrix3d C_jk_acc, Cxi_k_acc;  // T_jk's [x, y, yaw] and xi_k's (keyframe_fusion)
  const Eigen::Matrix<double, 6, 6> Cd_acc = withModelErrors(cov_acc);
  {
    const Eigen::Matrix3d M_j = T_wj_ * E_j;
    const Eigen::Matrix3d T_mk = T_jk * se2::exp(-c * xi_k);  // this scan's start, from M_j
    Eigen::Matrix<double, 3, 6> J;
    J.leftCols<3>().setIdentity();
    J.rightCols<3>() = -c * se2::adjoint(T_jk);
    const Eigen::Matrix3d Lk = se2::leftPerturbationToXyYaw(T_mk);
    // The keyframe map's own error stays: its points were moved to M_j with its velocity
    // estimate, by up to c_j, so a velocity error dxi_j moves them by up to c_j dxi_j (as
    // in C_rel). Without it a keyframe taken at a failed turn scan (tight_turns layout 1:
    // 19 deg off, key_xi_cov_ holding the yaw-rate step) left the chain at NEES 76.
    const Eigen::Matrix3d Ckey = key_c_ * key_c_ * key_xi_cov_;
    const Eigen::Matrix3d C_mk = Lk * (J * Cd_acc * J.transpose() + Ckey) * Lk.transpose();
    Eigen::Matrix3d T_unused;
    se2::compoundXyYaw(M_j, P_jm_, T_mk, C_mk, T_unused, P);
    C_jk_acc = Lm * (Cd_acc.topLeftCorner<3, 3>() + Ckey) * Lm.transpose();
    Cxi_k_acc = Cd_acc.bottomRightCorner<3, 3>();
    se2::compoundXyYaw(M_j, P_jm_, T_jk, C_jk_acc, T_unused, P_m_next);
  }
  blendStartRate(config_, key_stamp_ != rel_key_stamp_, prev_pair_xi_(2), dt, T_w_prev, pair.T_12,
                 T_w);
  pair.T_12 = se2::inverse(T_w_prev) * T_w;
  rel_key_stamp_ = key_stamp_;
  rel_T_ = T_rel;
  rel_C_ = C_rel;
  if (registered && key_inliers_ == 0) key_inliers_ = last_inliers_;
  const double dist = T_jk.topRightCorner<2, 1>().norm();
  const double ang = std::abs(std::atan2(T_jk(1, 0), T_jk(0, 0)));
  // Where one scan alone turns further than keyframe_angle, every scan would become a keyframe
  // and hand on a registration made under the turn's largest distortion: keyframe_angle_fast.
  const double scan_turn = std::abs(xi_k(2)) * c / kMidScan;
  const double switch_angle = scan_turn > config_.keyframe_angle
                                  ? std::max(config_.keyframe_angle, config_.keyframe_angle_fast)
                                  : config_.keyframe_angle;
  const bool renew = (!still && !registered) || weak || dist > config_.keyframe_distance || ang > switch_angle ||
                     (registered && last_inliers_ < config_.keyframe_inlier_ratio * key_inliers_);
  prev_c_ = c;
  prev_pair_xi_ = pair.velocity;
  prev_xi_ = xi_k;
  if (renew) {
    // EstimatorConfig::keyframe_fusion: register the new keyframe against the earlier ones
    // too and fuse (keyframe_fusion.cpp); its published pose and covariance follow.
    Eigen::Matrix3d M_k = T_wj_ * E_j * T_jk;
    // EstimatorConfig::keyframe_graph instead: a pose graph over the window (keyframe_graph.cpp).
    if (config_.keyframe_graph > 0) {  // its full window reserved: the edge vectors circulate
      new_edges_.reserve(static_cast<size_t>(config_.keyframe_graph));
      new_edges_.assign(1, GraphEdge{key_stamp_, T_jk, C_jk_acc});
    }
    const bool graphed = config_.keyframe_graph > 0 && !still &&
                         solveGraph(cur, c, T_jk, C_jk_acc, M_k);
    // keyframe_graph_rate: the velocity follows the graph's pose correction (keyframe_graph.cpp).
    if (graphed && config_.keyframe_graph_rate) {
      xi_key += graphVelocityCorrection(T_jk, E_j, M_k, Cd_acc);
      prev_xi_ = xi_key;
    }
    if (graphed || (config_.keyframe_graph == 0 && config_.keyframe_fusion > 0 && !still &&
                    fuseWithPast(cur, c, T_jk, C_jk_acc, M_k, P_m_next))) {
      const Eigen::Matrix3d E_k = se2::exp(-c * xi_k);
      const Eigen::Matrix3d Le = se2::leftPerturbationToXyYaw(E_k);
      const Eigen::Matrix3d C_e = Le * (c * c * Cxi_k_acc) * Le.transpose();
      se2::compoundXyYaw(M_k, P_m_next, E_k, C_e, T_w, P);
      pair.T_12 = se2::inverse(T_w_prev) * T_w;
    }
    pushPastKeyframe();
    key_rel_cov_ = C_jk_acc;
    key_xi_cov_ = xi_cov_pub;
    key_xi_cov_(2, 2) += dw_step * dw_step / 3.0;  // as above: its map was moved with that rate
    makeKeyframe(cur, xi_key, c, T_w, P);
    key_edges_.swap(new_edges_);
    key_pair_xi_ = pair.velocity;
    key_ramp_ = pair_ramp;
    P_jm_ = P_m_next;
    key_accel_ = accel_;  // the acceleration its map was built under
  } else {
    T_jprev_ = T_jk;
    C_jprev_ = C_jk;
    C_jprev_pub_ = C_pub;
  }
}

}  // namespace spinradar
