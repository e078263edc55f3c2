#include "spinradar/io/ground_truth_io.hpp"

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <Eigen/Geometry>

namespace spinradar {

namespace {

bool isBlank(const std::string& line) { return line.find_first_not_of(" \t\r") == std::string::npos; }

/// Line-by-line reader of one CSV file whose errors name the file and the line.
class CsvLines {
 public:
  explicit CsvLines(const std::string& path) : path_(path), in_(path) {
    if (!in_) throw std::runtime_error(path + ": cannot open for reading");
  }
  /// Next non-blank line split at commas; false at the end.
  bool next(std::vector<std::string>& cells) {
    std::string line;
    while (std::getline(in_, line)) {
      ++line_no_;
      if (isBlank(line)) continue;
      cells = splitCsvLine(line);
      return true;
    }
    return false;
  }
  [[noreturn]] void fail(const std::string& why) const {
    throw std::runtime_error(path_ + ":" + std::to_string(line_no_) + ": " + why);
  }
  double number(const std::string& cell, const char* what) const {
    size_t used = 0;
    double v = 0;
    try {
      v = std::stod(cell, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (cell.empty() || used != cell.size()) fail(std::string("malformed ") + what + " '" + cell + "'");
    if (!std::isfinite(v)) fail(std::string("non-finite ") + what);
    return v;
  }
  long long integer(const std::string& cell, const char* what) const {
    size_t used = 0;
    long long v = 0;
    try {
      v = std::stoll(cell, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (cell.empty() || used != cell.size()) fail(std::string("malformed ") + what + " '" + cell + "'");
    return v;
  }
  /// Column index of `name` in a header, or a failure naming what the format needs.
  static int column(const std::vector<std::string>& header, const std::string& name) {
    for (size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return static_cast<int>(i);
    return -1;
  }
  void requireIncreasing(const std::vector<PoseRecord>& out, double t) const {
    if (!out.empty() && !(t > out.back().t)) fail("time is not after the previous line's");
  }

 private:
  std::string path_;
  std::ifstream in_;
  int line_no_ = 0;
};

double yawOf(const Eigen::Matrix3d& T) { return std::atan2(T(1, 0), T(0, 0)); }

bool isOxfordHeader(const std::string& header) {
  return header.find("source_radar_timestamp") != std::string::npos ||
         header.find("destination_radar_timestamp") != std::string::npos;
}

bool isBoreasHeader(const std::string& header) { return header.rfind("GPSTime", 0) == 0; }

/// 13 bare numbers: MulRan global_pose.csv.
bool isMulranLine(const std::string& line) {
  const auto c = splitCsvLine(line);
  if (c.size() != 13) return false;
  for (const auto& cell : c) {
    if (cell.empty()) return false;
    char* end = nullptr;
    std::strtod(cell.c_str(), &end);
    if (*end != '\0') return false;
  }
  return true;
}

}  // namespace

std::vector<PoseRecord> readOxfordRadarOdometry(const std::string& path) {
  CsvLines csv(path);
  std::vector<std::string> c;
  if (!csv.next(c)) throw std::runtime_error(path + ": empty file");
  const int i_x = CsvLines::column(c, "x"), i_y = CsvLines::column(c, "y"), i_yaw = CsvLines::column(c, "yaw");
  const int i_src = CsvLines::column(c, "source_radar_timestamp");
  const int i_dst = CsvLines::column(c, "destination_radar_timestamp");
  if (i_x < 0 || i_y < 0 || i_yaw < 0 || i_src < 0 || i_dst < 0)
    csv.fail("not an Oxford radar_odometry.csv header (needs x, y, yaw, source_radar_timestamp, "
             "destination_radar_timestamp)");
  const size_t n_cols = c.size();
  std::vector<PoseRecord> out;
  Eigen::Matrix3d T = Eigen::Matrix3d::Identity();
  long long prev_source = 0;
  while (csv.next(c)) {
    if (c.size() != n_cols)
      csv.fail("expected " + std::to_string(n_cols) + " columns, found " + std::to_string(c.size()));
    const double x = csv.number(c[i_x], "x"), y = csv.number(c[i_y], "y");
    const double yaw = csv.number(c[i_yaw], "yaw");
    const long long src = csv.integer(c[i_src], "source_radar_timestamp");
    const long long dst = csv.integer(c[i_dst], "destination_radar_timestamp");
    if (src <= dst) csv.fail("source_radar_timestamp is not after destination_radar_timestamp");
    if (out.empty()) {
      PoseRecord p0;
      p0.t = dst * 1e-6;
      out.push_back(p0);
    } else if (dst != prev_source) {
      csv.fail("destination_radar_timestamp " + std::to_string(dst) +
               " is not the previous row's source_radar_timestamp " + std::to_string(prev_source) +
               " (the chain of relative poses is broken)");
    }
    // Dataset frame x forward, y right, z down -> REP 103: conjugate with diag(1, -1).
    T = T * poseMatrix(x, -y, -yaw);
    PoseRecord p;
    p.t = src * 1e-6;
    p.x = T(0, 2);
    p.y = T(1, 2);
    p.yaw = yawOf(T);
    out.push_back(p);
    prev_source = src;
  }
  if (out.empty()) throw std::runtime_error(path + ": no relative poses after the header");
  return out;
}

std::vector<PoseRecord> readBoreasPoses(const std::string& path) {
  CsvLines csv(path);
  std::vector<std::string> c;
  if (!csv.next(c)) throw std::runtime_error(path + ": empty file");
  const char* need[] = {"GPSTime", "easting", "northing", "roll", "pitch", "heading"};
  int col[6];
  for (int k = 0; k < 6; ++k)
    if ((col[k] = CsvLines::column(c, need[k])) < 0)
      csv.fail(std::string("not a Boreas pose header (no '") + need[k] +
               "' column; needs GPSTime, easting, northing, roll, pitch, heading)");
  const size_t n_cols = c.size();
  std::vector<PoseRecord> out;
  while (csv.next(c)) {
    if (c.size() != n_cols)
      csv.fail("expected " + std::to_string(n_cols) + " columns, found " + std::to_string(c.size()));
    double v[6];
    for (int k = 0; k < 6; ++k) v[k] = csv.number(c[col[k]], need[k]);
    // pyboreas' elementary rotations are passive (yaw(h) = [[c, s, 0], [-s, c, 0], [0, 0, 1]]),
    // i.e. active rotations by minus the angle.
    const Eigen::Matrix3d C = (Eigen::AngleAxisd(-v[3], Eigen::Vector3d::UnitX()) *
                               Eigen::AngleAxisd(-v[4], Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(-v[5], Eigen::Vector3d::UnitZ()))
                                  .toRotationMatrix();
    PoseRecord p;
    p.t = v[0] >= 1e11 ? v[0] * 1e-6 : v[0];
    csv.requireIncreasing(out, p.t);
    p.x = v[1];
    p.y = v[2];
    p.yaw = std::atan2(C(1, 0), C(0, 0));  // the sensor's x axis in the east-north plane
    out.push_back(p);
  }
  if (out.empty()) throw std::runtime_error(path + ": no poses after the header");
  return out;
}

std::vector<PoseRecord> readMulranGlobalPose(const std::string& path) {
  CsvLines csv(path);
  std::vector<std::string> c;
  std::vector<PoseRecord> out;
  while (csv.next(c)) {
    if (c.size() != 13)
      csv.fail("expected 13 values (time in ns, then a 3x4 pose row-major), found " + std::to_string(c.size()));
    const long long t_ns = csv.integer(c[0], "time");
    double m[12];
    for (int k = 0; k < 12; ++k) m[k] = csv.number(c[k + 1], "pose value");
    PoseRecord p;
    p.t = static_cast<double>(t_ns) * 1e-9;
    csv.requireIncreasing(out, p.t);
    p.x = m[3];
    p.y = m[7];
    p.yaw = std::atan2(m[4], m[0]);  // R(1,0), R(0,0)
    out.push_back(p);
  }
  if (out.empty()) throw std::runtime_error(path + ": no poses");
  return out;
}

std::vector<PoseRecord> readGroundTruth(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open for reading");
  std::string first;
  while (std::getline(in, first))
    if (!isBlank(first) && first[0] != '#') break;
  if (isOxfordHeader(first)) return readOxfordRadarOdometry(path);
  if (isBoreasHeader(first)) return readBoreasPoses(path);
  if (isMulranLine(first)) return readMulranGlobalPose(path);
  return readPoseCsv(path).poses;
}

std::vector<PoseRecord> withSensorPose(const std::vector<PoseRecord>& body, double x, double y,
                                       double yaw) {
  const Eigen::Matrix3d T_bs = poseMatrix(x, y, yaw);
  std::vector<PoseRecord> out = body;
  for (auto& p : out) {
    const Eigen::Matrix3d T = poseMatrix(p) * T_bs;
    p.x = T(0, 2);
    p.y = T(1, 2);
    p.yaw = yawOf(T);
  }
  return out;
}

}  // namespace spinradar
