// `spinradar localize`: metric localization of a live drive against the scans of a map drive
// (possibly driven the other way), RSD descriptors + rigid RANSAC on compensated keypoints
// (core/localizer.hpp). Writes the pose of each live scan in the map frame, and with --truth
// its error, the median errors (the paper's Table II) and a histogram of the errors.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "cli_checks.hpp"
#include "command.hpp"
#include "output_guard.hpp"
#include "pipeline_options.hpp"
#include "progress.hpp"
#include "spinradar/evaluation/evaluation.hpp"
#include "spinradar/core/lie.hpp"
#include "spinradar/localization/localizer.hpp"
#include "spinradar/evaluation/plot.hpp"
#include "spinradar/io/scan_folder.hpp"

namespace {

using namespace spinradar;

struct LocalizeArgs {
  std::string map, map_poses, input, out, truth, plot;
  std::string compensation = "motion_doppler";
  std::string prior = "track";
  std::string initial_pose;
  double input_from = -1e300, input_to = 1e300;
  double min_speed = 0.0;
  int global_stride = 1;
  LocalizerConfig loc;
  RsdConfig rsd;
  cli::PipelineOptions pipeline;
};

template <class Config>
void addParams(CLI::App& app, Config& cfg, const std::string& group, const char* skip = "") {
  cfg.visit([&](const ParamMeta& m, auto& value) {
    const std::string name = m.name;
    if (name == skip) return;
    std::string dashed = name;
    std::replace(dashed.begin(), dashed.end(), '_', '-');
    std::string doc = m.doc;
    if (m.unit[0]) doc += std::string(" [") + m.unit + "]";
    auto* opt = app.add_option("--" + name + (dashed != name ? ",--" + dashed : ""), value, doc);
    opt->capture_default_str()->group(group);
  });
}

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

Eigen::Matrix3d parsePose(const std::string& text) {
  std::stringstream ss(text);
  double v[3];
  char c1 = 0, c2 = 0;
  if (!(ss >> v[0] >> c1 >> v[1] >> c2 >> v[2]) || c1 != ',' || c2 != ',')
    throw std::runtime_error("--initial-pose '" + text + "': expected x,y,yaw");
  return se2::fromXyYaw(Eigen::Vector3d(v[0], v[1], v[2]));
}

/// Output path of one compensation when several run: out.csv -> out_<mode>.csv.
std::string modePath(const std::string& out, Compensation c, bool several) {
  if (!several) return out;
  const std::filesystem::path p(out);
  return (p.parent_path() / (p.stem().string() + "_" + compensationName(c) + p.extension().string()))
      .string();
}

struct ModeState {
  Compensation comp;
  std::unique_ptr<AtomicOutputFile> file;  // renamed onto `path` when the run completes
  std::string path;
  bool have_last = false;
  Eigen::Matrix3d T_last = Eigen::Matrix3d::Identity();
  int64_t last_stamp = 0;
  std::vector<double> err_t, err_r, match_ms;
  int evaluated = 0, failures = 0;
};

void savePlot(const std::vector<std::unique_ptr<ModeState>>& modes, const std::string& path) {
  using namespace spinradar::plot;
  Plot pt, pr;
  pt.title("Localization translation error").xlabel("error [m]").ylabel("scans");
  pr.title("Localization rotation error").xlabel("error [deg]").ylabel("scans");
  auto add = [&](Plot& p, bool rot) {
    std::vector<double> all;
    for (const auto& m : modes) all.insert(all.end(), (rot ? m->err_r : m->err_t).begin(), (rot ? m->err_r : m->err_t).end());
    if (all.empty()) return;
    std::sort(all.begin(), all.end());
    const double hi = std::max(all[static_cast<size_t>(0.95 * (all.size() - 1))], 1e-3) * 1.05;
    const int bins = 25;
    const double w = hi / bins;
    const int n = static_cast<int>(modes.size());
    for (int i = 0; i < n; ++i) {
      // Side-by-side bars per bin, one colour per compensation.
      Histogram h = histogram(rot ? modes[i]->err_r : modes[i]->err_t, bins, 0.0, hi);
      Series s;
      s.label = compensationName(modes[i]->comp);
      s.style = SeriesStyle::Bars;
      s.color = paletteColor(i + 1);
      s.bar_width = w / n;
      for (size_t b = 0; b < h.centres.size(); ++b) {
        s.x.push_back(h.centres[b] - 0.5 * w + (i + 0.5) * w / n);
        s.y.push_back(h.counts[b]);
      }
      p.add(s);
    }
    p.xlim(0.0, hi);
  };
  add(pt, false);
  add(pr, true);
  saveImage(tile({pt.render(800, 500), pr.render(800, 500)}, 2), path);
}

void runLocalize(LocalizeArgs& a) {
  const PipelineConfig pipeline = a.pipeline.resolve();
  std::vector<Compensation> comps;
  if (a.compensation == "all")
    comps = {Compensation::None, Compensation::Motion, Compensation::MotionDoppler};
  else
    comps = {parseCompensation(a.compensation)};
  a.loc.compensation = compensationName(comps.back());
  if (a.prior != "track" && a.prior != "truth")
    throw std::runtime_error("--prior '" + a.prior + "': expected track or truth");
  std::vector<PoseRecord> truth;
  if (!a.truth.empty()) truth = readPoseCsv(a.truth).poses;
  if (a.prior == "truth" && truth.empty()) throw std::runtime_error("--prior truth needs --truth");

  if (!a.plot.empty()) {
    if (truth.empty()) throw std::runtime_error("--plot needs --truth (it plots the errors)");
    plot::checkImagePath(a.plot);
  }
  Localizer loc(a.loc, a.rsd, pipeline);
  {
    std::unique_ptr<cli::Progress> progress;
    const int n = loc.loadMap(a.map, a.map_poses, [&](size_t done, size_t total) {
      if (!progress) progress = std::make_unique<cli::Progress>("map", total);
      if (done > 0) progress->update(done);
    });
    std::cerr << "localize: map of " << n << " scans from " << a.map << "\n";
  }

  ScanFolder live(a.input);
  {
    std::vector<NamedPath> inputs = cli::scanFolderInputs(live, "--input");
    for (const auto& p : cli::scanFolderInputs(ScanFolder(a.map), "--map")) inputs.push_back(p);
    inputs.insert(inputs.end(), {{a.map_poses, "--map-poses"}, {a.truth, "--truth"},
                                 {a.pipeline.configPath(), "--config"}});
    std::vector<NamedPath> outputs{{a.plot, "--plot"}};
    for (Compensation c : comps) outputs.push_back({modePath(a.out, c, comps.size() > 1), "--out"});
    cli::refuseOutputsOverInputs(outputs, inputs);
  }
  std::vector<size_t> idx;
  for (size_t i = 0; i < live.size(); ++i) {
    const double t = 1e-9 * static_cast<double>(live.fileStampNs(i));
    if (t >= a.input_from && t <= a.input_to) idx.push_back(i);
  }
  if (idx.empty()) throw std::runtime_error(a.input + ": no scan in the --input-from/--input-to window");

  const bool several = comps.size() > 1;
  std::vector<std::unique_ptr<ModeState>> modes;
  for (Compensation c : comps) {
    auto m = std::make_unique<ModeState>();
    m->comp = c;
    m->path = modePath(a.out, c, several);
    m->file = std::make_unique<AtomicOutputFile>(m->path);
    std::ofstream& csv = m->file->stream();
    csv << "t,x,y,yaw,ok,map_t,matches,inliers,velocity_known" << (truth.empty() ? "" : ",err_trans,err_rot_deg") << "\n";
    csv << std::fixed << std::setprecision(9);  // UNIX-time stamps need the decimals
    modes.push_back(std::move(m));
  }
  const bool have_initial = !a.initial_pose.empty();
  const Eigen::Matrix3d T_initial = have_initial ? parsePose(a.initial_pose) : Eigen::Matrix3d::Identity();

  // Sliding window: a scan's velocity comes from (it, next), so next is prepared first.
  LocFrame prev, cur, next;
  bool have_prev = false;
  std::vector<double> rsd_ms;
  double ms = 0.0;
  loc.prepare(live.load(idx[0]), next, &ms);
  rsd_ms.push_back(ms);
  cli::Progress progress("localize", idx.size());
  for (size_t k = 0; k < idx.size(); ++k) {
    std::swap(prev, cur);
    std::swap(cur, next);
    if (k + 1 < idx.size()) {
      loc.prepare(live.load(idx[k + 1]), next, &ms);
      rsd_ms.push_back(ms);
    }
    loc.setVelocity(cur, have_prev ? &prev : nullptr, k + 1 < idx.size() ? &next : nullptr);
    have_prev = true;
    const double t = 1e-9 * static_cast<double>(cur.stamp_ns);
    PoseRecord tp;
    const bool have_truth = !truth.empty() && interpolatePose(truth, t, tp);
    double speed = 0.0;
    if (have_truth) {
      PoseRecord tq;
      if (interpolatePose(truth, t + 0.1, tq)) speed = std::hypot(tq.x - tp.x, tq.y - tp.y) / 0.1;
    }
    const Eigen::Matrix3d T_true = have_truth ? poseMatrix(tp) : Eigen::Matrix3d::Identity();

    for (auto& mp : modes) {
      ModeState& m = *mp;
      std::ofstream& csv = m.file->stream();
      LocalizationResult r;
      if (a.prior == "truth") {
        if (!have_truth) continue;  // outside the truth's span: nothing to localize with
        r = loc.localize(cur, T_true, m.comp);
      } else if (m.have_last) {
        const double dt = 1e-9 * static_cast<double>(cur.stamp_ns - m.last_stamp);
        const Eigen::Vector3d v = cur.has_velocity ? cur.velocity_doppler : Eigen::Vector3d::Zero();
        r = loc.localize(cur, m.T_last * se2::exp(dt * v), m.comp);
        loc.checkAgainstPrior(r);
      } else if (have_initial) {
        r = loc.localize(cur, T_initial, m.comp);
        loc.checkAgainstPrior(r);
      } else {
        r = loc.globalLocalize(cur, m.comp, a.global_stride);
      }
      if (r.ok || m.have_last || have_initial) {
        m.T_last = r.T_map_sensor;
        m.have_last = true;
        m.last_stamp = cur.stamp_ns;
      }
      m.match_ms.push_back(r.match_ms);
      const Eigen::Vector3d p = se2::toXyYaw(r.T_map_sensor);
      const double map_t =
          r.map_index >= 0 ? 1e-9 * static_cast<double>(loc.mapFrame(r.map_index).stamp_ns) : std::nan("");
      csv << t << ',' << p(0) << ',' << p(1) << ',' << p(2) << ',' << (r.ok ? 1 : 0) << ','
            << map_t << ',' << r.matches << ',' << r.inliers << ',' << (r.velocity_known ? 1 : 0);
      if (!truth.empty()) {
        if (have_truth && r.ok) {
          const Eigen::Vector3d e = se2::toXyYaw(se2::inverse(T_true) * r.T_map_sensor);
          const double et = e.head<2>().norm(), er = std::abs(e(2)) * 180.0 / M_PI;
          csv << ',' << et << ',' << er;
          if (speed >= a.min_speed) {
            m.err_t.push_back(et);
            m.err_r.push_back(er);
          }
        } else {
          csv << ",nan,nan";
        }
        if (have_truth && speed >= a.min_speed) {
          ++m.evaluated;
          if (!r.ok) ++m.failures;
        }
      }
      csv << '\n';
    }
    progress.update(k + 1);
  }

  std::printf("RSD: median %.2f ms CPU per scan (%zu live scans); matching: median %.2f ms CPU per scan pair\n",
              median(rsd_ms), rsd_ms.size(), median(modes.back()->match_ms));
  if (!truth.empty()) {
    std::printf("%-16s %9s %9s %18s %18s\n", "compensation", "scans", "failed", "median trans [m]",
                "median rot [deg]");
    for (const auto& m : modes)
      std::printf("%-16s %9d %9d %18.4f %18.4f\n", compensationName(m->comp), m->evaluated, m->failures,
                  median(m->err_t), median(m->err_r));
    if (a.min_speed > 0.0) std::printf("(live scans at >= %.1f m/s only)\n", a.min_speed);
  }
  for (const auto& m : modes) {
    m->file->commit();
    std::cerr << "localize: wrote " << m->path << "\n";
  }
  if (!a.plot.empty()) {
    savePlot(modes, a.plot);
    std::cerr << "localize: wrote " << a.plot << "\n";
  }
}

}  // namespace

