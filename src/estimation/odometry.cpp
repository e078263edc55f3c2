// Frame-to-frame odometry: match each scan to the previous one, estimate the motion with the
// configured estimator, compound the poses.
#include "spinradar/estimation/odometry.hpp"

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "spinradar/estimation/azimuth_times.hpp"
#include "spinradar/estimation/doppler.hpp"
#include "spinradar/features/feature_extractor.hpp"
#include "spinradar/estimation/keyframe_tracker.hpp"
#include "spinradar/core/lie.hpp"
#include "spinradar/features/matcher.hpp"
#include "spinradar/estimation/mc_ransac.hpp"
#include "spinradar/estimation/pair_recovery.hpp"
#include "spinradar/estimation/refined_estimator.hpp"
#include "spinradar/estimation/rigid_ransac.hpp"
#include "spinradar/estimation/surface_tracker.hpp"
#include "spinradar/estimation/undistort.hpp"

namespace spinradar {

namespace {

enum class Estimator { kRigid, kMc, kMcDoppler, kRefined, kKeyframe, kSurface };

Estimator parseEstimator(const std::string& name) {
  if (name == "rigid") return Estimator::kRigid;
  if (name == "mc") return Estimator::kMc;
  if (name == "mc_doppler") return Estimator::kMcDoppler;
  if (name == "refined") return Estimator::kRefined;
  if (name == "keyframe") return Estimator::kKeyframe;
  if (name == "surface") return Estimator::kSurface;
  throw std::invalid_argument("parameter 'estimator': unknown value '" + name + "'");
}

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

/// A feature frame whose descriptor rows live in a growing storage matrix, so copying a
/// frame in does not allocate once the storage is large enough.
struct FrameBuffer {
  FeatureFrame frame;
  cv::Mat storage;

  void copyFrom(const FeatureFrame& src) {
    frame.stamp_ns = src.stamp_ns;
    frame.period_ns = src.period_ns;
    frame.keypoints.assign(src.keypoints.begin(), src.keypoints.end());
    const cv::Mat& d = src.descriptors;
    if (d.empty()) {
      frame.descriptors = cv::Mat();
      return;
    }
    if (storage.rows < d.rows || storage.cols != d.cols || storage.type() != d.type())
      storage.create(std::max(d.rows + d.rows / 2, 64), d.cols, d.type());
    frame.descriptors = storage.rowRange(0, d.rows);
    d.copyTo(frame.descriptors);  // same size and type: writes into the view
  }
};

}  // namespace

struct Odometry::Impl {
  PipelineConfig config;
  Estimator estimator = Estimator::kMcDoppler;
  bool config_dirty = false;  ///< setConfig() called: apply before the next scan
  std::unique_ptr<FeatureExtractor> extractor;  ///< created on the first polar scan
  RigidRansac rigid;
  McRansac mc;
  RefinedEstimator refined;
  KeyframeTracker keyframe;  ///< on top of refined for the keyframe estimator
  SurfaceTracker surface;    ///< on top of keyframe for the surface estimator
  PairRecovery recovery;     ///< refined chain: pairs the descriptors could not match
  /// surface: the keyframe tracker's own chain (its steps are the surface stage's prediction)
  Eigen::Matrix3d T_kf = Eigen::Matrix3d::Identity(), P_kf = Eigen::Matrix3d::Zero();

  FrameBuffer prev, cur;
  bool has_prev = false;
  std::vector<Match> matches;
  std::vector<Keypoint> corr1, corr2;  ///< Doppler-corrected keypoints of prev / cur
  std::vector<Eigen::Vector2d> corrected, raw;

  Eigen::Matrix3d T_world = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d pose_cov = Eigen::Matrix3d::Zero();
  MotionEstimate last;  ///< last successful estimate (for a failed scan's prediction)
  bool has_last = false;
  int64_t period_ns = 0;  ///< shortest interval between scans seen (the scan period)

  explicit Impl(const PipelineConfig& c) { apply(c); }

  void apply(const PipelineConfig& c) {
    c.validate();
    const bool features_changed = extractor && !sameFeatureConfig(config, c);
    config = c;
    const Estimator next = parseEstimator(c.estimator.estimator);
    if (next != estimator) {  // keyframe chains are stale after a switch
      keyframe.reset();
      surface.reset();
      T_kf = T_world;
      P_kf = pose_cov;
    }
    estimator = next;
    rigid.setConfig(c.estimator);
    mc.setConfig(c.estimator);
    refined.setConfig(c.estimator);
    keyframe.setConfig(c.estimator);
    surface.setConfig(c.estimator);
    recovery.setConfig(c.estimator);
    if (features_changed) extractor.reset();  // rebuilt with the new settings on demand
  }

