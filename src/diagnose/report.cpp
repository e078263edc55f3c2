// report.json, summary.md / summary.txt and PNG plots of a diagnosis.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "spinradar/evaluation/plot.hpp"
#include "spinradar/diagnose/advice.hpp"
#include "spinradar/diagnose/diagnose.hpp"
#include "markdown_table.hpp"

namespace spinradar::diagnose {
namespace {

nlohmann::json statsJson(const ResidualStats& s) {
  return {{"n", s.n},
          {"position_rms_m", s.position_rms},
          {"range_rms_m", s.range_rms},
          {"azimuth_rms_rad", s.azimuth_rms},
          {"time_rms_s", s.time_rms}};
}

nlohmann::json locateJson(const std::vector<LocateRow>& rows) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& r : rows)
    a.push_back({{"by", r.by},
                 {"group", r.label},
                 {"n", r.n},
                 {"mean_range_m", r.mean_r},
                 {"rms_range_m", r.rms_r},
                 {"mean_tangential_m", r.mean_t},
                 {"rms_tangential_m", r.rms_t},
                 {"z", r.z}});
  return a;
}

}  // namespace

nlohmann::json DiagnoseReport::toJson() const {
  nlohmann::json j;
  j["mismatch_found"] = mismatch_found;
  j["verdict"] = mismatch_found ? "mismatch found" : "no significant mismatch";
  j["effects"] = nlohmann::json::array();
  for (const auto& e : effects)
    j["effects"].push_back({{"name", e.name},
                            {"parameter", e.parameter},
                            {"unit", e.unit},
                            {"value", e.value},
                            {"stddev", e.stddev},
                            {"change_from_base", e.change},
                            {"significance", e.significance},
                            {"p_value", e.p},
                            {"holm_threshold", e.holm_threshold},
                            {"lr", e.lr},
                            {"lm", e.lm},
                            {"delta_bic", e.delta_bic},
                            {"absorbed_fraction", e.absorbed},
                            {"absorbed_by_scan_alignment", e.absorbed_by_alignment},
                            {"vif", e.vif},
                            {"confounded_with", e.confounded_with},
                            {"signature", signatureOf(e.effect)},
                            {"residual_rms_before", e.residual_rms_before},
                            {"residual_rms_after", e.residual_rms_after},
                            {"range_rms_before", e.range_rms_before},
                            {"range_rms_after", e.range_rms_after},
                            {"azimuth_rms_before", e.azimuth_rms_before},
                            {"azimuth_rms_after", e.azimuth_rms_after}});
  j["candidates"] = nlohmann::json::array();
  for (const auto& c : candidates)
    j["candidates"].push_back({{"name", effectName(c.effect)},
                               {"estimate", c.estimate},
                               {"stddev", c.stddev},
                               {"z", c.z},
                               {"lm", c.lm},
                               {"lr", c.lr},
                               {"p_value", c.p},
                               {"delta_bic", c.delta_bic},
                               {"absorbed_fraction", c.absorbed},
                               {"absorbed_by_scan_alignment", c.absorbed_by_alignment},
                               {"vif", c.vif}});
  nlohmann::json corr = nlohmann::json::object();
  for (size_t a = 0; a < effect_names_tested.size(); ++a)
    for (size_t b = a + 1; b < effect_names_tested.size(); ++b)
      if (static_cast<Eigen::Index>(b) < candidate_corr.rows())
        corr[effect_names_tested[a] + "~" + effect_names_tested[b]] = candidate_corr(a, b);
  j["candidate_correlation"] = corr;
  j["notes"] = notes;
  j["residual_rms_before"] = before.position_rms;
  j["residual_rms_after"] = after.position_rms;
  j["residuals_before"] = statsJson(before);
  j["residuals_after"] = statsJson(after);
  j["residuals_after_each_effect"] = nlohmann::json::array();
  for (const auto& s : after_step) j["residuals_after_each_effect"].push_back(statsJson(s));
  j["base_physics"] = base.toJson();
  j["fitted_physics"] = fitted.toJson();
  j["locate"] = locateJson(locate);
  j["locate_after_fit"] = locateJson(locateResiduals(obs, true));
  j["data"] = {{"scans", scans},
               {"observations", static_cast<int>(obs.size())},
               {"outliers", outliers},
               {"targets_used", targets_used},
               {"sigma_range_m", sigma_r},
               {"sigma_azimuth_rad", sigma_az},
               {"effects_tested", effect_names_tested}};
  j["scene_model"] = scene_model;
  j["timing"] = timing.toJson();
  j["runtime_s"] = runtime_s;
  return j;
}

