#include "spinradar/localization/localizer.hpp"

#include <cmath>
#include <ctime>
#include <limits>
#include <stdexcept>

#include "spinradar/estimation/doppler.hpp"
#include "spinradar/evaluation/evaluation.hpp"
#include "spinradar/core/lie.hpp"
#include "spinradar/core/param_check.hpp"
#include "spinradar/io/scan_folder.hpp"
#include "spinradar/estimation/undistort.hpp"

namespace spinradar {

void LocalizerConfig::validate() const {
  checkParamRanges(*this, "localizer");
  checkOneOf(compensation, {"none", "motion", "motion_doppler"}, "compensation");
}

Compensation parseCompensation(const std::string& name) {
  if (name == "none") return Compensation::None;
  if (name == "motion") return Compensation::Motion;
  if (name == "motion_doppler") return Compensation::MotionDoppler;
  throw std::invalid_argument("compensation '" + name +
                              "' is not one of: none, motion, motion_doppler");
}

const char* compensationName(Compensation c) {
  switch (c) {
    case Compensation::None: return "none";
    case Compensation::Motion: return "motion";
    case Compensation::MotionDoppler: return "motion_doppler";
  }
  return "?";
}

double threadCpuMs() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

namespace {

EstimatorConfig rigidConfig(const EstimatorConfig& base, const LocalizerConfig& c) {
  EstimatorConfig e = base;
  e.ransac_iterations = c.loc_ransac_iterations;
  e.inlier_threshold = c.loc_inlier_threshold;
  return e;
}

int64_t referenceStamp(const PolarScan& scan) {
  for (int a = 0; a < scan.azimuths && a < static_cast<int>(scan.stamp_ns.size()); ++a)
    if (scan.valid.empty() || scan.valid[a]) return scan.stamp_ns[a];
  return scan.firstStamp();
}

}  // namespace

Localizer::Localizer(const LocalizerConfig& config, const RsdConfig& rsd,
                     const PipelineConfig& pipeline)
    : config_(config), rsd_config_(rsd), pipeline_(pipeline), detector_(pipeline.detector),
      rsd_(rsd), mc_(pipeline.estimator), rigid_(rigidConfig(pipeline.estimator, config)) {
  config_.validate();
  pipeline_.validate();
}

void Localizer::setConfig(const LocalizerConfig& config) {
  config.validate();
  config_ = config;
  rigid_.setConfig(rigidConfig(pipeline_.estimator, config_));
}

// ---- Preparation ---------------------------------------------------------------------------

void Localizer::prepare(const PolarScan& scan, LocFrame& out, double* rsd_ms) {
  detector_.detect(scan, out.keypoints);
  out.stamp_ns = referenceStamp(scan);
  out.has_velocity = false;
  out.velocity_mc.setZero();
  out.velocity_doppler.setZero();
  const double t0 = threadCpuMs();
  rsd_.compute(out.keypoints, out.rsd);
  if (rsd_ms) *rsd_ms = threadCpuMs() - t0;
}

bool Localizer::estimateVelocity(const LocFrame& a, const LocFrame& b,
                                 Eigen::Vector3d& velocity_mc, Eigen::Vector3d& velocity_doppler) {
  const double gap = 1e-9 * static_cast<double>(b.stamp_ns - a.stamp_ns);
  if (!(gap > 0.0) || gap > config_.loc_max_velocity_gap) return false;
  // Consecutive scans of one drive look alike: the odometry's own ratio.
  matcher_.match(a.rsd, b.rsd, pipeline_.features.nndr, matches_);
  if (!mc_.estimate(a.keypoints, b.keypoints, matches_, a.stamp_ns, b.stamp_ns, est_))
    return false;
  if (static_cast<int>(est_.inliers.size()) < config_.loc_min_inliers) return false;
  velocity_mc = est_.velocity;
  if (!estimateMcDoppler(mc_, a.keypoints, b.keypoints, matches_, a.stamp_ns, b.stamp_ns,
                         pipeline_.estimator.beta, kc_a_, kc_b_, est_))
    return false;
  velocity_doppler = est_.velocity;
  return velocity_mc.allFinite() && velocity_doppler.allFinite();
}

bool Localizer::setVelocity(LocFrame& f, const LocFrame* prev, const LocFrame* next) {
  Eigen::Vector3d vm, vd;
  f.has_velocity = (next && estimateVelocity(f, *next, vm, vd)) ||
                   (prev && estimateVelocity(*prev, f, vm, vd));
  if (f.has_velocity) {
    f.velocity_mc = vm;
    f.velocity_doppler = vd;
  }
  return f.has_velocity;
}

// ---- Map -----------------------------------------------------------------------------------

int Localizer::loadMap(const std::string& scan_dir, const std::string& poses_csv,
                       const std::function<void(size_t, size_t)>& progress) {
  ScanFolder folder(scan_dir);
  const std::vector<PoseRecord> poses = readPoseCsv(poses_csv).poses;
  if (poses.size() < 2) throw std::runtime_error(poses_csv + ": fewer than 2 map poses");
  std::vector<LocFrame> frames;
  frames.reserve(folder.size());
  // File stamps are within a rotation of the reference time: skip scans clearly outside the
  // poses before paying for their detection.
  const double t_lo = poses.front().t - 1.0, t_hi = poses.back().t + 1.0;
  for (size_t i = 0; i < folder.size(); ++i) {
    if (progress) progress(i, folder.size());
    const double t_file = 1e-9 * static_cast<double>(folder.fileStampNs(i));
    if (t_file < t_lo || t_file > t_hi) continue;
    LocFrame f;
    prepare(folder.load(i), f);
    PoseRecord p;
    if (!interpolatePose(poses, 1e-9 * static_cast<double>(f.stamp_ns), p)) continue;
    f.T_map_sensor = poseMatrix(p);
    frames.push_back(std::move(f));
  }
  if (frames.empty())
    throw std::runtime_error(poses_csv + ": no scan of " + scan_dir +
                             " lies within the time span of the map poses");
  for (size_t k = 0; k < frames.size(); ++k) {
    if (setVelocity(frames[k], k > 0 ? &frames[k - 1] : nullptr,
                    k + 1 < frames.size() ? &frames[k + 1] : nullptr))
      continue;
    // Radar odometry failed here: fall back on the map poses' own motion over one rotation.
    const double t = 1e-9 * static_cast<double>(frames[k].stamp_ns), dt = 0.25;
    PoseRecord a, b;
    if (interpolatePose(poses, t, a) && interpolatePose(poses, t + dt, b)) {
      const Eigen::Vector3d v = se2::log(se2::inverse(poseMatrix(a)) * poseMatrix(b)) / dt;
      frames[k].velocity_mc = frames[k].velocity_doppler = v;
      frames[k].has_velocity = true;
    }
  }
  for (auto& f : frames) map_.push_back(std::move(f));
  if (progress) progress(folder.size(), folder.size());
  return static_cast<int>(map_.size());
}

void Localizer::addMapFrame(LocFrame frame) { map_.push_back(std::move(frame)); }

void Localizer::clearMap() { map_.clear(); }

int Localizer::nearestMapFrame(const Eigen::Vector2d& p) const {
  int best = -1;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < map_.size(); ++i) {
    const double d2 = (map_[i].T_map_sensor.topRightCorner<2, 1>() - p).squaredNorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      best = static_cast<int>(i);
    }
  }
  return best;
}

