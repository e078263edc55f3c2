#pragma once
// Pose CSV files: the odometry output (`t,x,y,yaw,vx,vy,wz`) and trajectories (`t,x,y,yaw`).
// t in seconds (scan clock), x/y in metres, yaw in radians CCW (REP 103); vx, vy, wz are the
// sensor body velocity in the sensor frame (m/s, m/s, rad/s).
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace spinradar {

struct PoseRecord {
  double t = 0.0;
  double x = 0.0, y = 0.0, yaw = 0.0;
  double vx = 0.0, vy = 0.0, wz = 0.0;
};

/// One CSV line split at commas, each cell trimmed of blanks; a trailing comma gives a last,
/// empty cell (so column counts stay honest). No quoting: the project's files need none.
std::vector<std::string> splitCsvLine(const std::string& line);

/// Pose as an SE(2) matrix T_world_sensor.
Eigen::Matrix3d poseMatrix(double x, double y, double yaw);
Eigen::Matrix3d poseMatrix(const PoseRecord& p);

struct PoseFile {
  std::vector<PoseRecord> poses;
  bool has_velocity = false;  ///< the file had vx, vy, wz columns
};

/// Reads a CSV whose header names at least t, x, y, yaw (any order, extra columns ignored;
/// vx, vy, wz read when present). Blank lines and lines starting with '#' are skipped. Throws
/// std::runtime_error "<file>:<line>: <reason>" on a missing column, a non-number, a non-finite
/// value, a time that is not strictly increasing, or no data row after the header.
PoseFile readPoseCsv(const std::string& path);
/// Same, from a stream; `name` is used in error messages.
PoseFile readPoseCsv(std::istream& in, const std::string& name);

/// Writes `t,x,y,yaw,vx,vy,wz` (with_velocity) or `t,x,y,yaw`, full precision, through a
/// temporary file renamed when complete. Throws std::runtime_error naming the file when it
/// cannot be written.
void writePoseCsv(const std::string& path, const std::vector<PoseRecord>& poses,
                  bool with_velocity = true);
void writePoseCsv(std::ostream& out, const std::vector<PoseRecord>& poses,
                  bool with_velocity = true);

/// One line of the TUM trajectory format that evo and the TUM tools read:
/// "t x y z qx qy qz qw" (z = 0, the yaw as a quaternion about z), full precision.
void writeTumRow(std::ostream& out, const PoseRecord& p);

/// Incremental writer. Rows go to a temporary file next to `path` that close() renames onto it;
/// destroyed without close() (a failed run) it leaves no partial file and `path` untouched.
/// `live` (a node that runs until killed): rows go straight to `path`, flushed one by one.
class PoseCsvWriter {
 public:
  PoseCsvWriter(const std::string& path, bool with_velocity = true, bool live = false);
  ~PoseCsvWriter();
  void write(const PoseRecord& p);
  void close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace spinradar
