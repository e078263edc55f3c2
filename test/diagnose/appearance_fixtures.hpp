#pragma once
// Shared setup of the appearance-stage tests: a sensor reaching all four range bands and
// options for quick renders.
#include "spinradar/diagnose/appearance.hpp"
#include "spinradar/sim/sensor_config.hpp"

namespace spinradar::diagnose::testing {

/// 2300 bins x 0.0438 m = 100 m: all four bands (2.5-10, 10-25, 25-50, 50-100 m).
inline sim::SensorConfig hundredMetreSensor() {
  sim::SensorConfig s;
  s.bins = 2300;
  return s;
}

/// Three scans per render keep each stage to a few seconds.
inline AppearanceOptions quickAppearanceOptions() {
  AppearanceOptions o;
  o.scans = 3;
  return o;
}

}  // namespace spinradar::diagnose::testing
