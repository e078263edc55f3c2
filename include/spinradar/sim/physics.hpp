#pragma once
// The physics configuration: JSON object from effect name to value, absent meaning off.
// {"motion_distortion": true, "doppler": 0.049, "timestamp_offset": 0.03,
//  "azimuth_offset": 0.0105, "range_offset": -0.3, "moving_objects": true}
// Extra effects of this simulator (keys in `extra`):
//   "stamp_bursts": true | {"size": 16, "spacing": 135e-6, "delay": 0}  per-azimuth stamps
//       arrive in packets (Oxford/MulRan): row i of a packet is stamped at the acquisition time
//       of the packet's last row + delay + i * spacing
//   "rotation_jitter": s   relative std of the rotation period per scan; true firing times
//       stretch, stamps stay nominal
//   "encoder_wobble": rad  true angle -= A sin(reported angle)
//   "multipath": dB (or true = -15)  double-bounce ghosts of point targets mirrored in walls
//   "attenuation": dB/km   two-way path loss (rain, fog)
//   "chirp_alternate": true  Boreas-RT style: Doppler sign flips on alternate azimuths
//   "scan_pose_time": "mid" | "start"  pose used when motion_distortion is off
//   "glint": m   per-axis std of a per-scan isotropic random shift of every scatterer's
//       scattering centre (where on an extended object the return comes from changes with the
//       aspect; real Oxford ~0.1 m, `spinradar spread`); 0 = off, the default
//   "glint_across": m  per-scan std of the scattering-centre shift across the line of sight
//       (seen from the scan's middle pose); "glint_along": m  the same along it. The real
//       spread is anisotropic (RADIATE 0.25 m across, 0.12 along; docs/diagnose_glint.md)
//   "azimuth_jitter": deg  std of a per-row error of the true beam angle (independent per
//       azimuth row and scan): the across-beam spread it adds grows with range
//   Each 0 = off, the default (output byte-identical). These four are also the keys a calibrated
//   sensor file may carry in its "physics" object (SensorConfig::physics).
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace spinradar::sim {

struct PhysicsConfig {
  bool motion_distortion = false;  ///< each azimuth from the pose at its own time
  double doppler = 0.0;            ///< beta in s (0 = off): apparent range r - beta * u
  double timestamp_offset = 0.0;   ///< s, recorded stamp minus true acquisition time
  double azimuth_offset = 0.0;     ///< rad, reported angle minus true angle
  double range_offset = 0.0;       ///< m, reported range minus true range
  bool moving_objects = false;     ///< targets move with their vx, vy
  nlohmann::json extra = nlohmann::json::object();  ///< further effects (own keys)

  static PhysicsConfig fromJson(const nlohmann::json& j);  ///< unknown keys kept in extra
  nlohmann::json toJson() const;                           ///< only effects that are on
  static PhysicsConfig load(const std::string& path);
  void save(const std::string& path) const;
  /// Names of the effects that are on, in catalogue order.
  std::vector<std::string> activeEffects() const;
  /// This configuration with a sensor's appearance physics (SensorConfig::physics) added for
  /// every key it does not set itself (an explicit value, 0 too, wins).
  PhysicsConfig withSensorPhysics(const std::map<std::string, double>& sensor_physics) const;
};

/// Physics keys a sensor file may carry ("physics": {...}): the appearance effects of a sensor's
/// recordings that `spinradar diagnose` fits (glint, glint_across, glint_along, azimuth_jitter).
extern const std::vector<std::string> kSensorPhysicsKeys;

/// The "physics" object of a sensor file, range-checked as physics keys; an unknown key or a
/// bad value throws naming "physics/<key>".
std::map<std::string, double> sensorPhysicsFromJson(const nlohmann::json& j);

}  // namespace spinradar::sim
