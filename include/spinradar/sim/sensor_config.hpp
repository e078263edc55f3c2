#pragma once
// Sensor model parameters (Navtech CIR204-H defaults). One definition, like params.hpp.
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "spinradar/core/param_macros.hpp"

// clang-format off
#define SPINRADAR_SENSOR_PARAMS(X) \
  X(double, rotation_hz, 4.0, 0.5, 20.0, "Hz", "Rotation rate") \
  X(int, azimuths, 400, 16, 4000, "", "Azimuths per rotation") \
  X(int, encoder_size, 5600, 16, 65535, "counts", "Encoder counts per rotation") \
  X(int, bins, 3768, 16, 16384, "", "Range bins per azimuth") \
  X(double, range_resolution, 0.0438, 0.001, 1.0, "m", "Range bin size") \
  X(double, beam_width_deg, 1.8, 0.1, 20.0, "deg", "One-way -3 dB azimuth beam width") \
  X(double, noise_floor_db, 8.0, 0.0, 100.0, "dB", "Mean receiver noise power (speckle, exponential)") \
  X(double, range_gain_db_per_decade, 30.0, 0.0, 60.0, "dB/dec", "Range gain (STC) compensating spreading loss") \
  X(double, power_scale, 1.0, 0.1, 10.0, "count/dB", "Output counts per dB (Navtech: about 1)") \
  X(int, native_codes, 1, 0, 1, "", "1 = native Navtech code set (integer amplitude, then dB: 0, 6, 9, 12, ...); 0 = rescaled dB, every code (RADIATE images)") \
  X(double, saturation, 255.0, 1.0, 255.0, "count", "Largest output value") \
  X(double, min_range, 0.5, 0.0, 50.0, "m", "Returns closer than this are not rendered") \
  X(double, radar_constant_db, 103.0, 0.0, 300.0, "dB", "Received power of a 0 dBsm point at 1 m before range gain") \
  X(double, noise_range_slope_db_per_decade, 0.0, -40.0, 40.0, "dB/dec", "Noise floor change per decade of range (from 10 m)") \
  X(double, clutter_db, 2.0, 0.0, 80.0, "dB", "Diffuse ground clutter power at 10 m, above the noise floor") \
  X(double, clutter_db_per_decade, -14.0, -60.0, 0.0, "dB/dec", "Ground clutter change per decade of range") \
  X(double, clutter_density, 0.0, 0.0, 4.0, "1/m^2", "Textured clutter: world-fixed point scatterers per m^2 around the route (0 = off)") \
  X(double, clutter_rcs_db, -30.0, -80.0, 20.0, "dBsm", "Median RCS of the textured clutter scatterers") \
  X(double, clutter_rcs_sd_db, 6.0, 0.0, 20.0, "dB", "Log-normal spread of the textured clutter RCS") \
  X(double, noise_texture_db, 0.0, 0.0, 15.0, "dB", "Std of a slow log-normal texture on the noise (heavy-tailed, K-like clutter; 0 = pure speckle)") \
  X(double, noise_texture_bins, 8.0, 1.0, 200.0, "bins", "Range correlation length of the noise texture") \
  X(double, stc_range, 0.0, 0.0, 100.0, "m", "Near-range STC: closer than this every return and the noise are attenuated (0 = off)") \
  X(double, stc_near_db_per_decade, 30.0, 0.0, 80.0, "dB/dec", "Near-range STC attenuation per decade of range below stc_range") \
  X(double, leakage_db, 0.0, 0.0, 80.0, "dB", "Near-range leakage at 0 m above the noise floor (0 = off)") \
  X(double, leakage_range, 1.0, 0.05, 50.0, "m", "Range over which the near-range leakage falls by 10 dB") \
  X(double, compression_knee, 255.0, 1.0, 255.0, "count", "Output count above which the receiver compresses") \
  X(double, compression_ratio, 1.0, 0.05, 1.0, "", "Output counts per dB above the compression knee (1 = none)") \
  X(double, range_psf_sigma_bins, 2.7, 0.3, 20.0, "bins", "Std of the Gaussian-like range mainlobe in power (real CTS350-X/CIR204: ~2.7)") \
  X(double, range_psf_odd_ratio, 1.0, 0.5, 3.0, "", "Range mainlobe std (and noise correlation) on odd azimuths over range_psf_sigma_bins, which holds for even ones: alternating chirps of unequal range resolution (Boreas-RT RAS6: the up chirp on odd rows, fitted 1.32); 1 = one chirp") \
  X(double, range_sidelobe_db, -60.0, -120.0, -10.0, "dB", "FFT-window range sidelobe level (decaying as offset^-3)") \
  X(int, range_psf_half_width, 24, 2, 64, "bins", "Half width of the rendered range point spread") \
  X(double, azimuth_sidelobe_db, -50.0, -80.0, -10.0, "dB", "Two-way azimuth sidelobe plateau relative to the peak") \
  X(double, azimuth_extent_deg, 4.0, 1.0, 30.0, "deg", "Half width of the rendered azimuth pattern") \
  X(double, noise_row_jitter_db, 2.0, 0.0, 20.0, "dB", "Std of the per-azimuth noise floor level (AR(1) across azimuths)") \
  X(double, incidence_exponent, 2.0, 0.0, 10.0, "", "Wall back-scatter falls as cos(incidence)^n") \
  X(double, wall_spacing, 0.25, 0.02, 5.0, "m", "Spacing of the scatterers a wall is rendered with") \
  X(double, wall_texture_db, 5.0, 0.0, 20.0, "dB", "Std of the per-scatterer facade texture") \
  X(double, occlusion_tolerance, 0.25, 0.0, 5.0, "m", "Scatterers this far behind the first wall still show") \
  X(double, mount_height, 2.0, 0.0, 50.0, "m", "Height of the antenna above the ground: a wall of a world's 'height' hides a target behind it only below the line from here over its top (no effect on worlds without heights)") \
  X(double, render_threshold_db, -6.0, -40.0, 20.0, "dB", "Contributions below noise floor + this are skipped") \
  X(double, stc_curve_db_5m, 0.0, -40.0, 40.0, "dB", "Range gain curve (STC) correction at 5 m, on noise and returns (curves: linear in log range between 5, 16, 35, 71 m, flat outside)") \
  X(double, stc_curve_db_16m, 0.0, -40.0, 40.0, "dB", "Range gain curve (STC) correction at 16 m, on noise and returns") \
  X(double, stc_curve_db_35m, 0.0, -40.0, 40.0, "dB", "Range gain curve (STC) correction at 35 m, on noise and returns") \
  X(double, stc_curve_db_71m, 0.0, -40.0, 40.0, "dB", "Range gain curve (STC) correction at 71 m, on noise and returns") \
  X(double, return_gain_db_5m, 0.0, -40.0, 40.0, "dB", "Gain of returns, not noise, at 5 m (elevation beam pattern on the ground and targets)") \
  X(double, return_gain_db_16m, 0.0, -40.0, 40.0, "dB", "Gain of returns, not noise, at 16 m") \
  X(double, return_gain_db_35m, 0.0, -40.0, 40.0, "dB", "Gain of returns, not noise, at 35 m") \
  X(double, return_gain_db_71m, 0.0, -40.0, 40.0, "dB", "Gain of returns, not noise, at 71 m") \
  X(double, return_far_slope_db_per_decade, 0.0, -80.0, 20.0, "dB/dec", "Gain of returns, not noise, beyond the last curve node (71 m) per decade of range (low-grazing ground clutter and the elevation pattern fall off there; 0 = flat, as the curves are outside their nodes)") \
  X(double, clutter_density_x_5m, 1.0, 0.0, 20.0, "", "Textured clutter density at 5 m relative to clutter_density (grazing-angle visibility)") \
  X(double, clutter_density_x_16m, 1.0, 0.0, 20.0, "", "Textured clutter density at 16 m relative to clutter_density") \
  X(double, clutter_density_x_35m, 1.0, 0.0, 20.0, "", "Textured clutter density at 35 m relative to clutter_density") \
  X(double, clutter_density_x_71m, 1.0, 0.0, 20.0, "", "Textured clutter density at 71 m relative to clutter_density")
