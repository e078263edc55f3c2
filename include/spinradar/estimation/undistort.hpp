#pragma once
// Motion undistortion: every point of a scan, observed at its own time t, is moved to the
// sensor frame at one reference time t_ref with the constant body velocity xi:
//   p_ref = exp((t - t_ref) xi^) p_t   (T_ref,t = pose of the sensor at t in the frame at t_ref).
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "spinradar/core/feature_frame.hpp"

namespace spinradar {

/// Points (x, y) of `keypoints` moved to `ref_ns`; `out` is resized (capacity reused).
void undistortPoints(const std::vector<Keypoint>& keypoints, const Eigen::Vector3d& velocity,
                     int64_t ref_ns, std::vector<Eigen::Vector2d>& out);

/// In place: updates x, y and the polar range/azimuth (clockwise) of every keypoint; the
/// stamps are left as acquired.
void undistortKeypoints(std::vector<Keypoint>& keypoints, const Eigen::Vector3d& velocity,
                        int64_t ref_ns);

/// Generic form on points with their own stamps (n each).
void undistortPoints(const Eigen::Vector2d* points, const int64_t* stamps_ns, int n,
                     const Eigen::Vector3d& velocity, int64_t ref_ns, Eigen::Vector2d* out);

}  // namespace spinradar