SPINRADAR_COMMAND(
    "localize", "Localize a drive against a map drive's scans (RSD + RANSAC, Table II)",
    [](CLI::App& app) {
      auto a = std::make_shared<LocalizeArgs>();
      app.add_option("--map", a->map, "Map drive: folder of polar scans")->required();
      app.add_option("--map-poses", a->map_poses, "Map scan poses CSV (t,x,y,yaw; interpolated)")
          ->required();
      app.add_option("--input", a->input, "Live drive: folder of polar scans")->required();
      app.add_option("--out", a->out,
                     "Output CSV: pose of each live scan in the map frame (with --compensation "
                     "all: <out>_<mode>.csv)")
          ->required();
      app.add_option("--truth", a->truth, "Live drive ground truth CSV (t,x,y,yaw)");
      app.add_option("--compensation", a->compensation, "none, motion, motion_doppler or all")
          ->capture_default_str();
      app.add_option("--prior", a->prior,
                     "Map scan selection: track (previous estimate + odometry; truth-free) or "
                     "truth (nearest to the true pose, as the paper pairs scans by GPS)")
          ->capture_default_str();
      app.add_option("--initial-pose", a->initial_pose,
                     "x,y,yaw of the first live scan for --prior track (default: global search)");
      app.add_option("--global-stride", a->global_stride,
                     "Global search tries every n-th map scan")
          ->capture_default_str()
          ->check(cli::atLeast(1));
      app.add_option("--input-from", a->input_from, "Only live scans from this time (s)");
      app.add_option("--input-to", a->input_to, "Only live scans up to this time (s)");
      app.add_option("--min-speed", a->min_speed,
                     "Statistics over live scans at least this fast (m/s, from --truth)")
          ->capture_default_str();
      app.add_option("--plot", a->plot, "Histogram of the errors (PNG; needs --truth)");
      addParams(app, a->loc, "Localizer parameters", "compensation");
      addParams(app, a->rsd, "RSD parameters");
      a->pipeline.add(app);
      // --config may also set the localizer and RSD parameters (options given still win).
      CLI::App* self = &app;
      a->pipeline.setExtraParams([a, self](const std::string& name, const std::string& value,
                                           const std::string& where) {
        LocalizerConfig loc = a->loc;
        RsdConfig rsd = a->rsd;
        const bool is_loc = cli::setParamByName(loc, name, value, where);
        const bool is_rsd = !is_loc && cli::setParamByName(rsd, name, value, where);
        if (!is_loc && !is_rsd) return false;
        const CLI::Option* given = self->get_option_no_throw("--" + name);
        if (given && given->count() > 0) return true;  // the command line overrides the file
        if (is_loc) a->loc = loc;
        else a->rsd = rsd;
        return true;
      });
      app.callback([a] { runLocalize(*a); });
    });
