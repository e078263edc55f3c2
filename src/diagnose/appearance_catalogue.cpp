// Appearance stage: the catalogue of smooth sensor parameters the fit moves (appearance_detail.hpp),
// the realism figures as one vector with their standard errors, and the reference rendering of a
// sensor model on the built-in scene that every fit step compares against the recording, and the
// coarse level pre-alignment that starts the fit.
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include <Eigen/Dense>

#include "appearance_detail.hpp"
#include "spinradar/sim/scenes.hpp"
#include "spinradar/sim/simulator.hpp"

namespace spinradar::diagnose {

using sim::SensorConfig;
namespace detail {

const std::vector<AppearanceParam>& appearanceParams() {
  static const std::vector<int> floor = {0, 1, 2, 3}, bright = {8, 9, 10, 11},
                                texture = {4, 5, 6, 7, 12, 13, 14, 15};
  static const std::vector<AppearanceParam> p = {
      {"noise floor", "noise_floor_db", "dB", &SensorConfig::noise_floor_db, 2.0, 0, 100,
       Kind::Level, 0, floor},
      {"noise floor range slope", "noise_range_slope_db_per_decade", "dB/dec",
       &SensorConfig::noise_range_slope_db_per_decade, 4.0, -40, 40, Kind::Slope, 0, floor},
      {"near-range STC", "stc_range", "m", &SensorConfig::stc_range, 2.0, 0, 100, Kind::Range,
       0, floor},
      {"receiver gain", "radar_constant_db", "dB", &SensorConfig::radar_constant_db, 3.0, 0, 300,
       Kind::Level, 1, bright},
      {"range gain (STC) slope", "range_gain_db_per_decade", "dB/dec",
       &SensorConfig::range_gain_db_per_decade, 4.0, 0, 60, Kind::Slope, 1, bright},
      {"beam width", "beam_width_deg", "deg", &SensorConfig::beam_width_deg, 0.4, 0.3, 20,
       Kind::Width, 2, {16}},
      {"range point spread", "range_psf_sigma_bins", "bins", &SensorConfig::range_psf_sigma_bins,
       0.8, 0.3, 20, Kind::Width, 3, {17}},
      {"clutter density", "clutter_density", "1/m^2", &SensorConfig::clutter_density, 0.05, 0, 4,
       Kind::Density, 4, texture},
      {"noise texture", "noise_texture_db", "dB", &SensorConfig::noise_texture_db, 1.5, 0, 15,
       Kind::Level, 4, texture},
  };
  return p;
}

Eigen::VectorXd figureVector(const AppearanceFigures& f) {
  Eigen::VectorXd v(kFigures);
  for (int k = 0; k < kBands; ++k) {
    v[k] = f.floor[k];
    v[4 + k] = f.mean[k];
    v[8 + k] = f.bright[k];
    v[12 + k] = f.cfar[k];
  }
  v[16] = std::isfinite(f.beam_rows) ? f.beam_rows : 0;
  v[17] = std::isfinite(f.psf_bins) ? f.psf_bins : 0;
  return v;
}

Eigen::VectorXd figureSe(const AppearanceFigures& f) {
  Eigen::VectorXd v(kFigures);
  for (int k = 0; k < kBands; ++k) {
    v[k] = std::max(f.floor_se[k], 0.05);
    v[4 + k] = std::max(f.mean_se[k], 0.05);
    v[8 + k] = std::max(f.bright_se[k], 0.1);
    v[12 + k] = std::max(f.cfar_se[k], 0.01);
  }
  v[16] = std::isfinite(f.beam_rows_se) ? std::max(f.beam_rows_se, 0.02) : 1e3;
  v[17] = std::isfinite(f.psf_bins_se) ? std::max(f.psf_bins_se, 0.05) : 1e3;
  return v;
}

Eigen::VectorXd differenceSe(const AppearanceFigures& a, const AppearanceFigures& b) {
  const Eigen::VectorXd sa = figureSe(a), sb = figureSe(b);
  Eigen::VectorXd se = (sa.array().square() + sb.array().square()).sqrt();
  if (a.replicates.size() != b.replicates.size() || a.replicates.size() < 4) return se;
  // Paired: the scatter of the replicate differences (same route, same scan positions).
  const Eigen::VectorXd floor = figureSe(AppearanceFigures{}) * 0.5;
  for (int i = 0; i < kFigures; ++i) {
    std::vector<double> d;
    for (size_t r = 0; r < a.replicates.size(); ++r) {
      const double x = a.replicates[r][i] - b.replicates[r][i];
      if (std::isfinite(x)) d.push_back(x);
    }
    if (d.size() < 4) continue;
    double m = 0, ss = 0;
    for (double x : d) m += x;
    m /= d.size();
    for (double x : d) ss += (x - m) * (x - m);
    const double paired = std::sqrt(ss / (d.size() - 1) / d.size());
    se[i] = std::min(se[i], std::max(paired, floor[i]));
  }
  return se;
}


// Level pre-alignment before the Gauss-Newton fit, which moves a level by at most 3 steps per
// iteration (6 dB noise, 9 dB gain): a recording 25-40 dB brighter than the base model
// (Boreas-RT's native level) ended on that trust region after 4 iterations. Counts are about
// 1 dB each, so the mean gap of the floor figures is the noise level to add and that of the
// bright figures the receiver gain, over the bands the fit uses (the 2.5-10 m band is
// scene-dependent). Only gaps beyond 3 Newton steps (18 dB noise, 27 dB gain) are pre-aligned,
// in up to 3 rounds, each re-simulated; the fit does the rest.
void alignLevels(const AppearanceFigures& real, SensorConfig& cur,
                 const std::function<AppearanceFigures(const SensorConfig&)>& figuresOf,
                 std::vector<std::string>& notes, bool hold_gain) {
  auto gap = [](const std::array<double, kBands>& r, const std::array<double, kBands>& s) {
    double g = 0;
    int n = 0;
    for (int k = 0; k < kBands; ++k)
      if (!isSceneDependent(k, "mean")) g += r[k] - s[k], ++n;
    return n ? g / n : 0.0;
  };
  const SensorConfig start = cur;
  for (int round = 0; round < 3; ++round) {
    const AppearanceFigures f = figuresOf(cur);
    const double noise = gap(real.floor, f.floor), gain = gap(real.bright, f.bright);
    const bool move_noise = std::abs(noise) > 18 || (round > 0 && std::abs(noise) > 6);
    const bool move_gain = !hold_gain && (std::abs(gain) > 27 || (round > 0 && std::abs(gain) > 9));
    if (!move_noise && !move_gain) break;
    if (move_noise) cur.noise_floor_db = std::clamp(cur.noise_floor_db + noise, 0.0, 100.0);
    if (move_gain) cur.radar_constant_db = std::clamp(cur.radar_constant_db + gain, 0.0, 300.0);
  }
  if (cur.noise_floor_db != start.noise_floor_db || cur.radar_constant_db != start.radar_constant_db) {
    std::ostringstream os;
    os << std::setprecision(3) << "Level pre-alignment (gaps beyond 3 Newton steps): noise floor "
       << start.noise_floor_db << " -> " << cur.noise_floor_db << " dB, receiver gain "
       << start.radar_constant_db << " -> " << cur.radar_constant_db
       << " dB; the catalogue fit starts from there.";
    notes.push_back(os.str());
  }
}

}  // namespace detail

const std::vector<std::string>& clutterFieldKeys() {
  static const std::vector<std::string> k = {
      "clutter_density",        "clutter_density_x_5m",  "clutter_density_x_16m",
      "clutter_density_x_35m",  "clutter_density_x_71m", "clutter_rcs_db",
      "clutter_rcs_sd_db"};
  return k;
}

bool isHeldParameter(const AppearanceOptions& opt, const std::string& key) {
  const auto& k = clutterFieldKeys();
  return opt.hold_clutter && std::find(k.begin(), k.end(), key) != k.end();
}

SensorConfig withHeldParameters(const SensorConfig& s, const SensorConfig& start,
                                const AppearanceOptions& opt) {
  if (!opt.hold_clutter) return s;
  nlohmann::json j = s.toJson();
  const nlohmann::json from = start.toJson();
  for (const auto& key : clutterFieldKeys()) j[key] = from.at(key);
  return SensorConfig::fromJson(j);
}

std::vector<PolarScan> renderReference(const SensorConfig& sensor, const sim::PhysicsConfig& physics,
                                       const AppearanceOptions& opt, uint64_t seed) {
  if (opt.scene == "recording") return renderRecordingScene(sensor, physics, opt, seed);
  sim::Scene sc = sim::builtinScene(opt.scene);
  sim::Simulator s(std::move(sc.world), std::move(sc.trajectory), sensor, physics, seed);
  std::vector<PolarScan> out;
  const int total = s.scanCount();
  for (int i = 0; i < opt.scans; ++i) out.push_back(s.renderScan(int((i + 0.5) * total / opt.scans)));
  return out;
}

}  // namespace spinradar::diagnose
