// `spinradar eval`: KITTI-style drift of odometry CSV(s) against ground truth, with plots.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include <Eigen/LU>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "spinradar/core/evaluation.hpp"
#include "spinradar/core/plot.hpp"

namespace {

using namespace spinradar;

struct EvalArgs {
  std::vector<std::string> est, labels;
  std::string gt, plot, json;
  int step = 10;
  int frames_listed = 20;
};

/// Estimate expressed in the ground truth's frame: both start at the first associated pose.
void alignedTrajectory(const AssociatedPoses& p, std::vector<double>& ex, std::vector<double>& ey,
                       std::vector<double>& gx, std::vector<double>& gy) {
  const Eigen::Matrix3d align = p.gt.front() * p.est.front().inverse();
  for (size_t k = 0; k < p.t.size(); ++k) {
    const Eigen::Matrix3d e = align * p.est[k];
    ex.push_back(e(0, 2));
    ey.push_back(e(1, 2));
    gx.push_back(p.gt[k](0, 2));
    gy.push_back(p.gt[k](1, 2));
  }
}

void savePlots(const std::vector<EvaluationReport>& reports, const std::vector<std::string>& labels,
               const std::string& path) {
  using namespace spinradar::plot;
  const int W = 640, H = 480;
  Plot traj, tlen, rlen, tspd, rspd, frames;
  traj.title("Trajectory (estimate aligned at the first pose)").xlabel("x [m]").ylabel("y [m]")
      .equalAspect();
  tlen.title("Translational drift vs path length").xlabel("path length [m]").ylabel("drift [%]");
  rlen.title("Rotational drift vs path length").xlabel("path length [m]").ylabel("drift [deg/m]");
  tspd.title("Translational drift vs speed").xlabel("speed [m/s]").ylabel("drift [%]");
  rspd.title("Rotational drift vs speed").xlabel("speed [m/s]").ylabel("drift [deg/m]");
  frames.title("Frame-to-frame translation error").xlabel("time [s]").ylabel("error [m]");
  for (size_t i = 0; i < reports.size(); ++i) {
    const auto& r = reports[i];
    const cv::Scalar c = paletteColor(static_cast<int>(i) + 1);
    std::vector<double> ex, ey, gx, gy;
    alignedTrajectory(r.poses, ex, ey, gx, gy);
    if (i == 0) traj.line(gx, gy, "ground truth", cv::Scalar(0, 0, 0), 2);
    traj.line(ex, ey, labels[i], c, 2);
    auto binSeries = [&](Plot& p, const std::vector<DriftBin>& bins, bool rot) {
      std::vector<double> x, y;
      for (const auto& b : bins) {
        x.push_back(b.key);
        y.push_back(rot ? b.r_err_deg_per_m : b.t_err_pct);
      }
      Series s;
      s.x = x;
      s.y = y;
      s.label = labels[i];
      s.color = c;
      s.style = SeriesStyle::LinePoints;
      p.add(s);
    };
    binSeries(tlen, r.drift.by_length, false);
    binSeries(rlen, r.drift.by_length, true);
    binSeries(tspd, r.drift.by_speed, false);
    binSeries(rspd, r.drift.by_speed, true);
    std::vector<double> ft, fe;
    for (const auto& f : r.frames.frames) {
      ft.push_back(f.t - r.poses.t.front());
      fe.push_back(f.t_err);
    }
    Series s;
    s.x = ft;
    s.y = fe;
    s.label = labels[i];
    s.color = c;
    s.style = reports[i].frames.frames.size() > 60 ? SeriesStyle::Line : SeriesStyle::LinePoints;
    frames.add(s);
  }
  const cv::Mat fig = tile({traj.render(W, H), frames.render(W, H), tlen.render(W, H),
                            rlen.render(W, H), tspd.render(W, H), rspd.render(W, H)},
                           2);
  saveImage(fig, path);
}

nlohmann::json toJson(const EvaluationReport& r, const std::string& label, const std::string& file) {
  nlohmann::json j;
  j["label"] = label;
  j["file"] = file;
  j["poses"] = r.poses.t.size();
  j["dropped"] = r.poses.dropped;
  j["path_length_m"] = r.path_length;
  j["duration_s"] = r.duration;
  j["drift_valid"] = r.drift.valid;
  j["t_err_pct"] = r.drift.t_err_pct;
  j["r_err_deg_per_m"] = r.drift.r_err_deg_per_m;
  j["segments"] = r.drift.segments.size();
  for (const char* what : {"by_length", "by_speed"}) {
    auto& arr = j[what] = nlohmann::json::array();
    for (const auto& b : std::string(what) == "by_length" ? r.drift.by_length : r.drift.by_speed)
      arr.push_back({{"key", b.key}, {"t_err_pct", b.t_err_pct},
                     {"r_err_deg_per_m", b.r_err_deg_per_m}, {"count", b.count}});
  }
  j["final_error_m"] = r.final_error_m;
  j["frame_t_err_m_mean"] = r.frames.t_err_m.mean;
  j["frame_t_err_m_median"] = r.frames.t_err_m.median;
  j["frame_t_err_pct_mean"] = r.frames.t_err_pct.mean;
  j["frame_r_err_deg_mean"] = r.frames.r_err_deg.mean;
  j["frame_r_err_deg_median"] = r.frames.r_err_deg.median;
  auto& fr = j["frames"] = nlohmann::json::array();
  for (const auto& f : r.frames.frames)
    fr.push_back({{"t", f.t}, {"gt_step_m", f.gt_step}, {"est_step_m", f.est_step},
                  {"gt_dyaw_rad", f.gt_dyaw}, {"est_dyaw_rad", f.est_dyaw},
                  {"t_err_m", f.t_err}, {"r_err_rad", f.r_err}, {"t_err_pct", f.t_err_pct}});
  return j;
}

void run(EvalArgs& a) {
  if (!a.labels.empty() && a.labels.size() != a.est.size())
    throw std::runtime_error("--label given " + std::to_string(a.labels.size()) +
                             " times for " + std::to_string(a.est.size()) + " --est files");
  std::vector<std::string> labels = a.labels;
  if (labels.empty())
    for (const auto& e : a.est) labels.push_back(std::filesystem::path(e).stem().string());
  const std::vector<PoseRecord> gt = readGroundTruth(a.gt);
  KittiConfig kc;
  kc.step = a.step;
  std::vector<EvaluationReport> reports;
  nlohmann::json all = nlohmann::json::array();
  for (size_t i = 0; i < a.est.size(); ++i) {
    const PoseFile est = readPoseCsv(a.est[i]);
    EvaluationReport r;
    try {
      r = evaluateOdometry(est.poses, gt, kc);
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(a.est[i] + " vs " + a.gt + ": " + e.what());
    }
    std::cout << "== " << labels[i] << " (" << a.est[i] << ")\n"
              << formatReport(r, a.frames_listed);
    all.push_back(toJson(r, labels[i], a.est[i]));
    reports.push_back(std::move(r));
  }
  if (reports.size() > 1) {
    std::cout << "\n| method | translational error (%) | rotational error (deg/m) |\n"
                 "|---|---|---|\n";
    for (size_t i = 0; i < reports.size(); ++i) {
      char buf[160];
      if (reports[i].drift.valid)
        std::snprintf(buf, sizeof buf, "| %s | %.4f | %.4f |\n", labels[i].c_str(),
                      reports[i].drift.t_err_pct, reports[i].drift.r_err_deg_per_m);
      else
        std::snprintf(buf, sizeof buf, "| %s | n/a (< 100 m) | n/a |\n", labels[i].c_str());
      std::cout << buf;
    }
  }
  if (!a.json.empty()) {
    std::ofstream out(a.json);
    if (!out) throw std::runtime_error(a.json + ": cannot open for writing");
    out << all.dump(1) << "\n";
  }
  if (!a.plot.empty()) {
    savePlots(reports, labels, a.plot);
    std::cerr << "wrote " << a.plot << "\n";
  }
}

}  // namespace

