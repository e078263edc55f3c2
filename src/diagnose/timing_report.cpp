// Timing stage, part 3: the report's JSON and Markdown sections.
#include <sstream>

#include <nlohmann/json.hpp>

#include "spinradar/diagnose/timing.hpp"
#include "markdown_table.hpp"
#include "timing_detail.hpp"

namespace spinradar::diagnose {

using detail::scansWord;
using detail::usRms;

nlohmann::json TimingReport::toJson() const {
  nlohmann::json j;
  j["stamp_model"] = stamp_model;
  j["scans"] = scans;
  j["rows"] = rows;
  j["rows_per_rotation"] = rows_per_rotation;
  j["row_interval_s"] = row_interval;
  j["stamp_rms_about_uniform_s"] = stamp_rms_uniform;
  j["stamp_rms_about_model_s"] = stamp_rms_model;
  j["bursts"] = {{"found", bursts},       {"size", burst_size},
                 {"spacing_s", burst_spacing}, {"spacing_sd_s", burst_spacing_sd},
                 {"gap_s", burst_gap},    {"z", burst_z},
                 {"p_value", burst_p},    {"size_agreement", burst_size_agreement},
                 {"phase", burst_phase}};
  j["period"] = {{"per_scan_s", period},      {"per_scan_sd_s", period_sd},
                 {"mean_s", period_mean},     {"relative_std", period_rel_std},
                 {"relative_std_sd", period_rel_std_sd}, {"chi2", period_chi2},
                 {"dof", period_dof},         {"p_value", period_p},
                 {"start_gaps_s", start_gap},  {"start_gap_mean_s", start_gap_mean},
                 {"start_gap_relative_std", start_gap_rel_std}};
  j["jitter"] = {{"tested", jitter_tested},   {"stretch_per_scan", stretch},
                 {"stretch_sd", stretch_sd},  {"std", jitter_std},
                 {"std_sd", jitter_std_sd},   {"chi2", jitter_chi2},
                 {"dof", jitter_dof},         {"p_value", jitter_p}};
  j["findings"] = nlohmann::json::array();
  for (const auto& f : findings)
    j["findings"].push_back({{"name", f.name},
                             {"parameter", f.parameter},
                             {"unit", f.unit},
                             {"value", f.value},
                             {"stddev", f.stddev},
                             {"significance", f.significance},
                             {"p_value", f.p},
                             {"scans", f.scans},
                             {"evidence", f.evidence},
                             {"details", f.details}});
  j["advice"] = advice;
  j["notes"] = notes;
  if (!chirp_doppler.is_null()) j["chirp_doppler"] = chirp_doppler;
  return j;
}

std::string TimingReport::summaryMarkdown() const {
  std::ostringstream s;
  s << "## Timing (" << scansWord(scans) << ", " << rows << " rows)\n\n";
  s << "Stamp model: **" << stamp_model << "**";
  if (bursts)
    s << " (packets of " << burst_size << ", spacing " << fmt(burst_spacing * 1e6, 4) << " +- "
      << fmt(burst_spacing_sd * 1e6, 2) << " us, gap " << fmt(burst_gap * 1e3, 4)
      << " ms, z " << fmt(burst_z, 3) << ")";
  s << "; stamps about one line per scan: " << fmt(usRms(stamp_rms_uniform), 4)
    << " us RMS, about the model: " << fmt(usRms(stamp_rms_model), 4) << " us RMS.\n\n";
  if (!period.empty()) {
    s << "Rotation period from the stamps (ms):";
    for (size_t k = 0; k < period.size(); ++k) s << " " << fmt(period[k] * 1e3, 7);
    s << "; relative spread " << fmt(100 * period_rel_std, 3) << " % (chi2 "
      << fmt(period_chi2, 4) << ", " << period_dof << " dof).";
    if (!start_gap.empty())
      s << " Scan start times: " << fmt(start_gap_mean * 1e3, 7) << " ms apart on average, "
        << "relative std " << fmt(100 * start_gap_rel_std, 3) << " % over " << start_gap.size()
        << " gaps.";
    s << "\n\n";
  }
  if (jitter_tested)
    s << "Rotation jitter from the targets: std " << fmt(100 * jitter_std, 3) << " +- "
      << fmt(100 * jitter_std_sd, 2) << " % (chi2 " << fmt(jitter_chi2, 4) << ", " << jitter_dof
      << " dof, p " << fmt(jitter_p, 3) << ").\n\n";
  if (!findings.empty()) {
    MarkdownTable t({"timing effect", "parameter", "value", "stddev", "z", "scans", "evidence"});
    for (const auto& f : findings)
      t.row(f.name, f.parameter + (f.unit.empty() ? "" : " (" + f.unit + ")"), fmt(f.value, 5),
            fmt(f.stddev, 3), fmt(f.significance, 3), f.scans, f.evidence);
    s << t.str() << "\n";
  }
  s << "**Timing model to use:**\n\n";
  for (const auto& a : advice) s << "- " << a << "\n";
  for (const auto& n : notes) s << "- Note: " << n << "\n";
  if (!chirp_doppler.is_null()) {
    const auto& c = chirp_doppler;
    s << "\nIn-scan Doppler (alternating chirps, `spinradar chirp-doppler`): detected in "
      << c["scans_detected"].get<int>() << " of " << c["scans_with_alternating_chirps"].get<int>()
      << " scans; median beta |v| " << fmt(c["median_beta_v_m"].get<double>(), 3) << " m";
    if (c.contains("median_speed_mps"))
      s << ", median speed " << fmt(c["median_speed_mps"].get<double>(), 3) << " m/s given beta "
        << fmt(c["beta_given_s"].get<double>(), 3) << " s";
    s << ".\n";
    for (const auto& r : c["per_scan"]) s << "- scan " << r["scan"].get<int>() << ": "
                                          << r["verdict"].get<std::string>() << "\n";
  }
  return s.str();
}

}  // namespace spinradar::diagnose
