// Combined reference of the appearance stage (issue 20, AppearanceOptions::scene = "combined").
// The recording's own scene (appearance_scene.cpp) takes up the returns' gain chain and the beam:
// its scatterers are the recorded returns with the model's gain chain divided out, and a wider
// beam gives wider returns, placed as more scatterers. So with that scene alone a fitted sensor
// file has no calibrated gain chain (Oxford's receiver gain drifted 112 -> 89.5 dB) and the beam
// is not identifiable. The city scene pins them (its targets have known strengths and shapes)
// but its content is not the recording's street, so the figures that measure the scene
// (Cen2018 per row, the far floor) pull the rest of the sensor off. Here the two are split:
//   1. the gain chain and beam from a fit with the city scene (or a given sensor file, such as
//      config/sensors/<sample>.json, which are such fits): receiver gain, its range slope, the
//      returns' level at each range-curve node, the beam width;
//   2. everything else (noise floor, its slope and range curve, texture, code set, range spread,
//      clutter, near STC, leakage, saturation, ghosts) fitted against the recording's own scene
//      with those held (AppearanceOptions::hold_gain_chain).
#include <algorithm>
#include <chrono>
#include <iomanip>
#include <sstream>

#include "appearance_detail.hpp"
#include "spinradar/diagnose/appearance.hpp"

namespace spinradar::diagnose {

using sim::SensorConfig;

namespace {

// The returns' gain chain and the beam of `from` into `to`. The range curves: the returns' level
// at each node (stc_curve + return_gain) is from's; the noise side (stc_curve) stays to's.
void copyGainChain(const SensorConfig& from, SensorConfig& to) {
  to.radar_constant_db = from.radar_constant_db;
  to.range_gain_db_per_decade = from.range_gain_db_per_decade;
  to.beam_width_deg = from.beam_width_deg;
  to.return_gain_db_5m = from.stc_curve_db_5m + from.return_gain_db_5m - to.stc_curve_db_5m;
  to.return_gain_db_16m = from.stc_curve_db_16m + from.return_gain_db_16m - to.stc_curve_db_16m;
  to.return_gain_db_35m = from.stc_curve_db_35m + from.return_gain_db_35m - to.stc_curve_db_35m;
  to.return_gain_db_71m = from.stc_curve_db_71m + from.return_gain_db_71m - to.stc_curve_db_71m;
}

std::string pct(double x) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(1) << 100 * x;
  return os.str();
}

}  // namespace

AppearanceReport combinedAppearance(const std::vector<PolarScan>& recording,
                                    const SensorConfig& sensor, const sim::PhysicsConfig& physics,
                                    const AppearanceOptions& opt) {
  if (opt.scene != "combined")
    throw std::invalid_argument("appearance: combinedAppearance needs scene 'combined'");
  const auto t0 = std::chrono::steady_clock::now();
  // Stage 1: the gain chain and beam, from the city scene's fit unless a sensor file gives them.
  AppearanceReport city;
  const bool ran_city = !opt.gain_chain;
  SensorConfig source;
  if (ran_city) {
    AppearanceOptions o = opt;
    o.scene = "city";
    o.hold_gain_chain = false;
    city = diagnoseAppearance(recording, sensor, physics, o);
    source = city.fitted;
  } else {
    source = *opt.gain_chain;
  }
  SensorConfig start = sensor;
  copyGainChain(source, start);
  start.validate();

  // Stage 2: the rest against the recording's own scene, the gain chain held.
  AppearanceOptions o = withReferenceScene(opt, recording);  // scene "recording", held
  AppearanceReport rep = diagnoseAppearance(recording, start, physics, o);
  rep.base = sensor;
  // Findings of the held parameters: the city fit's, where it was run; given ones are reported,
  // never named (they are the file's, not this recording's finding).
  for (const auto& key : {"radar_constant_db", "range_gain_db_per_decade", "beam_width_deg"}) {
    const auto it = std::find_if(city.findings.begin(), city.findings.end(),
                                 [&](const AppearanceFinding& f) { return f.parameter == key; });
    if (ran_city && it != city.findings.end()) {
      rep.findings.push_back(*it);
      rep.findings.back().effect += " (city scene's fit, held)";
      continue;
    }
    AppearanceFinding f;
    f.parameter = key;
    f.effect = std::string(key) + " (given, held)";
    const double SensorConfig::*field = std::string(key) == "radar_constant_db"
                                            ? &SensorConfig::radar_constant_db
                                        : std::string(key) == "beam_width_deg"
                                            ? &SensorConfig::beam_width_deg
                                            : &SensorConfig::range_gain_db_per_decade;
    f.unit = std::string(key) == "beam_width_deg" ? "deg" : "dB";
    f.base = sensor.*field;
    f.value = start.*field;
    f.verdict = "held (given)";
    rep.findings.push_back(f);
  }
  std::stable_sort(rep.findings.begin(), rep.findings.end(),
                   [](const AppearanceFinding& a, const AppearanceFinding& b) {
                     if (a.named != b.named) return a.named;
                     return a.z > b.z;
                   });
  std::ostringstream os;
  os << std::setprecision(4) << "Combined reference (docs/diagnose_scene.md): receiver gain "
     << start.radar_constant_db << " dB, its range slope " << start.range_gain_db_per_decade
     << " dB/dec, beam " << start.beam_width_deg << " deg and the returns' level per range node ("
     << start.stc_curve_db_5m + start.return_gain_db_5m << ", "
     << start.stc_curve_db_16m + start.return_gain_db_16m << ", "
     << start.stc_curve_db_35m + start.return_gain_db_35m << ", "
     << start.stc_curve_db_71m + start.return_gain_db_71m << " dB at 5/16/35/71 m) "
     << (ran_city ? "from the city scene's fit" : "from the given sensor")
     << ", held; everything else fitted against the recording's own scene.";
  if (ran_city && opt.realism)
    os << " The city scene's fit alone: worst gap " << pct(city.worst_gap_after)
       << " % (fit part), " << pct(city.worst_holdout_after) << " % (held out).";
  rep.notes.insert(rep.notes.begin(), os.str());
  rep.runtime_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return rep;
}

}  // namespace spinradar::diagnose