  static bool sameFeatureConfig(const PipelineConfig& a, const PipelineConfig& b) {
    bool same = true;
    auto cmp = [&](const auto& x, const auto& y) {
      std::vector<std::string> va, vb;
      x.visit([&](const ParamMeta&, const auto& v) { va.push_back(toString(v)); });
      y.visit([&](const ParamMeta&, const auto& v) { vb.push_back(toString(v)); });
      same = same && va == vb;
    };
    cmp(a.detector, b.detector);
    cmp(a.features, b.features);
    return same;
  }
  template <class T>
  static std::string toString(const T& v) {
    if constexpr (std::is_same_v<T, std::string>) return v;
    else return std::to_string(v);
  }

  void reset() {
    has_prev = false;
    has_last = false;
    T_world.setIdentity();
    pose_cov.setZero();
    refined.reset();
    keyframe.reset();
    surface.reset();
    T_kf.setIdentity();
    P_kf.setZero();
    corrected.clear();
    raw.clear();
  }

  bool estimate(MotionEstimate& m) {
    const FeatureFrame& a = prev.frame;
    const FeatureFrame& b = cur.frame;
    switch (estimator) {
      case Estimator::kRigid:
        return rigid.estimate(a.keypoints, b.keypoints, matches, a.stamp_ns, b.stamp_ns, m);
      case Estimator::kMc:
        return mc.estimate(a.keypoints, b.keypoints, matches, a.stamp_ns, b.stamp_ns, m);
      case Estimator::kMcDoppler:
        return estimateMcDoppler(mc, a.keypoints, b.keypoints, matches, a.stamp_ns, b.stamp_ns,
                                 config.estimator.beta, corr1, corr2, m);
      case Estimator::kRefined:
      case Estimator::kKeyframe:
      case Estimator::kSurface:
        return refined.estimate(a, b, matches, corr1, corr2, m);
    }
    return false;
  }

  bool usesRefinedChain() const {
    return estimator == Estimator::kRefined || estimator == Estimator::kKeyframe ||
           estimator == Estimator::kSurface;
  }

  /// Time going backwards, or a gap of several scan periods, starts a new segment: nothing is
  /// matched or extrapolated across it, the pose is kept (tf stays continuous) and the motion
  /// that may have happened meanwhile (last speed plus a margin, over the gap, or over one
  /// period when time went back) goes into its covariance.
  void checkTime(OdometryResult& res) {
    using TimeEvent = OdometryResult::TimeEvent;
    const int64_t dt_ns = cur.frame.stamp_ns - prev.frame.stamp_ns;
    if (dt_ns > 0 && !(period_ns > 0 && double(dt_ns) > Odometry::kGapPeriods * double(period_ns))) {
      period_ns = period_ns > 0 ? std::min(period_ns, dt_ns) : dt_ns;
      return;
    }
    res.time_event = dt_ns > 0 ? TimeEvent::Gap : TimeEvent::Backwards;
    res.time_step_s = 1e-9 * static_cast<double>(dt_ns);
    const double lost_s = 1e-9 * static_cast<double>(dt_ns > 0 ? dt_ns : period_ns);
    const Eigen::Vector3d v = has_last ? last.velocity : Eigen::Vector3d::Zero();
    const double s_xy = (std::hypot(v(0), v(1)) + 1.0) * lost_s;   // + 1 m/s
    const double s_yaw = (std::abs(v(2)) + 0.1) * lost_s;          // + 0.1 rad/s
    pose_cov.diagonal() += Eigen::Vector3d(s_xy * s_xy, s_xy * s_xy, s_yaw * s_yaw);
    has_prev = false;
    has_last = false;
    refined.reset();
    keyframe.reset();
    surface.reset();
  }

