// `spinradar eval`: KITTI-style drift of odometry CSV(s) against ground truth, with plots.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <algorithm>
#include <map>
#include <memory>
#include <sstream>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <nlohmann/json.hpp>

#include "cli_checks.hpp"
#include "command.hpp"
#include "output_guard.hpp"
#include "spinradar/evaluation/evaluation.hpp"
#include "spinradar/core/lie.hpp"
#include "spinradar/evaluation/plot.hpp"

namespace {

using namespace spinradar;

struct EvalArgs {
  std::vector<std::string> est, labels;
  std::vector<std::string> cov;
  std::string gt, plot, json;
  std::vector<double> sensor_pose;  ///< x, y, yaw of the sensor in the truth's body frame
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

/// NEES e^T C^-1 e of a set of [x, y, yaw] errors: count, mean, median, share under the 95 %
/// chi2 bound of 3 degrees of freedom.
nlohmann::json neesSummary(std::vector<double> v) {
  nlohmann::json j = {{"n", v.size()}};
  if (v.empty()) return j;
  double sum = 0.0, covered = 0.0;
  for (double x : v) {
    sum += x;
    covered += x < 7.815;
  }
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  j["mean"] = sum / v.size();
  j["median"] = v[v.size() / 2];
  j["covered_pct"] = 100.0 * covered / v.size();
  return j;
}

double nees(const Eigen::Matrix3d& est, const Eigen::Matrix3d& truth, const Eigen::Matrix3d& C) {
  Eigen::Vector3d e = se2::toXyYaw(est) - se2::toXyYaw(truth);
  e(2) = se2::wrapAngle(e(2));
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(C);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) return -1.0;
  return e.dot(ldlt.solve(e));
}

/// Honesty of the covariances `spinradar odometry --covariance-out` wrote next to `est`:
/// NEES against the truth of the accumulated pose (relative to the first scan, as published)
/// and, for the keyframe estimator, of each scan's pose relative to its keyframe (what one
/// registration measures; independent between keyframes).
nlohmann::json covarianceNees(const std::string& path, const PoseFile& est,
                              const std::vector<PoseRecord>& gt) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::string line;
  std::getline(in, line);
  std::map<std::string, size_t> col;
  {
    std::stringstream ss(line);
    std::string name;
    for (size_t i = 0; std::getline(ss, name, ','); ++i) col[name] = i;
  }
  const char* need[] = {"t", "ok", "pose_xx", "pose_xy", "pose_xyaw", "pose_yy", "pose_yyaw",
                        "pose_yawyaw", "key_t", "key_x", "key_y", "key_yaw", "key_xx", "key_xy",
                        "key_xyaw", "key_yy", "key_yyaw", "key_yawyaw"};
  for (const char* n : need)
    if (!col.count(n))
      throw std::runtime_error(path + ": line 1: no column '" + n +
                               "' (expected the CSV of spinradar odometry --covariance-out)");
  auto cov3 = [](const std::vector<double>& v, size_t i) {
    Eigen::Matrix3d C;
    C << v[i], v[i + 1], v[i + 2], v[i + 1], v[i + 3], v[i + 4], v[i + 2], v[i + 4], v[i + 5];
    return C;
  };
  if (est.poses.empty()) return {};
  PoseRecord g0;
  const double t0 = est.poses.front().t;
  if (!interpolatePose(gt, t0, g0)) throw std::runtime_error(path + ": first scan outside the truth");
  const Eigen::Matrix3d Ei = se2::inverse(poseMatrix(est.poses.front()));
  const Eigen::Matrix3d Gi = se2::inverse(poseMatrix(g0));
  std::vector<double> pose_nees, key_nees;
  size_t k = 0;
  for (int lineno = 2; std::getline(in, line); ++lineno) {
    if (line.empty()) continue;
    std::vector<double> v;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) {
      try {
        v.push_back(std::stod(cell));
      } catch (const std::exception&) {
        throw std::runtime_error(path + ": line " + std::to_string(lineno) + ": '" + cell +
                                 "' is not a number");
      }
    }
    if (v.size() < col.size())
      throw std::runtime_error(path + ": line " + std::to_string(lineno) + ": " +
                               std::to_string(v.size()) + " columns, expected " +
                               std::to_string(col.size()));
    const double t = v[col["t"]];
    while (k < est.poses.size() && est.poses[k].t < t - 1e-6) ++k;
    if (k == est.poses.size() || std::abs(est.poses[k].t - t) > 1e-6)
      throw std::runtime_error(path + ": line " + std::to_string(lineno) + ": t = " +
                               std::to_string(t) + " is not a time of the odometry CSV");
    PoseRecord g, gk;
    if (v[col["ok"]] == 0.0 || !interpolatePose(gt, t, g)) continue;
    const Eigen::Matrix3d G = poseMatrix(g);
    const double pn = nees(Ei * poseMatrix(est.poses[k]), Gi * G, cov3(v, col["pose_xx"]));
    if (pn >= 0.0) pose_nees.push_back(pn);
    const double kt = v[col["key_t"]];
    if (kt > 0.0 && std::abs(kt - t) > 1e-6 && interpolatePose(gt, kt, gk)) {
      const Eigen::Matrix3d rel = poseMatrix(v[col["key_x"]], v[col["key_y"]], v[col["key_yaw"]]);
      const double kn = nees(rel, se2::inverse(poseMatrix(gk)) * G, cov3(v, col["key_xx"]));
      if (kn >= 0.0) key_nees.push_back(kn);
    }
  }
  return {{"pose", neesSummary(pose_nees)}, {"keyframe_relative", neesSummary(key_nees)}};
}