SPINRADAR_COMMAND(
    "eval", "KITTI-style drift of odometry against ground truth, with plots", [](CLI::App& app) {
      auto a = std::make_shared<EvalArgs>();
      app.description(
          "Associates estimated and true poses by time (truth interpolated at the estimate's "
          "stamps) and reports KITTI-devkit drift (mean over 100..800 m subsequences: "
          "translational %, rotational deg/m), drift by path length and by speed, end-point "
          "error, and frame-to-frame errors (listed for short runs).");
      app.add_option("--est,-e", a->est,
                     "Odometry CSV (t,x,y,yaw[,vx,vy,wz]); repeat to compare several")
          ->required()
          ->check(CLI::ExistingFile);
      app.add_option("--label", a->labels, "Name of each --est in tables and plots");
      app.add_option("--gt,-g", a->gt,
                     "Ground truth: t,x,y,yaw CSV or the Oxford gt/radar_odometry.csv")
          ->required()
          ->check(CLI::ExistingFile);
      app.add_option("--plot", a->plot,
                     "PNG: trajectory vs truth, frame errors, drift vs length and vs speed");
      app.add_option("--json", a->json, "Write the figures as JSON");
      app.add_option("--step", a->step,
                     "First frames every N frames (KITTI devkit: 10; 4 = every second at 4 Hz)")
          ->check(CLI::PositiveNumber);
      app.add_option("--list-frames", a->frames_listed,
                     "List every frame-to-frame error when there are at most this many");
      app.callback([a] { run(*a); });
    });
