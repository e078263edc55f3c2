#include "spinradar/evaluation/evaluation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "spinradar/core/lie.hpp"

namespace spinradar {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRadToDeg = 180.0 / kPi;

double yawOf(const Eigen::Matrix3d& T) { return std::atan2(T(1, 0), T(0, 0)); }

/// SE(2) inverse without a general 3x3 inversion.
Eigen::Matrix3d inverseSE2(const Eigen::Matrix3d& T) {
  Eigen::Matrix3d inv = Eigen::Matrix3d::Identity();
  inv.topLeftCorner<2, 2>() = T.topLeftCorner<2, 2>().transpose();
  inv.topRightCorner<2, 1>() = -inv.topLeftCorner<2, 2>() * T.topRightCorner<2, 1>();
  return inv;
}

/// Devkit's rotationError is acos((trace(R) - 1) / 2); for a rotation about z that is |yaw|,
/// computed here with atan2, which keeps its precision for tiny angles.
double rotationError(const Eigen::Matrix3d& E) { return std::fabs(yawOf(E)); }

double translationError(const Eigen::Matrix3d& E) { return std::hypot(E(0, 2), E(1, 2)); }

/// Devkit's lastFrameFromSegmentLength: first frame whose distance exceeds start + len.
int lastFrameFromSegmentLength(const std::vector<double>& dist, int first, double len) {
  for (size_t i = first; i < dist.size(); ++i)
    if (dist[i] > dist[first] + len) return static_cast<int>(i);
  return -1;
}

}  // namespace

bool interpolatePose(const std::vector<PoseRecord>& traj, double t, PoseRecord& out, double tol) {
  if (traj.empty()) return false;
  if (t < traj.front().t - tol || t > traj.back().t + tol) return false;
  if (t <= traj.front().t) {
    out = traj.front();
    out.t = t;
    return true;
  }
  if (t >= traj.back().t) {
    out = traj.back();
    out.t = t;
    return true;
  }
  auto it = std::upper_bound(traj.begin(), traj.end(), t,
                             [](double v, const PoseRecord& p) { return v < p.t; });
  const PoseRecord& b = *it;
  const PoseRecord& a = *(it - 1);
  const double f = (t - a.t) / (b.t - a.t);
  out.t = t;
  out.x = a.x + f * (b.x - a.x);
  out.y = a.y + f * (b.y - a.y);
  out.yaw = se2::wrapAngle(a.yaw + f * se2::wrapAngle(b.yaw - a.yaw));
  out.vx = a.vx + f * (b.vx - a.vx);
  out.vy = a.vy + f * (b.vy - a.vy);
  out.wz = a.wz + f * (b.wz - a.wz);
  return true;
}

AssociatedPoses associatePoses(const std::vector<PoseRecord>& est,
                               const std::vector<PoseRecord>& gt, double tol) {
  AssociatedPoses a;
  for (const auto& e : est) {
    PoseRecord g;
    if (!interpolatePose(gt, e.t, g, tol)) {
      ++a.dropped;
      continue;
    }
    a.t.push_back(e.t);
    a.est.push_back(poseMatrix(e));
    a.gt.push_back(poseMatrix(g));
  }
  return a;
}

std::vector<double> pathDistances(const std::vector<Eigen::Matrix3d>& poses) {
  std::vector<double> dist;
  dist.reserve(poses.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    if (i == 0) {
      dist.push_back(0.0);
      continue;
    }
    const double dx = poses[i - 1](0, 2) - poses[i](0, 2);
    const double dy = poses[i - 1](1, 2) - poses[i](1, 2);
    dist.push_back(dist.back() + std::hypot(dx, dy));
  }
  return dist;
}

