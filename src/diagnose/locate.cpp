// Where the residuals are: grouped by scan, azimuth sector, range band, speed, turning,
// driving direction and time within the sweep.
#include <cmath>
#include <functional>
#include <map>
#include <sstream>

#include "spinradar/diagnose/diagnose.hpp"

namespace spinradar::diagnose {
namespace {

std::string rangeLabel(double lo, double hi, const char* unit) {
  std::ostringstream s;
  if (std::isinf(hi))
    s << ">= " << lo << ' ' << unit;
  else
    s << lo << "-" << hi << ' ' << unit;
  return s.str();
}

// Index of the band [edges[i], edges[i+1]) holding x (last band open).
int band(const std::vector<double>& edges, double x) {
  int i = 0;
  while (i + 1 < static_cast<int>(edges.size()) && x >= edges[i + 1]) ++i;
  return i;
}

}  // namespace

std::vector<LocateRow> locateResiduals(const std::vector<Observation>& obs, bool use_fit) {
  struct Acc {
    int n = 0;
    double sr = 0, sr2 = 0, st = 0, st2 = 0;
  };
  // Key: (group order, label order) -> accumulators; labels kept separately.
  std::map<std::pair<int, int>, Acc> acc;
  std::map<std::pair<int, int>, std::pair<std::string, std::string>> names;
  const std::vector<double> range_edges = {0, 10, 20, 40, 80, INFINITY};
  const std::vector<double> speed_edges = {0, 0.5, 2, 5, 10, INFINITY};
  auto add = [&](int g, const std::string& by, int l, const std::string& label, double er,
                 double et) {
    Acc& a = acc[{g, l}];
    ++a.n;
    a.sr += er;
    a.sr2 += er * er;
    a.st += et;
    a.st2 += et * et;
    names[{g, l}] = {by, label};
  };
  double sweep_max = 1e-9;
  for (const auto& o : obs) sweep_max = std::max(sweep_max, o.tau);
  for (const auto& o : obs) {
    if (!o.inlier) continue;
    const double er = use_fit ? o.fit_r : o.e_r;
    const double et = o.range * (use_fit ? o.fit_az : o.e_az);
    add(0, "scan", o.scan, "scan " + std::to_string(o.scan), er, et);
    const double deg = std::fmod(std::fmod(o.azimuth * 180.0 / M_PI, 360.0) + 360.0, 360.0);
    const int sec = std::min(7, static_cast<int>(deg / 45.0));
    add(1, "azimuth sector", sec,
        std::to_string(45 * sec) + "-" + std::to_string(45 * sec + 45) + " deg", er, et);
    const int rb = band(range_edges, o.range);
    add(2, "range band", rb, rangeLabel(range_edges[rb], range_edges[rb + 1], "m"), er, et);
    const double speed = std::hypot(o.vx, o.vy);
    const int sb = band(speed_edges, speed);
    add(3, "speed", sb, rangeLabel(speed_edges[sb], speed_edges[sb + 1], "m/s"), er, et);
    const int turn = o.yaw_rate > 0.05 ? 2 : (o.yaw_rate < -0.05 ? 0 : 1);
    static const char* turn_names[] = {"turning right", "straight", "turning left"};
    add(4, "turning", turn, turn_names[turn], er, et);
    const double hd = std::fmod(std::fmod(o.yaw * 180.0 / M_PI + 45.0, 360.0) + 360.0, 360.0);
    const int h = std::min(3, static_cast<int>(hd / 90.0));
    static const char* heading_names[] = {"heading +x (east)", "heading +y (north)",
                                          "heading -x (west)", "heading -y (south)"};
    add(5, "driving direction", h, heading_names[h], er, et);
    const int q = std::min(3, static_cast<int>(4.0 * o.tau / sweep_max));
    add(6, "sweep quarter", q, "sweep quarter " + std::to_string(q + 1), er, et);
  }
  std::vector<LocateRow> rows;
  for (const auto& [key, a] : acc) {
    LocateRow r;
    r.by = names[key].first;
    r.label = names[key].second;
    r.n = a.n;
    r.mean_r = a.sr / a.n;
    r.rms_r = std::sqrt(a.sr2 / a.n);
    r.mean_t = a.st / a.n;
    r.rms_t = std::sqrt(a.st2 / a.n);
    if (a.n >= 2) {
      const double vr = std::max(1e-12, r.rms_r * r.rms_r - r.mean_r * r.mean_r);
      const double vt = std::max(1e-12, r.rms_t * r.rms_t - r.mean_t * r.mean_t);
      r.z = std::max(std::fabs(r.mean_r) / std::sqrt(vr / a.n),
                     std::fabs(r.mean_t) / std::sqrt(vt / a.n));
    }
    rows.push_back(r);
  }
  return rows;
}

}  // namespace spinradar::diagnose