  /// Estimation and compounding on cur (prev is the previous scan, when there is one).
  void step(StageTimes times, OdometryResult& res) {
    std::vector<int> inliers;  // keeps the caller's buffer: no allocation once it has grown
    inliers.swap(res.motion.inliers);
    res = OdometryResult{};
    inliers.clear();
    res.motion.inliers.swap(inliers);
    res.stamp_ns = cur.frame.stamp_ns;
    if (has_prev) checkTime(res);
    const std::vector<Keypoint>& kps = cur.frame.keypoints;
    raw.resize(kps.size());
    for (size_t i = 0; i < kps.size(); ++i) raw[i] = {kps[i].x, kps[i].y};

    bool have_velocity = false;
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    bool doppler = false;
    if (has_prev) {
      auto t0 = std::chrono::steady_clock::now();
      matchDescriptors(prev.frame.descriptors, cur.frame.descriptors,
                       config.features.nndr, matches);
      times.match_ms = msSince(t0);
      t0 = std::chrono::steady_clock::now();
      MotionEstimate& m = res.motion;
      bool ok = estimate(m);
      // Descriptors failed (a turn faster than upright ORB follows, see pair_recovery.hpp),
      // or "succeeded" on a handful of chance matches: register the scan to the previous
      // one's points around the last velocity instead. A pair with fewer than
      // kMinPairInliers inliers is no registration: at the eased U-turn of out_and_back
      // (21 deg per scan) MC-RANSAC returned 9 deg on 3 inliers, and the refined chain came
      // out 12 deg off (keyframe 8.0 % -> 1.2 %, refined 6.4 -> 1.1 %, surface 8.3 -> 1.5 %;
      // no other column moved). Not for weak pairs: with < 10 / < 20 the peaks rows lost
      // (out_and_back_v2 0.14 -> 0.17-0.18 %) as the point registration replaced good pairs.
      if ((!ok || static_cast<int>(m.inliers.size()) < PairRecovery::kMinPairInliers) && has_last &&
          usesRefinedChain()) {
        MotionEstimate r;
        if (recovery.estimate(prev.frame, cur.frame, last.velocity, r)) {
          m = r;
          ok = true;
          refined.reset();  // its next pair has no previous one to interpolate with
          dopplerCorrect(cur.frame.keypoints, m.velocity, config.estimator.beta, corr2);
        }
      }
      keyframe.offerPairMatches(prev.frame.stamp_ns, cur.frame.stamp_ns, config.features.nndr,
                                matches);
      if (ok && estimator == Estimator::kKeyframe) {
        Eigen::Matrix3d T_new, P_new;
        keyframe.track(cur.frame, T_world, pose_cov, config.features.nndr, m, T_new, P_new);
        setPose(T_new, P_new);
        res.keyframe_stamp_ns = keyframe.keyframeStamp();
        res.T_keyframe_sensor = keyframe.relativePose();
        res.keyframe_cov = keyframe.relativeCov();
        dopplerCorrect(cur.frame.keypoints, m.velocity, config.estimator.beta, corr2);
      } else if (ok && estimator == Estimator::kSurface) {
        trackSurface(m, 1e-9 * static_cast<double>(cur.frame.stamp_ns - prev.frame.stamp_ns));
        res.keyframe_stamp_ns = surface.keyframeStamp();
        res.T_keyframe_sensor = surface.relativePose();
        res.keyframe_cov = surface.relativeCov();
        dopplerCorrect(cur.frame.keypoints, m.velocity, config.estimator.beta, corr2);
      } else if (!ok) {
        keyframe.reset();  // the prediction below is not tied to the keyframe
      }
      times.estimate_ms = msSince(t0);
      const double dt_ref = 1e-9 * static_cast<double>(cur.frame.stamp_ns - prev.frame.stamp_ns);
      if (ok) {
        if (estimator == Estimator::kRefined || estimator == Estimator::kKeyframe ||
            estimator == Estimator::kSurface) {
          // Published covariance (NEES on the city route): the refined step and velocity
          // assume a constant velocity over the pair; add what acceleration over the step
          // leaves out, the same model the keyframe estimator puts on this step as its prior.
          // Covariance only: the pose and the estimate are unchanged. (For keyframe: the
          // refined pair's step and velocity, the latter published, see keyframe_tracker.cpp.)
          const Eigen::Vector3d q = KeyframeTracker::stepModelNoise(dt_ref);
          m.T_12_cov.diagonal() += q;
          const double h = 0.5 * dt_ref;  // the velocity stands for the step's centre
          m.velocity_cov.diagonal() +=
              Eigen::Vector3d(KeyframeTracker::kStepAccelSigma * h, KeyframeTracker::kStepAccelSigma * h,
                              KeyframeTracker::kStepAngAccelSigma * h).cwiseAbs2();
        }
        if (estimator != Estimator::kKeyframe && estimator != Estimator::kSurface)
          compound(m.T_12, m.T_12_cov);
        last = m;
        has_last = true;
        res.ok = true;
        doppler = estimator == Estimator::kMcDoppler || estimator == Estimator::kRefined ||
                  estimator == Estimator::kKeyframe || estimator == Estimator::kSurface;
      } else if (has_last && dt_ref > 0.0) {
        // Estimation failed (too few matches, degenerate geometry): predict with the last
        // velocity so the trajectory stays continuous; res.ok = false reports the failure.
        const int n_matches = m.matches;
        m = last;
        m.ok = false;
        m.matches = n_matches;
        m.inliers.clear();
        setMotionFromVelocity(last.velocity, last.velocity_cov, dt_ref, m);
        compound(m.T_12, m.T_12_cov);
        T_kf = T_kf * m.T_12;
      }
      velocity = m.velocity;
      have_velocity = ok || (has_last && dt_ref > 0.0);
    }
    // Corrected points: Doppler-corrected keypoints (if this estimator corrects) moved to
    // the scan's reference time with the estimated velocity.
    const std::vector<Keypoint>& src = doppler ? corr2 : kps;
    if (have_velocity) {
      undistortPoints(src, velocity, cur.frame.stamp_ns, corrected);
    } else {
      corrected.assign(raw.begin(), raw.end());
    }
    res.T_world_sensor = T_world;
    res.pose_cov = pose_cov;
    res.times = times;
    std::swap(prev, cur);
    has_prev = true;
  }