DriftResult kittiDrift(const std::vector<Eigen::Matrix3d>& gt,
                       const std::vector<Eigen::Matrix3d>& est, const std::vector<double>& t,
                       const KittiConfig& cfg, double frame_dt) {
  if (gt.size() != est.size())
    throw std::invalid_argument("kittiDrift: " + std::to_string(gt.size()) +
                                " ground-truth poses but " + std::to_string(est.size()) +
                                " estimated poses");
  if (!t.empty() && t.size() != gt.size())
    throw std::invalid_argument("kittiDrift: times and poses differ in count");
  if (cfg.step < 1) throw std::invalid_argument("kittiDrift: step must be >= 1");
  DriftResult r;
  const std::vector<double> dist = pathDistances(gt);
  const int n = static_cast<int>(gt.size());
  for (int first = 0; first < n; first += cfg.step) {
    for (double len : cfg.lengths) {
      const int last = lastFrameFromSegmentLength(dist, first, len);
      if (last < 0) continue;
      const Eigen::Matrix3d d_gt = inverseSE2(gt[first]) * gt[last];
      const Eigen::Matrix3d d_est = inverseSE2(est[first]) * est[last];
      const Eigen::Matrix3d E = inverseSE2(d_est) * d_gt;
      SegmentError s;
      s.first_frame = first;
      s.last_frame = last;
      s.length = len;
      s.t_err = translationError(E) / len;
      s.r_err = rotationError(E) / len;
      const double elapsed =
          t.empty() ? frame_dt * (last - first + 1) : std::max(t[last] - t[first], 1e-9);
      s.speed = len / elapsed;
      r.segments.push_back(s);
    }
  }
  if (r.segments.empty()) return r;
  r.valid = true;
  double te = 0, re = 0;
  for (const auto& s : r.segments) {
    te += s.t_err;
    re += s.r_err;
  }
  r.t_err_pct = 100.0 * te / r.segments.size();
  r.r_err_deg_per_m = kRadToDeg * re / r.segments.size();

  // Devkit's saveErrorPlots: per length |len - L| < 1, per speed |v - c| < 2, keep num > 2.5.
  // Mean errors of the segments whose `value` lies within `half_width` of `key`.
  const auto addBin = [&](double key, double half_width, double SegmentError::*value,
                          std::vector<DriftBin>& bins) {
    DriftBin b;
    b.key = key;
    for (const auto& s : r.segments)
      if (std::fabs(s.*value - key) < half_width) {
        b.t_err_pct += s.t_err;
        b.r_err_deg_per_m += s.r_err;
        ++b.count;
      }
    if (b.count >= cfg.min_segments_per_bin) {
      b.t_err_pct *= 100.0 / b.count;
      b.r_err_deg_per_m *= kRadToDeg / b.count;
      bins.push_back(b);
    }
  };
  for (double len : cfg.lengths) addBin(len, 1.0, &SegmentError::length, r.by_length);
  for (double c : cfg.speed_centres)
    addBin(c, cfg.speed_half_width, &SegmentError::speed, r.by_speed);
  return r;
}

ErrorStats errorStats(std::vector<double> v) {
  ErrorStats s;
  if (v.empty()) return s;
  double sum = 0, sq = 0;
  for (double x : v) {
    sum += x;
    sq += x * x;
    s.max = std::max(s.max, x);
  }
  s.mean = sum / v.size();
  s.rmse = std::sqrt(sq / v.size());
  const size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + m, v.end());
  s.median = v[m];
  if (v.size() % 2 == 0) s.median = 0.5 * (s.median + *std::max_element(v.begin(), v.begin() + m));
  return s;
}

RelativeErrors relativeFrameErrors(const AssociatedPoses& p) {
  RelativeErrors r;
  std::vector<double> te, re, tp;
  for (size_t k = 1; k < p.gt.size(); ++k) {
    const Eigen::Matrix3d d_gt = inverseSE2(p.gt[k - 1]) * p.gt[k];
    const Eigen::Matrix3d d_est = inverseSE2(p.est[k - 1]) * p.est[k];
    const Eigen::Matrix3d E = inverseSE2(d_est) * d_gt;
    FrameError f;
    f.t = p.t[k];
    f.gt_step = std::hypot(d_gt(0, 2), d_gt(1, 2));
    f.gt_dyaw = yawOf(d_gt);
    f.est_step = std::hypot(d_est(0, 2), d_est(1, 2));
    f.est_dyaw = yawOf(d_est);
    f.t_err = translationError(E);
    f.r_err = std::fabs(yawOf(E));
    f.t_err_pct = f.gt_step > 0.01 ? 100.0 * f.t_err / f.gt_step : 0.0;
    const double dt = p.t[k] - p.t[k - 1];
    f.speed = dt > 0 ? f.gt_step / dt : 0.0;
    r.frames.push_back(f);
    te.push_back(f.t_err);
    re.push_back(f.r_err * kRadToDeg);
    if (f.gt_step > 0.01) tp.push_back(f.t_err_pct);
  }
  r.t_err_m = errorStats(te);
  r.r_err_deg = errorStats(re);
  r.t_err_pct = errorStats(tp);
  return r;
}