// ---- Localization --------------------------------------------------------------------------

void Localizer::compensate(const LocFrame& f, Compensation c, std::vector<Eigen::Vector2d>& out) {
  if (c == Compensation::None || !f.has_velocity) {
    out.resize(f.keypoints.size());
    for (size_t i = 0; i < f.keypoints.size(); ++i) out[i] = {f.keypoints[i].x, f.keypoints[i].y};
  } else if (c == Compensation::Motion) {
    undistortPoints(f.keypoints, f.velocity_mc, f.stamp_ns, out);
  } else {
    // Doppler first: the shift lies along the beam at acquisition time.
    dopplerCorrect(f.keypoints, f.velocity_doppler, pipeline_.estimator.beta, kd_);
    undistortPoints(kd_, f.velocity_doppler, f.stamp_ns, out);
  }
}

LocalizationResult Localizer::localize(const LocFrame& live, const Eigen::Matrix3d& T_map_prior,
                                       Compensation compensation) {
  const int idx = nearestMapFrame(T_map_prior.topRightCorner<2, 1>());
  if (idx >= 0 && (map_[idx].T_map_sensor.topRightCorner<2, 1>() -
                   T_map_prior.topRightCorner<2, 1>()).norm() > config_.loc_max_map_distance) {
    LocalizationResult r;
    r.stamp_ns = live.stamp_ns;
    r.T_map_prior = r.T_map_sensor = T_map_prior;
    r.reason = "no map scan within loc_max_map_distance of the prior";
    return r;
  }
  return localizeAgainst(live, idx, T_map_prior, compensation);
}

