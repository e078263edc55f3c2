// Appearance stage: locate the differences, realism before/after, report files and plots.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "appearance_detail.hpp"
#include "spinradar/sim/reference_scene.hpp"
#include "markdown_table.hpp"
#include "spinradar/evaluation/plot.hpp"

namespace spinradar::diagnose {

namespace detail {

namespace {

const char* kBandNames[kBands] = {"2.5-10 m", "10-25 m", "25-50 m", "50-100 m"};

void add(AppearanceReport& rep, const std::string& by, const std::string& where, double real,
         double sim, const std::string& unit, double notable, const std::string& what) {
  AppearanceLocate l{by, where, real, sim, unit, ""};
  const double d = real - sim;
  if (std::isfinite(d) && std::abs(d) >= notable) {
    std::ostringstream os;
    os << std::fixed << std::setprecision(1) << where << ": simulated " << std::abs(d) << " "
       << unit << (d > 0 ? " lower" : " higher") << " (" << what << ")";
    l.note = os.str();
  }
  rep.locate.push_back(l);
}

}  // namespace

void locateAppearance(AppearanceReport& rep) {
  const AppearanceFigures &r = rep.real, &s = rep.before;
  for (int k = 0; k < kBands; ++k) {
    add(rep, "range band, low intensities", kBandNames[k], r.floor[k], s.floor[k], "dB", 1.0,
        "noise floor: mean of the lower half");
    add(rep, "range band, mid intensities", kBandNames[k], r.mean[k], s.mean[k], "dB", 1.0,
        "mean count");
    add(rep, "range band, high intensities", kBandNames[k], r.bright[k], s.bright[k], "dB", 1.0,
        "mean of the brightest 5 %");
    add(rep, "range band, texture", kBandNames[k], std::pow(10.0, r.cfar[k]) - 1,
        std::pow(10.0, s.cfar[k]) - 1, "CA-CFAR cells/scan",
        0.15 * std::max(1.0, std::pow(10.0, r.cfar[k])), "clutter standing out of its neighbourhood");
  }
  add(rep, "isolated point targets", "azimuth width", r.beam_rows, s.beam_rows, "rows", 0.1,
      "beam width");
  add(rep, "isolated point targets", "range width", r.psf_bins, s.psf_bins, "bins", 0.3,
      "range point spread");
  add(rep, "neighbourhood of strong returns", "3-6 rows off", r.az_sidelobe_db, s.az_sidelobe_db,
      "dB re peak", 3.0, "azimuth sidelobes");
  add(rep, "neighbourhood of strong returns", "10-20 bins off", r.rng_sidelobe_db,
      s.rng_sidelobe_db, "dB re peak", 3.0, "range sidelobes");
  add(rep, "behind the first strong hit", "2-32 m behind", 100 * r.behind, 100 * s.behind,
      "% bright cells", 0.5, "multipath ghosts / penetration");
  add(rep, "near range", "below 2 m", r.near_excess, s.near_excess, "dB over floor", 2.0,
      "near-range leakage");
  add(rep, "azimuth", "row-to-row floor std", r.row_sd, s.row_sd, "dB", 0.5,
      "noise texture across azimuths");
  add(rep, "intensity level", "top count", r.top_count, s.top_count, "count", 3.0,
      "receiver saturation / compression");
  add(rep, "intensity level", "distinct codes 1-30", r.distinct_low_codes, s.distinct_low_codes,
      "codes", 3.0, "log quantisation");
}

void realismBeforeAfter(const std::vector<PolarScan>& real, const std::vector<PolarScan>& holdout,
                        const AppearanceOptions& opt, AppearanceReport& rep) {
  sim::RealismOptions ro;
  rep.realism_real = sim::computeRealism(real, "recording, fit part", ro);
  if (!holdout.empty()) rep.realism_holdout = sim::computeRealism(holdout, "recording, held out", ro);
  // Each simulated figure is the mean over the report's noise seeds (one render of seed + 1 by
  // default), the worst gaps the mean of each seed's worst gap: a single render's worst gap moves
  // by up to 15 points with the seed (docs/diagnose_render_seeds.md).
  const std::vector<uint64_t> seeds = reportSeeds(opt);
  const std::string over =
      seeds.size() > 1 ? " (mean of " + std::to_string(seeds.size()) + " seeds)" : "";
  rep.seeds_before = realismOverSeedsOf(rep.base, rep.base_physics, opt, seeds, "sim, base model" + over);
  rep.seeds_after = realismOverSeedsOf(rep.fitted, rep.fitted_physics, opt, seeds, "sim, fitted model" + over);
  rep.realism_before = rep.seeds_before.mean;
  rep.realism_after = rep.seeds_after.mean;
  // Over the fitted figures only: a scene-dependent figure is reported on its own.
  auto gaps = [](const sim::RealismStats& sim, const sim::RealismStats& real) {
    std::vector<double> g;
    for (const auto& x : fittedBandGaps(sim, real)) g.push_back(x.second);
    return g;
  };
  rep.worst_before_seeds = sim::worstGapOverSeeds(rep.seeds_before, rep.realism_real, gaps);
  rep.worst_after_seeds = sim::worstGapOverSeeds(rep.seeds_after, rep.realism_real, gaps);
  rep.worst_gap_before = rep.worst_before_seeds.mean;
  rep.worst_gap_after = rep.worst_after_seeds.mean;
  if (!holdout.empty()) {
    rep.worst_holdout_before_seeds = sim::worstGapOverSeeds(rep.seeds_before, rep.realism_holdout, gaps);
    rep.worst_holdout_after_seeds = sim::worstGapOverSeeds(rep.seeds_after, rep.realism_holdout, gaps);
    rep.worst_holdout_before = rep.worst_holdout_before_seeds.mean;
    rep.worst_holdout_after = rep.worst_holdout_after_seeds.mean;
    if (opt.holdout_scene_check) holdoutSceneCheck(real, holdout, opt, rep);
  }
}

}  // namespace detail

std::string AppearanceReport::summaryMarkdown() const {
  std::ostringstream os;
  os << std::setprecision(3);
  os << "## Appearance stage\n\n";
  int named = 0;
  for (const auto& f : findings) named += f.named;
  os << (named ? "Appearance mismatch found: " : "No appearance mismatch named.");
  for (const auto& f : findings)
    if (f.named) os << f.effect << " " << f.base << " -> " << f.value << " +- " << f.stddev << " " << f.unit << "; ";
  os << "\n\n### Where (real vs re-simulated with the base model)\n\n";
  for (const auto& l : locate)
    if (!l.note.empty()) os << "- " << l.by << ", " << l.note << "\n";
  MarkdownTable where({"by", "where", "real", "sim", "unit"}, 3);
  for (const auto& l : locate) where.row(l.by, l.where, l.real, l.sim, l.unit);
  MarkdownTable fitted({"effect", "parameter", "base", "fitted", "+-", "z", "size", "verdict",
                        "figure gap before -> after"},
                       3);
  for (const auto& f : findings)
    fitted.row(f.effect, f.parameter + " (" + f.unit + ")", f.base, f.value, f.stddev, f.z,
               fmt(f.size, 3) + " " + f.size_unit, f.verdict,
               fmt(f.gap_before, 3) + " -> " + fmt(f.gap_after, 3));
  os << "\n" << where.str();
  os << "\n### Named and fitted (catalogue of sensor physics)\n\n" << fitted.str();
  os << "\nPractical thresholds: levels 1 dB, widths 10 %, slopes 2 dB/decade; smaller "
        "significant changes are reported as negligible, not as mismatches.\n";
  for (const auto& n : notes) os << "\n- " << n;
  if (!realism_real.name.empty()) {
    os << "\n\n### Realism figures before and after\n\n";
    std::vector<sim::RealismStats> cols = {realism_real};
    if (!realism_holdout.name.empty()) cols.push_back(realism_holdout);
    cols.push_back(realism_before);
    cols.push_back(realism_after);
    std::vector<const sim::RealismOverSeeds*> ranges(cols.size(), nullptr);
    ranges[cols.size() - 2] = &seeds_before;
    ranges[cols.size() - 1] = &seeds_after;
    os << sim::formatRealismTable(cols, ranges);
    const size_t n_seeds = seeds_after.per_seed.size();
    auto range = [&](const sim::SeedSpread& sp) {
      return n_seeds > 1 ? " [" + fmt(100 * sp.lo, 3) + "-" + fmt(100 * sp.hi, 3) + "]" : std::string();
    };
    if (n_seeds > 1)
      os << "\nSimulated columns: mean over " << n_seeds << " noise seeds [lowest-highest seed]; "
            "each worst gap below is the mean of the seeds' worst gaps [their range].\n";
    os << "\nWorst per-band gap over the fitted figures (mean, q90, CA-CFAR, Cen2018 per band; "
          "scene-dependent ones below left out), fit part (" << fit_scans
       << " scans): " << 100 * worst_gap_before << range(worst_before_seeds) << " % before, "
       << 100 * worst_gap_after << range(worst_after_seeds) << " % after.";
    if (!realism_holdout.name.empty()) {
      std::string fig;
      const double halves = realHalvesDifference(&fig);
      os << " Held-out part (" << holdout_scans << " scans; split " << holdout_split << "): "
         << 100 * worst_holdout_before << range(worst_holdout_before_seeds) << " % before, "
         << 100 * worst_holdout_after << range(worst_holdout_after_seeds) << " % after. The real halves' own difference under this split: " << fmt(100 * halves, 3)
         << " % (" << fig << "), the floor of the held-out check.";
    }
    os << "\n";
    auto over = [&](const sim::RealismStats& real, const char* part) {
      std::string names;
      for (const auto& [name, gap] : fittedBandGaps(realism_after, real))
        if (gap > 0.15) names += (names.empty() ? "" : ", ") + name + " " + fmt(100 * gap, 2) + " %";
      os << "\nFitted figures still over 15 % after, " << part << ": "
         << (names.empty() ? "none" : names) << ".";
    };
    over(realism_real, "fit part");
    if (!realism_holdout.name.empty()) over(realism_holdout, "held-out part");
    os << "\n" << detail::holdoutSceneMarkdown(*this);
    os << "\n\n**Scene-dependent, not fitted** (real fit part / held out / sim before / after; "
          "why below):\n";
    const char* const band_names[kBands] = {"2.5-10 m", "10-25 m", "25-50 m", "50-100 m"};
    auto value = [](const sim::RealismStats& s, int k, const std::string& f) {
      return f == "mean" ? s.band_mean[k] : f == "q90" ? s.band_q90[k]
             : f == "cacfar" ? s.band_cacfar[k] : s.band_cen[k];
    };
    for (const auto& f : sceneDependentFigures()) {
      os << "\n- " << band_names[f.band] << " " << f.figure << ": "
         << fmt(value(realism_real, f.band, f.figure), 4) << " / "
         << (realism_holdout.name.empty() ? std::string("-")
                                          : fmt(value(realism_holdout, f.band, f.figure), 4))
         << " / " << fmt(value(realism_before, f.band, f.figure), 4) << " / "
         << fmt(value(realism_after, f.band, f.figure), 4);
    }
    std::vector<std::string> reasons;  // once each
    for (const auto& f : sceneDependentFigures())
      if (std::find(reasons.begin(), reasons.end(), f.reason) == reasons.end())
        reasons.push_back(f.reason);
    for (const auto& r : reasons) os << "\n\nWhy: " << r << ".";
    os << "\n";
  }
  return os.str();
}

namespace {

void writeText(const std::filesystem::path& p, const std::string& text) {
  const std::filesystem::path tmp = p.string() + ".tmp";
  {
    std::ofstream f(tmp);
    if (!(f << text)) throw std::runtime_error(tmp.string() + ": cannot write");
  }
  std::filesystem::rename(tmp, p);
}

std::vector<double> rangeProfile(const std::vector<PolarScan>& scans, std::vector<double>& x) {
  x.clear();
  std::vector<double> sum, n;
  for (const auto& s : scans)
    for (int a = 0; a < s.azimuths; ++a)
      for (int b = 0; b < s.bins; ++b) {
        const double r = s.rangeOfBin(b);
        if (r < 0 || r > 100) continue;
        const size_t i = size_t(r);
        if (sum.size() <= i) sum.resize(i + 1, 0.0), n.resize(i + 1, 0.0);
        sum[i] += s.row(a)[b], n[i] += 1;
      }
  for (size_t i = 0; i < sum.size(); ++i) {
    x.push_back(i + 0.5);
    sum[i] = n[i] > 0 ? sum[i] / n[i] : NAN;
  }
  return sum;
}

std::vector<double> logHistogram(const std::vector<PolarScan>& scans) {
  std::vector<double> h(256, 0.0);
  double n = 0;
  for (const auto& s : scans)
    for (uint8_t v : s.power) h[v] += 1, n += 1;
  for (double& v : h) v = v > 0 ? std::log10(v / n) : NAN;
  return h;
}

}  // namespace

double AppearanceReport::realHalvesDifference(std::string* figure) const {
  double worst = 0;
  for (const auto& [name, gap] : fittedBandGaps(realism_holdout, realism_real))
    if (gap > worst) {
      worst = gap;
      if (figure) *figure = name;
    }
  return worst;
}

void writeAppearanceReport(const AppearanceReport& rep, const std::vector<PolarScan>& real,
                           const AppearanceOptions& opt, const std::string& out_dir) {
  namespace fs = std::filesystem;
  fs::create_directories(out_dir);
  const fs::path d(out_dir);
  {
    AppearanceReport r = rep;  // the split by name, "auto" resolved on the recording
    if (opt.holdout)
      r.holdout_split = opt.holdout_split == "auto"
                            ? "auto = " + chooseHoldoutSplit(real).name()
                            : parseHoldoutSplit(opt.holdout_split).name();
    writeText(d / "appearance.json", r.toJson().dump(2) + "\n");
    writeText(d / "appearance.md", r.summaryMarkdown());
  }
  {
    // The fitted file names the scene it was calibrated in (reference_scene.hpp), so it renders
    // there by default. A fit against the recording's own returns ("recording", "combined") has
    // no built-in scene to name: the key is dropped, not inherited from the starting file.
    sim::SensorConfig fitted = rep.fitted;
    fitted.reference_scene = sim::isBuiltinScene(opt.scene) ? opt.scene : "";
    fitted.save((d / "sensor_fitted.json").string());
  }
  rep.fitted_physics.save((d / "physics_fitted.json").string());

  const auto before = renderReference(rep.base, rep.base_physics, opt, opt.seed + 1);
  const auto after = renderReference(rep.fitted, rep.fitted_physics, opt, opt.seed + 1);
  using plot::Plot;
  // Each panel: one figure for the recording, the base model and the fitted model.
  const auto panel = [](const char* title, const char* xlabel, const char* ylabel,
                        const std::vector<double>& x, const std::vector<double>& rec,
                        const std::vector<double>& base, const std::vector<double>& fitted) {
    return Plot()
        .labels(title, xlabel, ylabel)
        .line(x, rec, "recording")
        .line(x, base, "sim, base model")
        .line(x, fitted, "sim, fitted model")
        .render(700, 450);
  };
  std::vector<cv::Mat> panels;
  std::vector<double> x;
  auto pr = rangeProfile(real, x), pb = rangeProfile(before, x), pa = rangeProfile(after, x);
  panels.push_back(panel("mean count vs range", "range (m)", "mean count (~dB)", x, pr, pb, pa));
  std::vector<double> cx(256);
  for (int v = 0; v < 256; ++v) cx[v] = v;
  panels.push_back(panel("intensity histogram", "count", "log10 share of cells", cx,
                         logHistogram(real), logHistogram(before), logHistogram(after)));
  std::vector<double> bx = {6.25, 17.5, 37.5, 75}, cr, cb, ca, fr, fb, fa;
  for (int k = 0; k < kBands; ++k) {
    cr.push_back(std::pow(10.0, rep.real.cfar[k]) - 1);
    cb.push_back(std::pow(10.0, rep.before.cfar[k]) - 1);
    ca.push_back(std::pow(10.0, rep.after.cfar[k]) - 1);
    fr.push_back(rep.real.bright[k]);
    fb.push_back(rep.before.bright[k]);
    fa.push_back(rep.after.bright[k]);
  }
  panels.push_back(panel("plain CA-CFAR cells per scan, by range band", "band centre (m)",
                         "cells per scan", bx, cr, cb, ca));
  panels.push_back(panel("brightest 5 % by range band (range gain)", "band centre (m)",
                         "mean count", bx, fr, fb, fa));
  plot::saveImage(plot::tile(panels, 2), (d / "appearance.png").string());
}

}  // namespace spinradar::diagnose
