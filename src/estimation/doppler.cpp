#include "spinradar/estimation/doppler.hpp"

namespace spinradar {

void dopplerCorrect(std::vector<Keypoint>& keypoints, const Eigen::Vector3d& velocity,
                    double beta) {
  for (Keypoint& k : keypoints) {
    const double c = std::cos(k.azimuth), s = std::sin(k.azimuth);
    const double dr = beta * (velocity(0) * c - velocity(1) * s);  // beta * beamVelocity
    k.range += dr;
    k.x += dr * c;   // beam direction (cos phi, -sin phi)
    k.y -= dr * s;
  }
}

void dopplerCorrect(const std::vector<Keypoint>& in, const Eigen::Vector3d& velocity,
                    double beta, std::vector<Keypoint>& out) {
  out.assign(in.begin(), in.end());
  dopplerCorrect(out, velocity, beta);
}

bool estimateMcDoppler(McRansac& mc, const std::vector<Keypoint>& k1,
                       const std::vector<Keypoint>& k2, const std::vector<Match>& matches,
                       int64_t ref1_ns, int64_t ref2_ns, double beta,
                       std::vector<Keypoint>& k1c, std::vector<Keypoint>& k2c,
                       MotionEstimate& out) {
  if (!mc.estimate(k1, k2, matches, ref1_ns, ref2_ns, out)) {
    k1c.assign(k1.begin(), k1.end());
    k2c.assign(k2.begin(), k2.end());
    return false;
  }
  // Constant velocity across both scans: the same correction applies to each. Always
  // correct the raw keypoints with the latest velocity (never correct twice).
  for (int round = 0; round < kDopplerRounds; ++round) {
    const Eigen::Vector3d before = out.velocity;
    dopplerCorrect(k1, out.velocity, beta, k1c);
    dopplerCorrect(k2, out.velocity, beta, k2c);
    if (!mc.refit(k1c, k2c, matches, ref1_ns, ref2_ns, out, false)) return false;
    if ((out.velocity - before).head<2>().norm() < kDopplerTolerance) break;
  }
  return out.ok = mc.updateCovariance(ref1_ns, ref2_ns, out);
}

}  // namespace spinradar
