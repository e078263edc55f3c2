#pragma once
// Scene (world JSON) and sensor trajectory (t,x,y,yaw CSV): the simulator's file interfaces.
// World frame REP 103: x, y in metres, yaw CCW in radians.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

namespace spinradar::sim {

struct Target {
  double x = 0, y = 0;      ///< m
  double rcs = 10;          ///< dBsm
  double vx = 0, vy = 0;    ///< m/s (moving objects; extra key "vx","vy" in the JSON)
  /// Seen over the walls (JSON key "elevated", default false): upper storeys, roof edges, tree
  /// crowns that a roof-mounted radar sees over the first row of buildings. The 2-D depth map
  /// would hide them behind the first wall hit, so they are exempt from it.
  bool elevated = false;
  /// Height of the scatterer above the ground, m (JSON key "height", optional, 0..1000). Unset =
  /// on the ground (0). Used by the visibility rule against walls that have a height (render:
  /// seen over a wall crossing the line of sight at distance d < r iff
  /// (height - mount_height) * d > (wall height - mount_height) * r); a wall without a height
  /// is infinitely tall and hides it as before. "elevated" wins over it.
  std::optional<double> height{};
};

struct Wall {
  double x1 = 0, y1 = 0, x2 = 0, y2 = 0;  ///< m
  double rcs_per_m = 0;                   ///< dBsm per metre of wall
  /// Top of the wall above the ground, m (JSON key "height", optional, 0..1000). Unset =
  /// infinitely tall: it hides everything behind it (the 2-D depth map, as before). A wall lower
  /// than the sensor (a parked car) hides only what lies below the line from the sensor over it.
  std::optional<double> height{};
};

/// {"targets": [{"x","y","rcs"[,"vx","vy","elevated","height"]}],
///  "walls": [{"x1","y1","x2","y2","rcs_per_m"[,"height"]}]} + extra keys. Optional keys are
/// written only when set, so worlds without them keep their bytes.
struct World {
  std::vector<Target> targets;
  std::vector<Wall> walls;
  static World fromJson(const nlohmann::json& j);  ///< throws std::runtime_error with the key
  nlohmann::json toJson() const;
  /// Any wall or target with a height: the renderer then applies the height rule (otherwise
  /// the plain depth map, byte for byte as before heights existed).
  bool hasHeights() const;
  static World load(const std::string& path);      ///< errors name the file
  void save(const std::string& path) const;
};

struct Pose2 {
  double x = 0, y = 0, yaw = 0;
};

/// Sensor pose over time, interpolated continuously (linear in x, y; shortest-arc in yaw).
class Trajectory {
 public:
  struct Sample {
    double t;  ///< s, same clock as scan stamps
    Pose2 pose;
  };
  /// A motion-profile segment: hold speed and yaw rate for a duration.
  struct Segment {
    double duration;  ///< s
    double speed;     ///< m/s along the sensor's x axis
    double yaw_rate;  ///< rad/s, CCW
  };

  Trajectory() = default;
  explicit Trajectory(std::vector<Sample> samples);  ///< sorted by t, at least 2
  static Trajectory fromProfile(const std::vector<Segment>& segments, const Pose2& start,
                                double t0, double rate_hz = 100.0);
  static Trajectory loadCsv(const std::string& path);  ///< header t,x,y,yaw; errors name file+line
  void saveCsv(const std::string& path) const;

  Pose2 at(double t) const;                 ///< clamped outside [start, end]
  /// Sensor body velocity [vx, vy, wz] at t (sensor frame), from the interpolated motion.
  Eigen::Vector3d bodyVelocity(double t) const;
  double startTime() const;
  double endTime() const;
  const std::vector<Sample>& samples() const { return samples_; }

 private:
  std::vector<Sample> samples_;
};

}  // namespace spinradar::sim
