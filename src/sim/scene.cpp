// World JSON and trajectory CSV: parsing, validation, interpolation, motion profiles.
#include "spinradar/sim/scene.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "file_errors.hpp"
#include "render_geometry.hpp"
#include "spinradar/io/poses_io.hpp"

namespace spinradar::sim {

using detail::JsonPathError;
using detail::JsonStep;
using detail::wrapPi;

namespace {

double number(const nlohmann::json& obj, const std::vector<JsonStep>& at, const char* key,
              bool required, double def, double lo = -1e9, double hi = 1e9) {
  auto path = at;
  path.push_back({key, -1});
  auto it = obj.find(key);
  if (it == obj.end()) {
    if (required) throw JsonPathError(at, std::string("missing key '") + key + "'");
    return def;
  }
  if (!it->is_number()) throw JsonPathError(path, "must be a number");
  double v = it->get<double>();
  if (!std::isfinite(v) || v < lo || v > hi) {
    std::ostringstream ss;
    ss << "value " << v << " outside [" << lo << ", " << hi << "]";
    throw JsonPathError(path, ss.str());
  }
  return v;
}

const nlohmann::json* arrayAt(const nlohmann::json& j, const char* key) {
  auto it = j.find(key);
  if (it == j.end()) return nullptr;
  if (!it->is_array()) throw JsonPathError({{key, -1}}, "must be an array");
  return &*it;
}

}  // namespace

World World::fromJson(const nlohmann::json& j) {
  if (!j.is_object()) throw JsonPathError({}, "world must be a JSON object");
  World w;
  if (const auto* ts = arrayAt(j, "targets")) {
    for (size_t i = 0; i < ts->size(); ++i) {
      std::vector<JsonStep> at{{"targets", -1}, {"", int(i)}};
      const auto& o = (*ts)[i];
      if (!o.is_object()) throw JsonPathError(at, "must be an object");
      Target t;
      t.x = number(o, at, "x", true, 0, -1e7, 1e7);
      t.y = number(o, at, "y", true, 0, -1e7, 1e7);
      t.rcs = number(o, at, "rcs", true, 0, -100, 100);
      t.vx = number(o, at, "vx", false, 0, -200, 200);
      t.vy = number(o, at, "vy", false, 0, -200, 200);
      if (auto e = o.find("elevated"); e != o.end()) {
        auto path = at;
        path.push_back({"elevated", -1});
        if (!e->is_boolean()) throw JsonPathError(path, "must be true or false");
        t.elevated = e->get<bool>();
      }
      if (o.contains("height")) t.height = number(o, at, "height", true, 0, 0, 1000);
      w.targets.push_back(t);
    }
  }
  if (const auto* ws = arrayAt(j, "walls")) {
    for (size_t i = 0; i < ws->size(); ++i) {
      std::vector<JsonStep> at{{"walls", -1}, {"", int(i)}};
      const auto& o = (*ws)[i];
      if (!o.is_object()) throw JsonPathError(at, "must be an object");
      Wall wl;
      wl.x1 = number(o, at, "x1", true, 0, -1e7, 1e7);
      wl.y1 = number(o, at, "y1", true, 0, -1e7, 1e7);
      wl.x2 = number(o, at, "x2", true, 0, -1e7, 1e7);
      wl.y2 = number(o, at, "y2", true, 0, -1e7, 1e7);
      wl.rcs_per_m = number(o, at, "rcs_per_m", true, 0, -100, 100);
      if (o.contains("height")) wl.height = number(o, at, "height", true, 0, 0, 1000);
      if (std::hypot(wl.x2 - wl.x1, wl.y2 - wl.y1) < 1e-6)
        throw JsonPathError(at, "wall has zero length");
      w.walls.push_back(wl);
    }
  }
  return w;
}

nlohmann::json World::toJson() const {
  nlohmann::json j;
  j["targets"] = nlohmann::json::array();
  for (const auto& t : targets) {
    nlohmann::json o{{"x", t.x}, {"y", t.y}, {"rcs", t.rcs}};
    if (t.vx != 0 || t.vy != 0) {
      o["vx"] = t.vx;
      o["vy"] = t.vy;
    }
    if (t.elevated) o["elevated"] = true;  // written only when set: older worlds keep their bytes
    if (t.height) o["height"] = *t.height;
    j["targets"].push_back(o);
  }
  j["walls"] = nlohmann::json::array();
  for (const auto& w : walls) {
    nlohmann::json o{{"x1", w.x1}, {"y1", w.y1}, {"x2", w.x2}, {"y2", w.y2}, {"rcs_per_m", w.rcs_per_m}};
    if (w.height) o["height"] = *w.height;
    j["walls"].push_back(o);
  }
  return j;
}

bool World::hasHeights() const {
  for (const auto& t : targets)
    if (t.height) return true;
  for (const auto& w : walls)
    if (w.height) return true;
  return false;
}

World World::load(const std::string& path) {
  return detail::loadJsonFile<World>(path);
}

void World::save(const std::string& path) const { detail::saveJsonFile(*this, path); }

// ---------------------------------------------------------------------------------------------

Trajectory::Trajectory(std::vector<Sample> samples) : samples_(std::move(samples)) {
  if (samples_.size() < 2) throw std::runtime_error("trajectory needs at least 2 samples");
  for (size_t i = 1; i < samples_.size(); ++i)
    if (!(samples_[i].t > samples_[i - 1].t))
      throw std::runtime_error("trajectory: sample " + std::to_string(i) +
                               ": time not strictly increasing");
}

Trajectory Trajectory::fromProfile(const std::vector<Segment>& segments, const Pose2& start,
                                   double t0, double rate_hz) {
  if (segments.empty()) throw std::runtime_error("motion profile: no segments");
  if (!(rate_hz > 0)) throw std::runtime_error("motion profile: rate must be positive");
  std::vector<Sample> out;
  Pose2 p = start;
  double t = t0;
  out.push_back({t, p});
  const double dt_max = 1.0 / rate_hz;
  for (size_t k = 0; k < segments.size(); ++k) {
    const Segment& s = segments[k];
    if (!(s.duration > 0) || !std::isfinite(s.speed) || !std::isfinite(s.yaw_rate))
      throw std::runtime_error("motion profile: segment " + std::to_string(k) + ": bad values");
    int n = std::max(1, int(std::ceil(s.duration / dt_max - 1e-9)));
    double dt = s.duration / n;
    for (int i = 0; i < n; ++i) {
      // Exact integration of constant speed and yaw rate (a circular arc).
      double w = s.yaw_rate, v = s.speed;
      if (std::abs(w) > 1e-9) {
        p.x += v / w * (std::sin(p.yaw + w * dt) - std::sin(p.yaw));
        p.y += v / w * (-std::cos(p.yaw + w * dt) + std::cos(p.yaw));
      } else {
        p.x += v * dt * std::cos(p.yaw);
        p.y += v * dt * std::sin(p.yaw);
      }
      p.yaw = wrapPi(p.yaw + w * dt);
      t = t0 + (out.back().t - t0) + dt;
      out.push_back({t, p});
    }
  }
  return Trajectory(std::move(out));
}

Trajectory Trajectory::loadCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::string line;
  int lineno = 0;
  int col[4] = {-1, -1, -1, -1};
  size_t ncols = 0;
  bool header = false;
  std::vector<Sample> samples;
  const char* names[4] = {"t", "x", "y", "yaw"};
  while (std::getline(in, line)) {
    ++lineno;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    auto f = splitCsvLine(line);
    if (!header) {
      for (size_t c = 0; c < f.size(); ++c)
        for (int k = 0; k < 4; ++k)
          if (f[c] == names[k]) col[k] = int(c);
      for (int k = 0; k < 4; ++k)
        if (col[k] < 0)
          detail::fail(path, lineno,
                       std::string("header must name columns t,x,y,yaw (missing '") + names[k] +
                           "')");
      ncols = f.size();
      header = true;
      continue;
    }
    if (f.size() != ncols)
      detail::fail(path, lineno,
                   "expected " + std::to_string(ncols) + " fields, got " + std::to_string(f.size()));
    double v[4];
    for (int k = 0; k < 4; ++k) {
      const std::string& s = f[col[k]];
      char* end = nullptr;
      v[k] = std::strtod(s.c_str(), &end);
      if (s.empty() || end != s.c_str() + s.size() || !std::isfinite(v[k]))
        detail::fail(path, lineno, std::string("column '") + names[k] + "': not a number: '" + s + "'");
    }
    if (!samples.empty() && !(v[0] > samples.back().t))
      detail::fail(path, lineno, "time not strictly increasing");
    samples.push_back({v[0], {v[1], v[2], v[3]}});
  }
  if (!header) detail::fail(path, 0, "empty file (expected header t,x,y,yaw)");
  if (samples.size() < 2) detail::fail(path, lineno, "needs at least 2 samples");
  return Trajectory(std::move(samples));
}