std::string formatNees(const nlohmann::json& j) {
  std::string out = "covariance honesty: NEES over [x, y, yaw] (expected 3; 95 % chi2 bound 7.815)\n";
  for (const auto& [key, name] : {std::pair<const char*, const char*>{"keyframe_relative",
                                                                      "pose relative to keyframe"},
                                  {"pose", "accumulated pose"}}) {
    const auto& s = j[key];
    char buf[200];
    if (s.value("n", 0) == 0)
      std::snprintf(buf, sizeof buf, "  %-26s none\n", name);
    else
      std::snprintf(buf, sizeof buf, "  %-26s %5d scans: mean %.2f, median %.2f, within bound %.1f %%\n",
                    name, s["n"].get<int>(), s["mean"].get<double>(), s["median"].get<double>(),
                    s["covered_pct"].get<double>());
    out += buf;
  }
  return out;
}

void run(EvalArgs& a) {
  if (!a.labels.empty() && a.labels.size() != a.est.size())
    throw std::runtime_error("--label given " + std::to_string(a.labels.size()) +
                             " times for " + std::to_string(a.est.size()) + " --est files");
  if (!a.cov.empty() && a.cov.size() != a.est.size())
    throw std::runtime_error("--covariance given " + std::to_string(a.cov.size()) +
                             " times for " + std::to_string(a.est.size()) + " --est files");
  // Outputs: never an input, checked (and --plot's image type) before any work.
  std::vector<NamedPath> inputs{{a.gt, "--gt"}};
  for (const auto& e : a.est) inputs.push_back({e, "--est"});
  for (const auto& c : a.cov) inputs.push_back({c, "--covariance"});
  cli::refuseOutputsOverInputs({{a.json, "--json"}, {a.plot, "--plot"}}, inputs);
  if (!a.plot.empty()) plot::checkImagePath(a.plot);
  std::vector<std::string> labels = a.labels;
  if (labels.empty())
    for (const auto& e : a.est) labels.push_back(std::filesystem::path(e).stem().string());
  std::vector<PoseRecord> gt = readGroundTruth(a.gt);
  if (!a.sensor_pose.empty()) gt = withSensorPose(gt, a.sensor_pose[0], a.sensor_pose[1], a.sensor_pose[2]);
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
    if (!a.cov.empty()) {
      const nlohmann::json n = covarianceNees(a.cov[i], est, gt);
      std::cout << formatNees(n);
      all.back()["nees"] = n;
    }
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
    AtomicOutputFile out(a.json);
    out.stream() << all.dump(1) << "\n";
    out.commit();
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
                     "Ground truth: t,x,y,yaw CSV, Oxford gt/radar_odometry.csv, Boreas "
                     "applanix/radar_poses.csv or MulRan global_pose.csv (told apart by content)")
          ->required()
          ->check(CLI::ExistingFile);
      app.add_option("--gt-sensor-pose", a->sensor_pose,
                     "x,y,yaw (m, m, rad): the radar's pose in the ground truth's body frame, "
                     "when the truth is of the vehicle (MulRan global_pose.csv)")
          ->expected(3)
          ->delimiter(',');
      app.add_option("--covariance", a->cov,
                     "CSV of spinradar odometry --covariance-out, one per --est: adds the NEES "
                     "of the published covariances against the truth")
          ->check(CLI::ExistingFile);
      app.add_option("--plot", a->plot,
                     "PNG: trajectory vs truth, frame errors, drift vs length and vs speed");
      app.add_option("--json", a->json, "Write the figures as JSON");
      app.add_option("--step", a->step,
                     "First frames every N frames (KITTI devkit: 10; 4 = every second at 4 Hz)")
          ->check(cli::atLeast(1));
      app.add_option("--list-frames", a->frames_listed,
                     "List every frame-to-frame error when there are at most this many")
          ->check(cli::atLeast(0));
      app.callback([a] { run(*a); });
    });
