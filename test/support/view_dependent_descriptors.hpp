// ORB on the Cartesian image changes as the scene turns under the sensor: each bit of a
// landmark's descriptor flips once the heading passes its own random threshold within 45 deg.
// A scan pair 9 deg apart still matches; a keyframe 15-20 deg back mostly does not, as at the
// city route's corners and on tight_turns (the proximity ICP registers there).
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "support/synthetic_scene.hpp"
#include "spinradar/core/lie.hpp"

namespace spinradar::testing {

class ViewDependentDescriptors {
 public:
  ViewDependentDescriptors(int landmarks, uint32_t seed) : flip_at_(static_cast<size_t>(landmarks) * 256) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    for (double& t : flip_at_) t = 45.0 * M_PI / 180.0 * u01(rng);
  }
  /// Flips the bits of scan k's descriptors (ids: their landmarks, -1 = clutter).
  void apply(SyntheticScene& sc, int k, FeatureFrame& f, const std::vector<int>& ids) const {
    const double heading = std::abs(se2::log(sc.pose(sc.scanStart(k)))(2));
    for (size_t r = 0; r < ids.size(); ++r) {
      if (ids[r] < 0) continue;
      for (int b = 0; b < 256; ++b)
        if (flip_at_[static_cast<size_t>(ids[r]) * 256 + b] < heading)
          f.descriptors.at<uint8_t>(static_cast<int>(r), b / 8) ^= static_cast<uint8_t>(1u << (b % 8));
    }
  }

 private:
  std::vector<double> flip_at_;
};

}  // namespace spinradar::testing