std::string DiagnoseReport::summaryMarkdown() const {
  std::ostringstream s;
  s << "# spinradar diagnose\n\n";
  s << "**Verdict: " << (mismatch_found ? "mismatch found" : "no significant mismatch") << "**"
    << " (" << scans << " scans, " << obs.size() << " target returns of " << targets_used
    << " targets, " << outliers << " outliers dropped; family-wise alpha with Holm correction "
    << "and BIC).\n\n";
  s << "Scene model: " << scene_model << ".\n\n";
  s << timing.summaryMarkdown() << "\n";
  s << "Residual RMS (position, re-simulated): " << fmt(before.position_rms) << " m before, "
    << fmt(after.position_rms) << " m after. Range " << fmt(before.range_rms) << " -> "
    << fmt(after.range_rms) << " m, azimuth " << fmt(before.azimuth_rms * 180 / M_PI) << " -> "
    << fmt(after.azimuth_rms * 180 / M_PI) << " deg.\n\n";
  if (!effects.empty()) {
    MarkdownTable t({"effect", "parameter", "value", "stddev", "z", "LR", "dBIC", "absorbed",
                     "rms before (m)", "rms after (m)"});
    for (const auto& e : effects)
      t.row(e.name, e.parameter + (e.unit.empty() ? "" : " (" + e.unit + ")"), fmt(e.value, 5),
            fmt(e.stddev, 3), fmt(e.significance, 3), fmt(e.lr, 4), fmt(e.delta_bic, 4),
            fmt(e.absorbed, 2), fmt(e.residual_rms_before), fmt(e.residual_rms_after));
    s << "## Effects found (most significant first)\n\n" << t.str() << "\n";
  }
  MarkdownTable cand({"effect", "estimate", "stddev", "z", "LM", "LR", "p", "dBIC", "VIF",
                      "absorbed by scan alignment"});
  for (const auto& c : candidates)
    cand.row(effectName(c.effect), fmt(c.estimate, 4), fmt(c.stddev, 3), fmt(c.z, 3),
             fmt(c.lm, 4), fmt(c.lr, 4), fmt(c.p, 3), fmt(c.delta_bic, 4), fmt(c.vif, 3),
             fmt(c.absorbed_by_alignment, 2));
  s << "## Every candidate against the base model\n\n" << cand.str();
  if (!notes.empty()) {
    s << "\n## Notes\n\n";
    for (const auto& n : notes) s << "- " << n << "\n";
  }
  MarkdownTable where({"by", "group", "n", "mean range (cm)", "rms range (cm)",
                       "mean tangential (cm)", "rms tangential (cm)", "z"});
  for (const auto& r : locate)
    where.row(r.by, r.label, r.n, fmt(100 * r.mean_r, 3), fmt(100 * r.rms_r, 3),
              fmt(100 * r.mean_t, 3), fmt(100 * r.rms_t, 3),
              fmt(r.z, 3) + (r.z > 3 ? " **" : ""));
  s << "\n## Where the residuals are (before fitting; |z| > 3 marked)\n\n" << where.str();
  s << "\nFitted physics: `" << fitted.toJson().dump() << "`\n";
  s << "\nRuntime " << fmt(runtime_s, 3) << " s.\n";
  return s.str();
}

void writeTimingReport(const TimingReport& timing, const std::string& out_dir,
                       const std::string& why_no_catalogue) {
  namespace fs = std::filesystem;
  fs::create_directories(out_dir);
  nlohmann::json j;
  j["mismatch_found"] = !timing.findings.empty();
  j["verdict"] = timing.findings.empty() ? "no timing effect found" : "timing effect found";
  j["catalogue"] = "not run: " + why_no_catalogue;
  j["timing"] = timing.toJson();
  std::ostringstream md;
  md << "# spinradar diagnose (timing only)\n\n**Verdict: "
     << (timing.findings.empty() ? "no timing effect found" : "timing effect found")
     << "**\n\nCatalogue stage not run: " << why_no_catalogue << "\n\n"
     << timing.summaryMarkdown();
  for (const std::string name : {"report.json", "summary.md", "summary.txt"}) {
    const std::string path = (fs::path(out_dir) / name).string();
    std::ofstream f(path);
    if (!f) throw std::runtime_error(path + ": cannot write");
    f << (name == "report.json" ? j.dump(2) + "\n" : md.str());
  }
}