EvaluationReport evaluateOdometry(const std::vector<PoseRecord>& est,
                                  const std::vector<PoseRecord>& gt, const KittiConfig& config) {
  EvaluationReport r;
  r.poses = associatePoses(est, gt);
  if (r.poses.t.size() < 2)
    throw std::runtime_error("evaluation: only " + std::to_string(r.poses.t.size()) +
                             " estimated pose(s) fall inside the ground truth's time span [" +
                             (gt.empty() ? std::string("empty") :
                              std::to_string(gt.front().t) + ", " + std::to_string(gt.back().t)) +
                             "] s (estimate spans " +
                             (est.empty() ? std::string("nothing") :
                              std::to_string(est.front().t) + " .. " + std::to_string(est.back().t)) +
                             " s): are both on the same clock?");
  r.drift = kittiDrift(r.poses.gt, r.poses.est, r.poses.t, config);
  r.frames = relativeFrameErrors(r.poses);
  const auto dist = pathDistances(r.poses.gt);
  r.path_length = dist.back();
  r.duration = r.poses.t.back() - r.poses.t.front();
  const Eigen::Matrix3d d_gt = inverseSE2(r.poses.gt.front()) * r.poses.gt.back();
  const Eigen::Matrix3d d_est = inverseSE2(r.poses.est.front()) * r.poses.est.back();
  r.final_error_m = std::hypot(d_gt(0, 2) - d_est(0, 2), d_gt(1, 2) - d_est(1, 2));
  r.final_error_pct = r.path_length > 0 ? 100.0 * r.final_error_m / r.path_length : 0.0;
  return r;
}

std::string formatReport(const EvaluationReport& r, int max_frames_listed) {
  std::ostringstream o;
  char buf[256];
  std::snprintf(buf, sizeof buf, "poses: %zu associated (%d outside the ground truth), %.1f m, %.1f s\n",
                r.poses.t.size(), r.poses.dropped, r.path_length, r.duration);
  o << buf;
  if (r.drift.valid) {
    std::snprintf(buf, sizeof buf,
                  "KITTI drift (%zu segments of 100..800 m): translational %.4f %%, rotational "
                  "%.5f deg/m\n",
                  r.drift.segments.size(), r.drift.t_err_pct, r.drift.r_err_deg_per_m);
    o << buf;
    o << "  by length:  length_m  t_err_%   r_err_deg/m  segments\n";
    for (const auto& b : r.drift.by_length) {
      std::snprintf(buf, sizeof buf, "              %6.0f  %8.4f  %11.5f  %8d\n", b.key,
                    b.t_err_pct, b.r_err_deg_per_m, b.count);
      o << buf;
    }
    o << "  by speed:   speed_m/s t_err_%   r_err_deg/m  segments\n";
    for (const auto& b : r.drift.by_speed) {
      std::snprintf(buf, sizeof buf, "              %6.0f  %8.4f  %11.5f  %8d\n", b.key,
                    b.t_err_pct, b.r_err_deg_per_m, b.count);
      o << buf;
    }
  } else {
    o << "KITTI drift: not available (ground-truth path shorter than 100 m)\n";
  }
  std::snprintf(buf, sizeof buf, "end-point error: %.3f m (%.3f %% of the path)\n",
                r.final_error_m, r.final_error_pct);
  o << buf;
  const auto& f = r.frames;
  std::snprintf(buf, sizeof buf,
                "frame-to-frame errors (%zu): translation mean %.4f m, median %.4f m, rmse %.4f m"
                " (mean %.3f %% of the step); rotation mean %.4f deg, median %.4f deg\n",
                f.frames.size(), f.t_err_m.mean, f.t_err_m.median, f.t_err_m.rmse,
                f.t_err_pct.mean, f.r_err_deg.mean, f.r_err_deg.median);
  o << buf;
  if (static_cast<int>(f.frames.size()) <= max_frames_listed) {
    o << "  t_s                 gt_step_m  est_step_m  gt_dyaw_deg  est_dyaw_deg  t_err_m  "
         "t_err_%  r_err_deg\n";
    for (const auto& e : f.frames) {
      std::snprintf(buf, sizeof buf,
                    "  %-18.6f  %9.4f  %10.4f  %11.4f  %12.4f  %7.4f  %7.3f  %9.4f\n", e.t,
                    e.gt_step, e.est_step, e.gt_dyaw * kRadToDeg, e.est_dyaw * kRadToDeg, e.t_err,
                    e.t_err_pct, e.r_err * kRadToDeg);
      o << buf;
    }
  }
  return o.str();
}

}  // namespace spinradar
