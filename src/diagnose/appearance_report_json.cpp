// Appearance stage: the report as JSON (appearance.json), split from appearance_report.cpp
// (locating, realism before/after, the markdown summary and the files) to keep files small.
#include <cmath>

#include "appearance_detail.hpp"

namespace spinradar::diagnose {

nlohmann::json AppearanceReport::toJson() const {
  nlohmann::json j;
  j["findings"] = nlohmann::json::array();
  for (const auto& f : findings)
    j["findings"].push_back({{"effect", f.effect}, {"parameter", f.parameter}, {"unit", f.unit},
                             {"base", std::isfinite(f.base) ? nlohmann::json(f.base) : nlohmann::json()},
                             {"value", f.value}, {"stddev", f.stddev}, {"z", f.z},
                             {"size", f.size}, {"size_unit", f.size_unit},
                             {"gap_before", f.gap_before}, {"gap_after", f.gap_after},
                             {"named", f.named}, {"verdict", f.verdict}});
  j["locate"] = nlohmann::json::array();
  for (const auto& l : locate)
    j["locate"].push_back({{"by", l.by}, {"where", l.where},
                           {"real", std::isfinite(l.real) ? nlohmann::json(l.real) : nlohmann::json()},
                           {"sim", std::isfinite(l.sim) ? nlohmann::json(l.sim) : nlohmann::json()},
                           {"unit", l.unit}, {"note", l.note}});
  j["notes"] = notes;
  j["base_sensor"] = base.toJson();
  j["fitted_sensor"] = fitted.toJson();
  j["base_physics"] = base_physics.toJson();
  j["fitted_physics"] = fitted_physics.toJson();
  j["worst_band_gap_before"] = worst_gap_before;
  j["worst_band_gap_after"] = worst_gap_after;
  j["worst_band_gap_holdout_before"] = worst_holdout_before;
  j["worst_band_gap_holdout_after"] = worst_holdout_after;
  // Worst gaps as spreads over the render's noise seeds (the worst_band_gap_* above are means).
  auto spread = [](const sim::SeedSpread& s) {
    return nlohmann::json{{"mean", s.mean}, {"min", s.lo}, {"max", s.hi}, {"seeds", s.n}};
  };
  j["render_seeds"] = seeds_after.per_seed.size();
  j["worst_band_gap_over_seeds"] = {{"before", spread(worst_before_seeds)},
                                    {"after", spread(worst_after_seeds)}};
  if (!realism_holdout.name.empty()) {
    j["worst_band_gap_over_seeds"]["holdout_before"] = spread(worst_holdout_before_seeds);
    j["worst_band_gap_over_seeds"]["holdout_after"] = spread(worst_holdout_after_seeds);
  }
  j["fit_scans"] = fit_scans;
  j["holdout_scans"] = holdout_scans;
  j["holdout_split"] = holdout_split;
  if (!realism_holdout.name.empty()) {
    std::string fig;
    j["real_halves_difference"] = realHalvesDifference(&fig);
    j["real_halves_difference_figure"] = fig;
  }
  auto bands = [](const sim::RealismStats& s) {
    nlohmann::json b;
    b["mean"] = std::vector<double>(s.band_mean, s.band_mean + 4);
    b["q90"] = std::vector<double>(s.band_q90, s.band_q90 + 4);
    b["cacfar"] = std::vector<double>(s.band_cacfar, s.band_cacfar + 4);
    b["cen2018"] = std::vector<double>(s.band_cen, s.band_cen + 4);
    // Not a gap figure: the noise side, which tells receiver noise from weak clutter.
    b["floor"] = std::vector<double>(s.band_floor, s.band_floor + 4);
    b["zero"] = std::vector<double>(s.band_zero, s.band_zero + 4);
    // Nor these: beyond 100 m, the far slope's evidence (-1: the scans end at 100 m).
    b["beyond_mean"] = s.beyond_mean;
    b["beyond_q90"] = s.beyond_q90;
    return b;
  };
  if (!realism_real.name.empty()) {
    j["realism_bands"] = {{"recording_fit", bands(realism_real)},
                          {"sim_before", bands(realism_before)},
                          {"sim_after", bands(realism_after)}};
    if (seeds_after.per_seed.size() > 1) {  // each figure's range over the seeds
      j["realism_bands"]["sim_before_min"] = bands(seeds_before.lo);
      j["realism_bands"]["sim_before_max"] = bands(seeds_before.hi);
      j["realism_bands"]["sim_after_min"] = bands(seeds_after.lo);
      j["realism_bands"]["sim_after_max"] = bands(seeds_after.hi);
      for (const auto* o : {&seeds_before, &seeds_after}) {  // each seed's, for spreads
        nlohmann::json per = nlohmann::json::array();
        for (const auto& s : o->per_seed) per.push_back(bands(s));
        j["realism_bands"][o == &seeds_before ? "sim_before_per_seed" : "sim_after_per_seed"] = per;
      }
    }
    if (!realism_holdout.name.empty()) j["realism_bands"]["recording_holdout"] = bands(realism_holdout);
    j["scene_dependent_not_fitted"] = nlohmann::json::array();
    for (const auto& f : sceneDependentFigures())
      j["scene_dependent_not_fitted"].push_back(
          {{"band", f.band}, {"figure", f.figure}, {"reason", f.reason}});
    auto over = [](const sim::RealismStats& sim, const sim::RealismStats& real) {
      nlohmann::json o = nlohmann::json::object();
      for (const auto& [name, gap] : fittedBandGaps(sim, real))
        if (gap > 0.15) o[name] = gap;
      return o;
    };
    j["fitted_figures_over_15_percent"] = {{"fit_part", over(realism_after, realism_real)}};
    if (!realism_holdout.name.empty())
      j["fitted_figures_over_15_percent"]["holdout_part"] = over(realism_after, realism_holdout);
    if (!held_out_figures.empty()) {
      j["realism_bands"]["sim_after_fit_scene"] = bands(realism_fit_scene);
      j["realism_bands"]["sim_after_holdout_scene"] = bands(realism_holdout_scene);
      j["held_out_figures"] = detail::holdoutSceneJson(*this);
      j["worst_band_gap_fit_own_scene"] = worst_fit_scene;
      j["worst_band_gap_holdout_own_scene"] = worst_holdout_scene;
      j["worst_band_gap_holdout_net_of_scene"] = worst_net;
    }
  }
  j["runtime_s"] = runtime_s;
  return j;
}

}  // namespace spinradar::diagnose