void writeReport(const DiagnoseReport& rep, const std::string& out_dir) {
  namespace fs = std::filesystem;
  fs::create_directories(out_dir);
  const auto write = [&](const std::string& name, const std::string& text) {
    const std::string path = (fs::path(out_dir) / name).string();
    std::ofstream f(path);
    if (!f) throw std::runtime_error(path + ": cannot write");
    f << text;
  };
  write("report.json", rep.toJson().dump(2) + "\n");
  const std::string md = rep.summaryMarkdown();
  write("summary.md", md);
  write("summary.txt", md);
  rep.fitted.save((fs::path(out_dir) / "fitted_physics.json").string());

  // Residuals against azimuth (range and tangential), before and after the fit.
  std::vector<double> az, er, et, er_f, et_f, vr, scan_i, rng;
  for (const auto& o : rep.obs) {
    if (!o.inlier) continue;
    az.push_back(std::fmod(std::fmod(o.azimuth * 180 / M_PI, 360.0) + 360.0, 360.0));
    er.push_back(100 * o.e_r);
    et.push_back(100 * o.range * o.e_az);
    er_f.push_back(100 * o.fit_r);
    et_f.push_back(100 * o.range * o.fit_az);
    vr.push_back(o.radialVelocity());
    scan_i.push_back(o.scan);
    rng.push_back(o.range);
  }
  using plot::Plot;
  // Each panel: one residual against one quantity, base model and fitted model.
  const auto panel = [](const char* title, const char* xlabel, const char* ylabel,
                        const std::vector<double>& x, const std::vector<double>& base,
                        const std::vector<double>& fitted) {
    return Plot()
        .labels(title, xlabel, ylabel)
        .scatter(x, base, "base model")
        .scatter(x, fitted, "fitted model")
        .render(700, 450);
  };
  std::vector<cv::Mat> panels;
  panels.push_back(panel("range residual vs azimuth", "azimuth (deg, clockwise)",
                         "real - sim range (cm)", az, er, er_f));
  panels.push_back(panel("tangential residual vs azimuth", "azimuth (deg, clockwise)",
                         "range x azimuth residual (cm)", az, et, et_f));
  panels.push_back(panel("range residual vs radial velocity (Doppler signature)",
                         "sensor velocity along the ray (m/s)", "real - sim range (cm)", vr, er,
                         er_f));
  panels.push_back(panel("range residual vs range", "range (m)", "real - sim range (cm)", rng, er,
                         er_f));
  plot::saveImage(plot::tile(panels, 2), (fs::path(out_dir) / "residuals.png").string());

  // Per scan: mean and RMS of the residuals.
  std::vector<double> sx, mr, rr, mt;
  for (const auto& r : rep.locate)
    if (r.by == "scan") {
      sx.push_back(static_cast<double>(sx.size()));
      mr.push_back(100 * r.mean_r);
      rr.push_back(100 * r.rms_r);
      mt.push_back(100 * r.mean_t);
    }
  // Residual RMS after each effect is added (re-simulated).
  std::vector<double> step_x = {0}, step_rms = {100 * rep.before.position_rms};
  for (size_t j = 0; j < rep.after_step.size(); ++j) {
    step_x.push_back(static_cast<double>(j + 1));
    step_rms.push_back(100 * rep.after_step[j].position_rms);
  }
  std::vector<cv::Mat> p2;
  p2.push_back(Plot()
                   .title("per scan (base model)")
                   .xlabel("scan")
                   .ylabel("cm")
                   .line(sx, mr, "mean range residual")
                   .line(sx, rr, "rms range residual")
                   .line(sx, mt, "mean tangential residual")
                   .render(700, 450));
  plot::Histogram h;
  h.centres = step_x;
  h.counts = step_rms;
  h.width = 0.6;
  p2.push_back(Plot()
                   .title("position residual RMS as effects are added")
                   .xlabel("effects added (order of the report)")
                   .ylabel("rms (cm)")
                   .bars(h, "re-simulated")
                   .render(700, 450));
  plot::saveImage(plot::tile(p2, 2), (fs::path(out_dir) / "locate.png").string());
}

}  // namespace spinradar::diagnose