void Trajectory::saveCsv(const std::string& path) const {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write");
  out << "t,x,y,yaw\n" << std::setprecision(17);
  for (const auto& s : samples_)
    out << s.t << ',' << s.pose.x << ',' << s.pose.y << ',' << s.pose.yaw << '\n';
  if (!out) throw std::runtime_error(path + ": write failed");
}

Pose2 Trajectory::at(double t) const {
  if (samples_.empty()) return {};
  if (t <= samples_.front().t) return samples_.front().pose;
  if (t >= samples_.back().t) return samples_.back().pose;
  auto it = std::upper_bound(samples_.begin(), samples_.end(), t,
                             [](double v, const Sample& s) { return v < s.t; });
  const Sample& b = *it;
  const Sample& a = *(it - 1);
  double u = (t - a.t) / (b.t - a.t);
  Pose2 p;
  p.x = a.pose.x + u * (b.pose.x - a.pose.x);
  p.y = a.pose.y + u * (b.pose.y - a.pose.y);
  p.yaw = wrapPi(a.pose.yaw + u * wrapPi(b.pose.yaw - a.pose.yaw));
  return p;
}

Eigen::Vector3d Trajectory::bodyVelocity(double t) const {
  if (samples_.size() < 2 || t < samples_.front().t || t > samples_.back().t)
    return Eigen::Vector3d::Zero();
  auto it = std::upper_bound(samples_.begin(), samples_.end(), t,
                             [](double v, const Sample& s) { return v < s.t; });
  if (it == samples_.end()) --it;
  if (it == samples_.begin()) ++it;
  const Sample& b = *it;
  const Sample& a = *(it - 1);
  double dt = b.t - a.t;
  double vx = (b.pose.x - a.pose.x) / dt, vy = (b.pose.y - a.pose.y) / dt;
  double wz = wrapPi(b.pose.yaw - a.pose.yaw) / dt;
  double yaw = at(t).yaw;
  double c = std::cos(yaw), s = std::sin(yaw);
  return {c * vx + s * vy, -s * vx + c * vy, wz};
}

double Trajectory::startTime() const { return samples_.empty() ? 0.0 : samples_.front().t; }
double Trajectory::endTime() const { return samples_.empty() ? 0.0 : samples_.back().t; }

}  // namespace spinradar::sim
