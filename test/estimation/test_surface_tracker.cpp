// The `surface` estimator (issue 19) and its parts against known truth: surface points of
// hand-made lines and blobs, the cell index against brute force, fitted firing times from
// bursty stamps, and drives through scenes of walls (random layouts, several seeds) where
// each keypoint sits on its azimuth row (the row quantisation of real Navtech keypoints).
#include <gtest/gtest.h>

#include <ctime>
#include <cmath>
#include <iostream>
#include <random>

#include <Eigen/Cholesky>

#include "support/synthetic_scene.hpp"
#include "spinradar/core/lie.hpp"
#include "spinradar/estimation/azimuth_times.hpp"
#include "spinradar/estimation/odometry.hpp"
#include "spinradar/estimation/surface_points.hpp"
#include "spinradar/estimation/surface_tracker.hpp"

using namespace spinradar;
using spinradar::testing::SceneOptions;
using spinradar::testing::SyntheticScene;

namespace {

constexpr double kDeg = M_PI / 180.0;

TEST(SurfacePoints, LineGivesItsNormalAndBlobIsNotPlanar) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 0.05);
  std::vector<Eigen::Vector2d> pts;
  // A wall along direction (cos 30, sin 30) through (20, 5), points every 0.3 m.
  const Eigen::Vector2d dir(std::cos(30 * kDeg), std::sin(30 * kDeg)), nrm(-dir.y(), dir.x());
  for (int i = 0; i < 60; ++i) pts.push_back(Eigen::Vector2d(20, 5) + (0.3 * i) * dir + n(rng) * nrm);
  // A round blob of returns (a tree) far away.
  std::uniform_real_distribution<double> u(-0.8, 0.8);
  for (int i = 0; i < 40; ++i) pts.push_back(Eigen::Vector2d(-40 + u(rng), -30 + u(rng)));
  SurfaceExtractor ex;
  std::vector<SurfacePoint> sp;
  ex.extract(pts, 2.0, 4, sp);
  int on_wall = 0, blob = 0;
  for (const SurfacePoint& s : sp) {
    if (s.mean.x() > 0) {
      ++on_wall;
      EXPECT_GT(std::abs(s.normal.dot(nrm)), std::cos(3 * kDeg));
      EXPECT_NEAR(nrm.dot(s.mean - Eigen::Vector2d(20, 5)), 0.0, 0.05);
      EXPECT_GT(s.planarity, 0.95);
    } else {
      ++blob;
      EXPECT_LT(s.planarity, 0.5);
    }
  }
  EXPECT_GE(on_wall, 5);
  EXPECT_GE(blob, 1);
}

TEST(SurfacePoints, CellIndexFindsTheNearestPoint) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-50, 50);
  std::vector<Eigen::Vector2d> pts(2000);
  for (auto& p : pts) p = Eigen::Vector2d(u(rng), u(rng));
  CellIndex idx;
  idx.build(pts.data(), static_cast<int>(pts.size()), 1.5);
  for (int t = 0; t < 500; ++t) {
    const Eigen::Vector2d q(u(rng), u(rng));
    int best = -1;
    double bd = 1.5 * 1.5;
    for (size_t i = 0; i < pts.size(); ++i)
      if ((pts[i] - q).squaredNorm() < bd) bd = (pts[i] - q).squaredNorm(), best = static_cast<int>(i);
    EXPECT_EQ(idx.nearest(q, 1.5), best);
  }
}

