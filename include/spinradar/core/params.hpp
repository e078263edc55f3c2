#pragma once
// The single definition of every pipeline parameter: name, type, default, range, unit, doc.
// Nodelets (ROS params + dynamic_reconfigure via cfg/*.cfg), the CLI (CLI11 options) and the
// README table are all generated from these lists. Keep one entry per line (parsed by cfg/).
#include <string>

#include "spinradar/core/param_macros.hpp"

// clang-format off
#define SPINRADAR_DETECTOR_PARAMS(X) \
  X(std::string, detector, "cen2018", 0, 0, "", "Keypoint detector: cen2018 or cfar") \
  X(double, zq, 3.0, 0.0, 20.0, "sigma", "Cen2018 probability threshold z_q (noise std above mean)") \
  X(int, sigma_gauss, 17, 1, 100, "bins", "Cen2018 Gaussian smoothing sigma along range") \
  X(int, cfar_window, 40, 4, 400, "bins", "CA-CFAR training cells on each side") \
  X(int, cfar_guard, 2, 0, 50, "bins", "CA-CFAR guard cells on each side") \
  X(double, cfar_threshold, 2.0, 0.1, 50.0, "x mean", "CA-CFAR threshold factor over the cell average") \
  X(double, min_range, 2.5, 0.0, 100.0, "m", "Ignore returns closer than this (vehicle, near-field leakage)") \
  X(double, max_range, 160.0, 1.0, 500.0, "m", "Ignore returns farther than this") \
  X(double, range_offset, 0.0, -5.0, 5.0, "m", "Added to every range (Boreas: -0.31)") \
  X(bool, azimuth_peaks, true, 0, 1, "", "One keypoint per return at its azimuthal power peak, sub-row azimuth and time (false: one per row at the row angle, the paper's front end)")

#define SPINRADAR_FEATURE_PARAMS(X) \
  X(double, cart_resolution, 0.2592, 0.01, 2.0, "m/px", "Cartesian image resolution") \
  X(int, cart_pixel_width, 964, 64, 4096, "px", "Cartesian image width and height") \
  X(int, orb_patch_size, 21, 5, 101, "px", "ORB descriptor patch size") \
  X(double, nndr, 0.8, 0.1, 1.0, "", "Nearest-neighbour distance ratio for matching") \
  X(int, max_keypoints, 0, 0, 100000, "", "Keep at most this many strongest keypoints (0 = all)")

