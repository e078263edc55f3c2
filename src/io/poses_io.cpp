#include "spinradar/io/poses_io.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "spinradar/core/safe_output.hpp"

namespace spinradar {

Eigen::Matrix3d poseMatrix(double x, double y, double yaw) {
  Eigen::Matrix3d T = Eigen::Matrix3d::Identity();
  const double c = std::cos(yaw), s = std::sin(yaw);
  T(0, 0) = c;
  T(0, 1) = -s;
  T(1, 0) = s;
  T(1, 1) = c;
  T(0, 2) = x;
  T(1, 2) = y;
  return T;
}

Eigen::Matrix3d poseMatrix(const PoseRecord& p) { return poseMatrix(p.x, p.y, p.yaw); }

std::vector<std::string> splitCsvLine(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  std::istringstream ss(line);
  while (std::getline(ss, cell, ',')) {
    const size_t a = cell.find_first_not_of(" \t\r\n");
    const size_t b = cell.find_last_not_of(" \t\r\n");
    out.push_back(a == std::string::npos ? std::string() : cell.substr(a, b - a + 1));
  }
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

namespace {

std::string trim(const std::string& s) {
  size_t a = s.find_first_not_of(" \t\r\n");
  if (a == std::string::npos) return {};
  size_t b = s.find_last_not_of(" \t\r\n");
  return s.substr(a, b - a + 1);
}

[[noreturn]] void fail(const std::string& name, int line, const std::string& why) {
  throw std::runtime_error(name + ":" + std::to_string(line) + ": " + why);
}

double parseNumber(const std::string& cell, const std::string& column, const std::string& name,
                   int line) {
  if (cell.empty()) fail(name, line, "empty value in column '" + column + "'");
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(cell.c_str(), &end);
  if (end == cell.c_str() || *end != '\0' || errno == ERANGE)
    fail(name, line, "column '" + column + "': '" + cell + "' is not a number");
  if (!std::isfinite(v)) fail(name, line, "column '" + column + "': value is not finite");
  return v;
}

void writeHeader(std::ostream& out, bool with_velocity) {
  out << (with_velocity ? "t,x,y,yaw,vx,vy,wz\n" : "t,x,y,yaw\n");
}

void writeRow(std::ostream& out, const PoseRecord& p, bool with_velocity) {
  // %.9f on t keeps nanoseconds of a UNIX time in seconds; %.17g round-trips the rest.
  char buf[256];
  int n = std::snprintf(buf, sizeof buf, "%.9f,%.17g,%.17g,%.17g", p.t, p.x, p.y, p.yaw);
  out.write(buf, n);
  if (with_velocity) {
    n = std::snprintf(buf, sizeof buf, ",%.17g,%.17g,%.17g", p.vx, p.vy, p.wz);
    out.write(buf, n);
  }
  out << '\n';
}

}  // namespace

PoseFile readPoseCsv(std::istream& in, const std::string& name) {
  PoseFile file;
  std::string line;
  int line_no = 0;
  int idx_t = -1, idx_x = -1, idx_y = -1, idx_yaw = -1, idx_vx = -1, idx_vy = -1, idx_wz = -1;
  size_t n_columns = 0;
  bool have_header = false;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string s = trim(line);
    if (s.empty() || s[0] == '#') continue;
    const auto cells = splitCsvLine(s);
    if (!have_header) {
      for (size_t i = 0; i < cells.size(); ++i) {
        const std::string& c = cells[i];
        const int ii = static_cast<int>(i);
        if (c == "t" || c == "time" || c == "timestamp") idx_t = ii;
        else if (c == "x") idx_x = ii;
        else if (c == "y") idx_y = ii;
        else if (c == "yaw" || c == "theta") idx_yaw = ii;
        else if (c == "vx") idx_vx = ii;
        else if (c == "vy") idx_vy = ii;
        else if (c == "wz") idx_wz = ii;
      }
      std::string missing;
      if (idx_t < 0) missing += " t";
      if (idx_x < 0) missing += " x";
      if (idx_y < 0) missing += " y";
      if (idx_yaw < 0) missing += " yaw";
      if (!missing.empty())
        fail(name, line_no, "header '" + s + "' lacks column(s):" + missing +
                                " (expected t,x,y,yaw[,vx,vy,wz])");
      file.has_velocity = idx_vx >= 0 && idx_vy >= 0 && idx_wz >= 0;
      n_columns = cells.size();
      have_header = true;
      continue;
    }
    if (cells.size() != n_columns)
      fail(name, line_no, "expected " + std::to_string(n_columns) + " columns, found " +
                              std::to_string(cells.size()));
    PoseRecord p;
    p.t = parseNumber(cells[idx_t], "t", name, line_no);
    p.x = parseNumber(cells[idx_x], "x", name, line_no);
    p.y = parseNumber(cells[idx_y], "y", name, line_no);
    p.yaw = parseNumber(cells[idx_yaw], "yaw", name, line_no);
    if (file.has_velocity) {
      p.vx = parseNumber(cells[idx_vx], "vx", name, line_no);
      p.vy = parseNumber(cells[idx_vy], "vy", name, line_no);
      p.wz = parseNumber(cells[idx_wz], "wz", name, line_no);
    }
    if (!file.poses.empty() && !(p.t > file.poses.back().t))
      fail(name, line_no, "time " + cells[idx_t] + " is not after the previous row's");
    file.poses.push_back(p);
  }
  if (!have_header) throw std::runtime_error(name + ": empty file (expected a t,x,y,yaw header)");
  if (file.poses.empty())
    throw std::runtime_error(name + ": a header but no poses (the file holds no data rows)");
  return file;
}

PoseFile readPoseCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open for reading");
  return readPoseCsv(in, path);
}

