// The landmark field of the keyframe glint tests: 900 landmarks seen to 100 m, azimuth-peak
// azimuths, and `glint` (m) of per-scan scatter along and across the beam.
#pragma once

#include <cmath>
#include <cstdint>

#include "support/synthetic_scene.hpp"

namespace spinradar::testing {

inline SceneOptions glintSceneOptions(uint32_t seed, double glint) {
  SceneOptions o;
  o.landmarks = 900;
  o.min_range = 4.0;
  o.max_range = 140.0;
  o.visible_range = 100.0;
  o.range_sigma = std::hypot(0.03, glint);  // glint along the beam, on the range noise
  o.azimuth_sigma = 0.001;                  // azimuth peaks: sub-row azimuths
  o.tangential_sigma = glint;               // and across it
  o.clutter = 100;
  o.seed = seed;
  return o;
}

}  // namespace spinradar::testing