#define SPINRADAR_ESTIMATOR_PARAMS(X) \
  X(std::string, estimator, "keyframe", 0, 0, "", "Motion estimator: rigid, mc, mc_doppler, refined, keyframe or surface") \
  X(int, ransac_iterations, 100, 1, 10000, "", "RANSAC iterations") \
  X(double, inlier_threshold, 0.35, 0.01, 5.0, "m", "RANSAC inlier threshold") \
  X(int, ransac_seed, 7, 0, 1000000, "", "RANSAC random seed (fixed for reproducibility)") \
  X(int, gn_iterations, 10, 1, 100, "", "Gauss-Newton iterations of MC-RANSAC refits") \
  X(double, beta, 0.049, 0.0, 1.0, "s", "Doppler coefficient beta = f_t / (df/dt)") \
  X(double, range_sigma, 0.0438, 0.001, 1.0, "m", "Range noise std for Cartesian covariance weighting") \
  X(double, azimuth_sigma, 0.0045, 0.0001, 0.1, "rad", "Azimuth noise std for Cartesian covariance weighting") \
  X(bool, robust_loss, true, 0, 1, "", "Cauchy loss, scaled by the median residual, in the refit of refined (the pair estimate of keyframe and surface); false: every gated match weighted 1. mc and mc_doppler stay the paper's least squares") \
  X(std::string, azimuth_times, "stamps", 0, 0, "", "Keypoint times: stamps (each row's recorded stamp) or uniform (a line fitted to the scan's row stamps: for stamps that are packet arrival times, as in Oxford and MulRan)") \
  X(int, submap_keyframes, 2, 1, 8, "", "keyframe: a new keyframe's map points are averaged with their nearest points (within 0.5 m) in the last submap_keyframes - 1 keyframes, which averages the scatter (glint) of the map's returns; an earlier keyframe whose points a rigid fit moves by over 0.2 deg or 0.15 m onto the new one's is left out (1: its own points)") \
  X(double, floor_gate, 0.0, 0.0, 20.0, "x floor", "keyframe: the registration's inlier gate is at least this multiple of its measured tangential noise floor (0: inlier_threshold only)") \
  X(double, yaw_rate_sigmas, 4.0, 0.0, 20.0, "x sigma", "keyframe: a registration's own yaw rate replaces the pair velocity's (in its published pose and its keyframe map) only when they differ by this multiple of the difference's standard deviation as well as by 0.05 rad/s (0: by 0.05 rad/s only)") \
  X(bool, yaw_rate_map_check, true, 0, 1, "", "keyframe: a registration's yaw rate that differs from the pair velocity's by the same amount (within 0.05 rad/s) as the previous scan's against the same keyframe, the pair's yaw rate steady, is the keyframe map's own yaw-rate error and is not used (false: the difference alone decides; docs/sensor_columns/round19_map_rate_bias.md)") \
  X(double, proximity_settle_gate, 0.0, 0.0, 1.5, "m", "keyframe: the proximity ICP (keyframe turned away from the scan, descriptors failed) iterates on at this narrower gate until it settles, after its 0.6 m iterations (0: one re-association at 0.3 m)") \
  X(double, keyframe_angle, 0.35, 0.05, 1.5, "rad", "keyframe: a scan turned further than this from the keyframe becomes the next keyframe (as one beyond keyframe_distance, or one registered weakly)") \
  X(double, keyframe_distance, 9.0, 1.0, 100.0, "m", "keyframe: a scan further than this from the keyframe becomes the next keyframe (as one turned beyond keyframe_angle, or one registered weakly); 9 since the twenty-second round (10 before: geometric mean of drift 0.91x over the 22 tuning columns, 9 runs each; docs/sensor_columns/round22_keyframe_spacing_phases.md); 7 m lowers it further on the RADIATE, Boreas-RT and glint Oxford models and raises it on the simulator's own") \
  X(double, keyframe_inlier_ratio, 0.5, 0.0, 1.0, "", "keyframe: a scan whose registration keeps fewer inliers than this fraction of the first registration against its keyframe becomes the next keyframe (0: never by this rule)") \
  X(double, keyframe_angle_fast, 0.35, 0.05, 1.5, "rad", "keyframe: the switch angle in turns where one scan alone turns further than keyframe_angle (every scan would otherwise become a keyframe); at or below keyframe_angle: no effect (docs/sensor_columns/round15_keyframe_angle.md)") \
  X(int, keyframe_fusion, 0, 0, 2, "", "keyframe: a scan that becomes the keyframe is also registered against the last keyframe_fusion keyframes before the current one, and its pose is the information-weighted fusion of those registrations with the chained one (each extra estimate gated by chi-square against it; 0: the chained pose only)") \
  X(int, keyframe_graph, 6, 0, 10, "", "keyframe: a scan that becomes the keyframe is registered against each of the last keyframe_graph keyframes (weak and proximity registrations too, each gated by chi-square against the chained pose), and the window's poses are solved as a pose graph (information-weighted least squares on SE(2), the oldest held); the new keyframe takes its solved pose, published poses stay causal (0: the chained pose only)") \
  X(int, graph_proximity_rounds, 5, 1, 100, "", "keyframe_graph: at most this many rounds of pairing by proximity and solving again per gate of the proximity ICP in a new keyframe's registrations to past keyframes, fewer where the pose settles first; under dense clutter most of these loops do not settle (30 before the seventeenth round; docs/sensor_columns/round17_proximity_rounds.md)") \
  X(bool, keyframe_graph_screen, false, 0, 1, "", "keyframe_graph: each extra edge of a new keyframe is tested against the window solved without it (leave-one-out chi-square, 99 %, 3 dof) and the worst failing one dropped until none fails (measured, docs/sensor_columns/round11_keyframe_graph.md: it loses city_oxford_glint0.14, so off)") \
  X(bool, keyframe_graph_rate, true, 0, 1, "", "keyframe_graph: the graph's correction of a new keyframe's mid-scan pose also corrects its velocity through the registration's joint pose-velocity covariance (where the registration's own yaw rate was used), so its published scan-start pose and its map follow; off: the turn-entry loss of docs/sensor_columns/round12_graph_rate.md") \
  X(bool, keyframe_graph_step, true, 0, 1, "", "keyframe_graph: the solved window is translated until the current keyframe sits at its published position, so the new keyframe takes the window's step from there (every heading stays the window's); off: the new keyframe takes its solved position, where the window's heading correction, a rotation about its oldest keyframe, moved new keyframes on straights sideways by up to 11 cm (docs/sensor_columns/round13_graph_losses.md; matrix of the thirteenth round: drift 5 % lower, geometric mean over 25 simulated columns)") \
  X(double, start_rate_pair_weight, 0.25, 0.0, 1.0, "", "keyframe: the first scan after a keyframe switch made in a turn (pair yaw rate over 3 deg/s, one scan turning no further than keyframe_angle) is published with its yaw increment from the previous scan blended with the scan-to-scan pair estimate's at this weight; its relative pose to the keyframe stays the registration's (0: off; 0.25 since the twentieth round, docs/sensor_columns/round20_start_rate_default.md: tight_turns 8 % lower, every other column within 3 %; 0.5 worse)")
// clang-format on

namespace spinradar {

struct DetectorConfig {
  SPINRADAR_DECLARE_PARAMS(SPINRADAR_DETECTOR_PARAMS)
  void validate() const;  ///< throws std::invalid_argument naming the parameter
};

struct FeatureConfig {
  SPINRADAR_DECLARE_PARAMS(SPINRADAR_FEATURE_PARAMS)
  void validate() const;
};

struct EstimatorConfig {
  SPINRADAR_DECLARE_PARAMS(SPINRADAR_ESTIMATOR_PARAMS)
  void validate() const;
};

/// Everything the odometry pipeline needs.
struct PipelineConfig {
  DetectorConfig detector;
  FeatureConfig features;
  EstimatorConfig estimator;
  void validate() const {
    detector.validate();
    features.validate();
    estimator.validate();
  }
  template <class F>
  void visit(F&& f) {
    detector.visit(f);
    features.visit(f);
    estimator.visit(f);
  }
  template <class F>
  void visit(F&& f) const {
    detector.visit(f);
    features.visit(f);
    estimator.visit(f);
  }
};

}  // namespace spinradar
