#pragma once
// Sensor model parameters (Navtech CIR204-H defaults). One definition, like params.hpp.
#include <string>

#include "spinradar/core/param_macros.hpp"

// clang-format off
#define SPINRADAR_SENSOR_PARAMS(X) \
  X(double, rotation_hz, 4.0, 0.5, 20.0, "Hz", "Rotation rate") \
  X(int, azimuths, 400, 16, 4000, "", "Azimuths per rotation") \
  X(int, encoder_size, 5600, 16, 65535, "counts", "Encoder counts per rotation") \
  X(int, bins, 3768, 16, 16384, "", "Range bins per azimuth") \
  X(double, range_resolution, 0.0438, 0.001, 1.0, "m", "Range bin size") \
  X(double, beam_width_deg, 1.8, 0.1, 20.0, "deg", "One-way -3 dB azimuth beam width") \
  X(double, noise_floor_db, 18.0, 0.0, 100.0, "dB", "Mean receiver noise power (speckle, exponential)") \
  X(double, range_gain_db_per_decade, 30.0, 0.0, 60.0, "dB/dec", "Range gain (STC) compensating spreading loss") \
  X(double, power_scale, 1.0, 0.1, 10.0, "count/dB", "Output counts per dB (Navtech: about 1)") \
  X(double, saturation, 255.0, 1.0, 255.0, "count", "Largest output value")
// clang-format on

namespace spinradar::sim {

struct SensorConfig {
  SPINRADAR_DECLARE_PARAMS(SPINRADAR_SENSOR_PARAMS)
  void validate() const;
};

}  // namespace spinradar::sim