  /// surface: the keyframe estimator on its own chain gives the predicted step (m.T_12 on
  /// entry: the refined pair's), the surface stage registers the scan; m.T_12 becomes the
  /// step taken. dt: scan period.
  void trackSurface(MotionEstimate& m, double dt) {
    Eigen::Matrix3d T_k, P_k;
    keyframe.track(cur.frame, T_kf, P_kf, config.features.nndr, m, T_k, P_k);
    T_kf = T_k;
    P_kf = P_k;
    // The refined pair's covariance (+ what acceleration leaves out) bounds the step's.
    Eigen::Matrix3d C = m.T_12_cov;
    C.diagonal() += KeyframeTracker::stepModelNoise(dt);
    Eigen::Matrix3d T_new, P_new;
    surface.track(cur.frame, m.velocity, T_world, pose_cov, m.T_12, C, T_new, P_new);
    m.T_12 = se2::inverse(T_world) * T_new;
    setPose(T_new, P_new);
  }

  /// T_world <- T_world T_12 with first-order propagation over [x, y, yaw] (se2::compoundXyYaw):
  /// p' = p + R(yaw) t, yaw' = yaw + dyaw.
  void compound(const Eigen::Matrix3d& T_12, const Eigen::Matrix3d& cov_12) {
    Eigen::Matrix3d T, P;
    se2::compoundXyYaw(T_world, pose_cov, T_12, cov_12, T, P);
    setPose(T, P);
  }

  void setPose(const Eigen::Matrix3d& T, const Eigen::Matrix3d& P) {
    T_world = T;
    pose_cov = P;
    // Re-orthonormalise the rotation against round-off over long runs.
    const double yaw = std::atan2(T_world(1, 0), T_world(0, 0));
    T_world.topLeftCorner<2, 2>() << std::cos(yaw), -std::sin(yaw), std::sin(yaw), std::cos(yaw);
  }
};

Odometry::Odometry(const PipelineConfig& config) : impl_(std::make_unique<Impl>(config)) {}
Odometry::~Odometry() = default;
Odometry::Odometry(Odometry&&) noexcept = default;
Odometry& Odometry::operator=(Odometry&&) noexcept = default;

OdometryResult Odometry::process(const PolarScan& scan) {
  OdometryResult res;
  process(scan, res);
  return res;
}

void Odometry::process(const PolarScan& scan, OdometryResult& out) {
  Impl& d = *impl_;
  if (!d.extractor)
    d.extractor = std::make_unique<FeatureExtractor>(d.config.detector, d.config.features);
  StageTimes times;
  extractFeatures(d.config, *d.extractor, scan, d.cur.frame, &times);
  d.step(times, out);
}

void Odometry::extractFeatures(const PipelineConfig& config, FeatureExtractor& extractor,
                               const PolarScan& scan, FeatureFrame& out, StageTimes* times) {
  extractor.extract(scan, out, times);
  if (config.estimator.azimuth_times == "uniform") uniformKeypointTimes(scan, out.keypoints);
}

OdometryResult Odometry::process(const FeatureFrame& frame, const StageTimes& times) {
  OdometryResult res;
  process(frame, times, res);
  return res;
}

void Odometry::process(const FeatureFrame& frame, const StageTimes& times, OdometryResult& out) {
  Impl& d = *impl_;
  d.cur.copyFrom(frame);
  d.step(times, out);
}

const std::vector<Eigen::Vector2d>& Odometry::correctedPoints() const { return impl_->corrected; }
const std::vector<Eigen::Vector2d>& Odometry::rawPoints() const { return impl_->raw; }

void Odometry::reset() { impl_->reset(); }
const PipelineConfig& Odometry::config() const { return impl_->config; }
void Odometry::setConfig(const PipelineConfig& config) { impl_->apply(config); }

}  // namespace spinradar