TEST(AzimuthTimes, UniformTimesFromPacketArrivalStamps) {
  // 400 rows fired every 625 us; stamped in packets of 16 on arrival: every row of a packet
  // gets the last row's firing time + 0.5 ms + i * 135 us (Oxford-like).
  PolarScan scan;
  scan.resize(400, 8);
  const int64_t t0 = 5'000'000'000;
  auto fire = [&](int a) { return t0 + static_cast<int64_t>(a) * 625'000; };
  for (int a = 0; a < 400; ++a) {
    const int last = std::min(399, (a / 16) * 16 + 15);
    scan.stamp_ns[a] = fire(last) + 500'000 + (a % 16) * 135'000;
  }
  std::vector<Keypoint> kps;
  for (int a = 0; a < 400; a += 7) {
    Keypoint k;
    k.azimuth_index = a;
    k.stamp_ns = scan.stamp_ns[a] + (a % 2 ? 100'000 : 0);  // a sub-row offset on odd rows
    kps.push_back(k);
  }
  // The fit recovers the firing times up to one constant: the spread of the error is small.
  double worst_before = 0, mean = 0;
  std::vector<double> err;
  for (const Keypoint& k : kps) {
    const double e = 1e-6 * static_cast<double>(k.stamp_ns - (k.azimuth_index % 2 ? 100'000 : 0) -
                                                 fire(k.azimuth_index));
    worst_before = std::max(worst_before, e);
  }
  uniformKeypointTimes(scan, kps);
  for (const Keypoint& k : kps) {
    err.push_back(1e-6 * static_cast<double>(k.stamp_ns - (k.azimuth_index % 2 ? 100'000 : 0) -
                                             fire(k.azimuth_index)));
    mean += err.back() / kps.size();
  }
  double spread = 0;
  for (double e : err) spread = std::max(spread, std::abs(e - mean));
  std::cout << "[ info ] stamp error before " << worst_before << " ms; after: offset " << mean
            << " ms, spread " << spread << " ms\n";
  EXPECT_GT(worst_before, 9.0);
  EXPECT_LT(spread, 0.2);
}

/// Landmarks along walls: `n_walls` segments 8-30 m long at 8-110 m, one point every 0.4 m.
std::vector<Eigen::Vector2d> wallPoints(uint32_t seed, int n_walls) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ur(8.0, 110.0), ua(-M_PI, M_PI), ul(8.0, 30.0);
  std::vector<Eigen::Vector2d> pts;
  for (int w = 0; w < n_walls; ++w) {
    const double r = ur(rng), a = ua(rng), o = ua(rng), len = ul(rng);
    const Eigen::Vector2d c(r * std::cos(a), r * std::sin(a)), d(std::cos(o), std::sin(o));
    for (double s = -0.5 * len; s <= 0.5 * len; s += 0.4) pts.push_back(c + s * d);
  }
  return pts;
}

struct DriveResult {
  double final_err = 0, final_yaw_err = 0, length = 0;
  std::vector<double> key_nees;
};

DriveResult drive(const std::string& estimator, uint32_t seed, const std::vector<Eigen::Vector3d>& v) {
  const std::vector<Eigen::Vector2d> walls = wallPoints(seed, 70);
  SceneOptions o;
  o.landmarks = static_cast<int>(walls.size());
  o.range_sigma = 0.04;
  o.azimuth_sigma = 0.0;
  o.quantize_azimuth = true;  // every return on its row's angle, as a Navtech keypoint
  o.clutter = 100;
  o.beta = 0.049;
  o.seed = seed;
  SyntheticScene scene(o, v);
  scene.landmarks() = walls;
  PipelineConfig cfg;
  cfg.estimator.estimator = estimator;
  Odometry odo(cfg);
  DriveResult d;
  Eigen::Matrix3d prev = Eigen::Matrix3d::Identity();
  const int n = static_cast<int>(v.size()) - 1;
  for (int k = 0; k < n; ++k) {
    const OdometryResult res = odo.process(scene.observe(k));
    if (k == 0) continue;
    EXPECT_TRUE(res.ok) << estimator << " scan " << k;
    const Eigen::Matrix3d truth = scene.pose(scene.scanStart(k));
    d.final_err = (res.T_world_sensor.topRightCorner<2, 1>() - truth.topRightCorner<2, 1>()).norm();
    d.final_yaw_err = std::abs(se2::log(se2::inverse(truth) * res.T_world_sensor)(2));
    d.length += (truth.topRightCorner<2, 1>() - prev.topRightCorner<2, 1>()).norm();
    prev = truth;
    if (res.keyframe_stamp_ns != 0 && res.keyframe_stamp_ns != res.stamp_ns) {
      const double tk = 1e-9 * static_cast<double>(res.keyframe_stamp_ns - o.t0_ns);
      const Eigen::Matrix3d rel_t = se2::inverse(scene.pose(tk)) * truth;
      Eigen::Vector3d er = se2::toXyYaw(res.T_keyframe_sensor) - se2::toXyYaw(rel_t);
      er(2) = std::remainder(er(2), 2.0 * M_PI);
      d.key_nees.push_back(er.dot(res.keyframe_cov.ldlt().solve(er)));
    }
  }
  std::cout << "[ info ] " << estimator << " seed " << seed << ": " << d.length << " m, final error "
            << d.final_err << " m (" << 100 * d.final_err / d.length << " %), yaw "
            << d.final_yaw_err / kDeg << " deg\n";
  return d;
}

/// 8-12 m/s, yaw rate swinging +-12 deg/s.
std::vector<Eigen::Vector3d> varying(int n, double phase) {
  std::vector<Eigen::Vector3d> v;
  for (int k = 0; k <= n; ++k) {
    const double t = std::max(k, 1) + phase;
    v.emplace_back(10.0 + 2.0 * std::sin(0.2 * t), 0.0, 12.0 * kDeg * std::sin(0.15 * t));
  }
  return v;
}

}  // namespace

TEST(SurfaceTracker, CorrectsAWrongPrediction) {
  // Two scans of a wall scene at 10 m/s turning 10 deg/s (motion distortion, Doppler): the
  // second registered from a prediction 0.6 deg and 0.3 m off. The point-to-line stage must
  // land on the true pose (keypoints at their true bearings, 4 cm range noise).
  for (uint32_t seed : {21u, 22u, 23u}) {
    const std::vector<Eigen::Vector2d> walls = wallPoints(seed, 70);
    SceneOptions o;
    o.landmarks = static_cast<int>(walls.size());
    o.range_sigma = 0.04;
    o.beta = 0.049;
    o.seed = seed;
    const Eigen::Vector3d v(10.0, 0.0, 10.0 * kDeg);
    SyntheticScene scene(o, {v});
    scene.landmarks() = walls;
    SurfaceTracker st;
    const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
    const Eigen::Matrix3d C = Eigen::Vector3d(0.5 * 0.5, 0.5 * 0.5, std::pow(1.0 * kDeg, 2)).asDiagonal();
    Eigen::Matrix3d T0, P0, T1, P1;
    ASSERT_TRUE(st.track(scene.observe(0), v, I, Eigen::Matrix3d::Zero(), I, C, T0, P0));
    const Eigen::Matrix3d truth = scene.relative(0, 1);
    const Eigen::Matrix3d wrong = truth * se2::exp(Eigen::Vector3d(0.3, -0.2, 0.6 * kDeg));
    const FeatureFrame f1 = scene.observe(1);
    const std::clock_t c_start = std::clock();  // CPU time: other load does not count
    ASSERT_TRUE(st.track(f1, v, T0, P0, wrong, C, T1, P1));
    const double ms = 1e3 * static_cast<double>(std::clock() - c_start) / CLOCKS_PER_SEC;
    const Eigen::Vector3d e = se2::log(se2::inverse(truth) * T1);
    std::cout << "[ info ] seed " << seed << ": " << st.lastAssociations() << " line pairs, error "
              << e.head<2>().norm() << " m, " << e(2) / kDeg << " deg (prediction 0.36 m, 0.6 deg); " << f1.keypoints.size() << " keypoints, "
              << ms << " ms CPU (information only)\n";
    EXPECT_LT(e.head<2>().norm(), 0.05) << "seed " << seed;
    EXPECT_LT(std::abs(e(2)), 0.05 * kDeg) << "seed " << seed;
  }
}

TEST(SurfaceTracker, RowQuantisedWallDrivesHold) {
  // Three random wall layouts and drives with every keypoint on its row's angle (the
  // row quantisation of Navtech keypoints); the surface stage must hold each drive as the
  // keyframe estimator it starts from does (measured: 0.74-0.87 % and 0.11-0.17 deg for
  // surface, 0.78-0.82 % and 0.02-0.19 deg for keyframe after 77 m).
  for (uint32_t seed : {11u, 12u, 13u}) {
    const auto v = varying(32, seed);
    const DriveResult sf = drive("surface", seed, v);
    EXPECT_LT(sf.final_err / sf.length, 0.012) << "seed " << seed;
    EXPECT_LT(sf.final_yaw_err, 0.3 * kDeg) << "seed " << seed;
    double nees = 0;
    for (double x : sf.key_nees) nees += x / sf.key_nees.size();
    std::cout << "[ info ] mean NEES relative to the surface keyframe " << nees << " over "
              << sf.key_nees.size() << " scans\n";
  }
}