// clang-format on

namespace spinradar::sim {

struct SensorConfig {
  SPINRADAR_DECLARE_PARAMS(SPINRADAR_SENSOR_PARAMS)
  /// Appearance physics of this sensor's recordings (file key "physics": physics keys
  /// kSensorPhysicsKeys, defined and range-checked in physics.cpp), applied by the simulator
  /// unless its physics configuration sets the key. Empty (the default): no effect, and the
  /// sensor file has no "physics" entry.
  std::map<std::string, double> physics;
  /// The built-in scene this file was calibrated in (file key "reference_scene";
  /// reference_scene.hpp): simulate, serve, realism and diagnose's appearance stage render the
  /// sensor there when no scene is named. Written by diagnose into sensor_fitted.json from
  /// --appearance-scene. Empty (the default): no key in the file, and those commands keep
  /// their own default scene.
  std::string reference_scene;
  void validate() const;  ///< throws std::invalid_argument naming the parameter (or the scene)
  /// {"name": value, ...} for every parameter; fromJson takes a subset (unknown keys rejected).
  nlohmann::json toJson() const;
  static SensorConfig fromJson(const nlohmann::json& j);
  static SensorConfig load(const std::string& path);  ///< errors name file + line + reason
  /// A sensor file by path, or by the name of a calibrated sensor (config/sensors/<name>.json,
  /// also searched in $SPINRADAR_SENSORS_DIR): "oxford", "mulran", "boreas_rt", "radiate".
  /// An unknown name throws, listing the names available.
  static SensorConfig loadNamed(const std::string& name_or_path);
  /// Names of the calibrated sensor files found.
  static std::vector<std::string> namedSensors();
  void save(const std::string& path) const;
  /// Range curves (stc_curve_db_*, return_gain_db_*, clutter_density_x_*): node ranges, and the
  /// interpolation weights of the four nodes at range r (linear in log range, flat outside).
  static constexpr double kCurveNodes[4] = {5.0, 16.0, 35.0, 71.0};
  static void curveWeights(double r, double w[4]);
  double stcCurveDb(double r) const;     ///< receiver gain correction (noise and returns), dB
  double returnGainDb(double r) const;   ///< gain of returns only, dB
  double clutterDensityX(double r) const;  ///< relative textured clutter density
  double clutterDensityXMax() const;     ///< largest node of clutter_density_x_*
  bool hasRangeCurves() const;           ///< any curve node away from its neutral value
  /// Maximum rendered range (m): bins * range_resolution.
  double maxRange() const { return bins * range_resolution; }
};

}  // namespace spinradar::sim
