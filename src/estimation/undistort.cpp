#include "spinradar/estimation/undistort.hpp"

#include <cmath>

#include "spinradar/core/lie.hpp"

namespace spinradar {

namespace {

inline Eigen::Vector2d moveToRef(const Eigen::Vector2d& p, int64_t stamp_ns,
                                 const Eigen::Vector3d& velocity, int64_t ref_ns) {
  const double dt = 1e-9 * static_cast<double>(stamp_ns - ref_ns);
  const Eigen::Matrix3d T = se2::exp(dt * velocity);
  return T.topLeftCorner<2, 2>() * p + T.topRightCorner<2, 1>();
}

}  // namespace

void undistortPoints(const Eigen::Vector2d* points, const int64_t* stamps_ns, int n,
                     const Eigen::Vector3d& velocity, int64_t ref_ns, Eigen::Vector2d* out) {
  for (int i = 0; i < n; ++i) out[i] = moveToRef(points[i], stamps_ns[i], velocity, ref_ns);
}

void undistortPoints(const std::vector<Keypoint>& keypoints, const Eigen::Vector3d& velocity,
                     int64_t ref_ns, std::vector<Eigen::Vector2d>& out) {
  out.resize(keypoints.size());
  for (size_t i = 0; i < keypoints.size(); ++i) {
    const Keypoint& k = keypoints[i];
    out[i] = moveToRef({k.x, k.y}, k.stamp_ns, velocity, ref_ns);
  }
}

void undistortKeypoints(std::vector<Keypoint>& keypoints, const Eigen::Vector3d& velocity,
                        int64_t ref_ns) {
  for (Keypoint& k : keypoints) {
    const Eigen::Vector2d p = moveToRef({k.x, k.y}, k.stamp_ns, velocity, ref_ns);
    k.x = p.x();
    k.y = p.y();
    k.range = p.norm();
    double az = std::atan2(-p.y(), p.x());  // clockwise from forward, in [0, 2 pi)
    if (az < 0.0) az += 2.0 * M_PI;
    k.azimuth = az;
  }
}

}  // namespace spinradar