LocalizationResult Localizer::localizeAgainst(const LocFrame& live, int map_index,
                                              const Eigen::Matrix3d& T_map_prior,
                                              Compensation compensation) {
  LocalizationResult r;
  r.stamp_ns = live.stamp_ns;
  r.T_map_prior = r.T_map_sensor = T_map_prior;
  r.map_index = map_index;
  if (map_index < 0 || map_index >= static_cast<int>(map_.size())) {
    r.reason = "no map";
    return r;
  }
  const LocFrame& map = map_[map_index];
  r.velocity_known = compensation == Compensation::None || (live.has_velocity && map.has_velocity);

  // 1. Descriptor matches (map keypoint i1, live keypoint i2), optionally gated by the prior.
  double t0 = threadCpuMs();
  const Eigen::Matrix3d T_ms_prior = se2::inverse(map.T_map_sensor) * T_map_prior;
  if (config_.loc_match_gate > 0.0) {
    gate_m_.resize(map.keypoints.size());
    for (size_t i = 0; i < map.keypoints.size(); ++i) gate_m_[i] = {map.keypoints[i].x, map.keypoints[i].y};
    gate_l_.resize(live.keypoints.size());
    const Eigen::Matrix2d C = T_ms_prior.topLeftCorner<2, 2>();
    const Eigen::Vector2d t = T_ms_prior.topRightCorner<2, 1>();
    for (size_t i = 0; i < live.keypoints.size(); ++i)
      gate_l_[i] = C * Eigen::Vector2d(live.keypoints[i].x, live.keypoints[i].y) + t;
    matcher_.match(map.rsd, live.rsd, config_.loc_nndr, matches_, gate_m_.data(), gate_l_.data(),
                   config_.loc_match_gate);
  } else {
    matcher_.match(map.rsd, live.rsd, config_.loc_nndr, matches_);
  }
  r.matches = static_cast<int>(matches_.size());
  double t1 = threadCpuMs();
  r.match_ms = t1 - t0;

  // 2. Each scan compensated with its own velocity, then rigid RANSAC: p_map = T p_live.
  compensate(map, compensation, pm_);
  compensate(live, compensation, pl_);
  std::vector<Eigen::Vector2d>& a = gate_m_;
  std::vector<Eigen::Vector2d>& b = gate_l_;
  a.resize(matches_.size());
  b.resize(matches_.size());
  for (size_t k = 0; k < matches_.size(); ++k) {
    a[k] = pm_[matches_[k].i1];
    b[k] = pl_[matches_[k].i2];
  }
  const bool ok = rigid_.estimate(a, b, 1.0, est_);
  r.ransac_ms = threadCpuMs() - t1;
  r.inliers = ok ? static_cast<int>(est_.inliers.size()) : 0;
  if (!ok || r.inliers < config_.loc_min_inliers) {
    r.reason = "too few RANSAC inliers (" + std::to_string(r.inliers) + " of " +
               std::to_string(r.matches) + " matches)";
    return r;
  }
  r.ok = true;
  r.T_mapscan_sensor = est_.T_12;
  r.cov = est_.T_12_cov;
  r.T_map_sensor = map.T_map_sensor * est_.T_12;
  return r;
}