void writePoseCsv(std::ostream& out, const std::vector<PoseRecord>& poses, bool with_velocity) {
  writeHeader(out, with_velocity);
  for (const auto& p : poses) writeRow(out, p, with_velocity);
}

void writePoseCsv(const std::string& path, const std::vector<PoseRecord>& poses,
                  bool with_velocity) {
  AtomicOutputFile file(path);
  writePoseCsv(file.stream(), poses, with_velocity);
  file.commit();
}

void writeTumRow(std::ostream& out, const PoseRecord& p) {
  char line[192];
  std::snprintf(line, sizeof line, "%.9f %.17g %.17g 0 0 0 %.17g %.17g\n", p.t, p.x, p.y,
                std::sin(0.5 * p.yaw), std::cos(0.5 * p.yaw));
  out << line;
}

struct PoseCsvWriter::Impl {
  std::string path;
  std::unique_ptr<AtomicOutputFile> file;  ///< batch runs
  std::ofstream live;                      ///< live nodes
  bool with_velocity = true;
  std::ostream& out() { return file ? static_cast<std::ostream&>(file->stream()) : live; }
};

PoseCsvWriter::PoseCsvWriter(const std::string& path, bool with_velocity, bool live)
    : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  impl_->with_velocity = with_velocity;
  if (live) {
    impl_->live.open(path);
    if (!impl_->live) throw std::runtime_error(path + ": cannot open for writing");
  } else {
    impl_->file = std::make_unique<AtomicOutputFile>(path);
  }
  writeHeader(impl_->out(), with_velocity);
}

PoseCsvWriter::~PoseCsvWriter() = default;

void PoseCsvWriter::write(const PoseRecord& p) {
  std::ostream& out = impl_->out();
  writeRow(out, p, impl_->with_velocity);
  if (!impl_->file) out.flush();  // live: the file stays usable if the node is killed
  if (!out) throw std::runtime_error(impl_->path + ": write failed");
}

void PoseCsvWriter::close() {
  if (impl_->file) {
    impl_->file->commit();
  } else if (impl_->live.is_open()) {
    impl_->live.close();
    if (impl_->live.fail()) throw std::runtime_error(impl_->path + ": write failed");
  }
}

}  // namespace spinradar