bool Localizer::checkAgainstPrior(LocalizationResult& r) const {
  if (!r.ok) return false;
  const Eigen::Vector3d d = se2::toXyYaw(se2::inverse(r.T_map_prior) * r.T_map_sensor);
  if (d.head<2>().norm() <= config_.loc_track_max_offset && std::abs(d(2)) <= config_.loc_track_max_yaw)
    return true;
  r.ok = false;
  r.reason = "estimate too far from the prior (" + std::to_string(d.head<2>().norm()) + " m, " +
             std::to_string(d(2)) + " rad)";
  r.T_map_sensor = r.T_map_prior;
  return false;
}

LocalizationResult Localizer::globalLocalize(const LocFrame& live, Compensation compensation,
                                             int stride) {
  LocalizationResult best;
  best.stamp_ns = live.stamp_ns;
  best.reason = "no map";
  const double gate = config_.loc_match_gate;
  config_.loc_match_gate = 0.0;  // no prior to gate with
  for (size_t i = 0; i < map_.size(); i += std::max(stride, 1)) {
    LocalizationResult r = localizeAgainst(live, static_cast<int>(i), map_[i].T_map_sensor,
                                           compensation);
    if (r.inliers > best.inliers || best.map_index < 0) best = r;
  }
  config_.loc_match_gate = gate;
  if (best.ok) best.T_map_prior = best.T_map_sensor;
  return best;
}

// ---- Online tracking -----------------------------------------------------------------------

void Localizer::setInitialPose(const Eigen::Matrix3d& T_map_sensor) {
  T_initial_ = T_map_sensor;
  have_initial_ = true;
  have_last_ = false;
}

void Localizer::resetTracking() {
  have_last_ = have_initial_ = false;
  prev_live_ = LocFrame{};
  cur_live_ = LocFrame{};
  last_stamp_ = 0;
}

LocalizationResult Localizer::process(const PolarScan& scan, const Eigen::Vector3d* velocity) {
  const bool have_prev = !cur_live_.keypoints.empty() || cur_live_.stamp_ns != 0;
  std::swap(prev_live_, cur_live_);  // reuse the older frame's buffers
  prepare(scan, cur_live_);
  if (velocity) {
    cur_live_.velocity_mc = cur_live_.velocity_doppler = *velocity;
    cur_live_.has_velocity = true;
  } else if (have_prev) {
    setVelocity(cur_live_, &prev_live_, nullptr);
  }
  const Compensation comp = parseCompensation(config_.compensation);
  LocalizationResult r;
  if (have_last_) {
    const double dt = 1e-9 * static_cast<double>(cur_live_.stamp_ns - last_stamp_);
    const Eigen::Vector3d v =
        cur_live_.has_velocity ? cur_live_.velocity_doppler : Eigen::Vector3d::Zero();
    r = localize(cur_live_, T_last_ * se2::exp(dt * v), comp);
    checkAgainstPrior(r);
  } else if (have_initial_) {
    r = localize(cur_live_, T_initial_, comp);
    checkAgainstPrior(r);
  } else {
    r = globalLocalize(cur_live_, comp);
  }
  if (r.ok || have_last_ || have_initial_) {
    T_last_ = r.T_map_sensor;  // the estimate, or the prediction when it failed
    have_last_ = true;
    last_stamp_ = cur_live_.stamp_ns;
  }
  return r;
}

}  // namespace spinradar
