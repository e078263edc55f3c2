// Keypoints and yaw rate against the simulator's truth in steady turns: the detector's
// keypoints lie where the trajectory puts the targets, and the yaw rate estimated through the
// whole front end (Cen2018, ORB, ratio test, MC-RANSAC) is unbiased. The azimuth rows of a
// spinning radar quantise bearings; in a turn every target moves by the same fractional
// number of rows per scan, which biased the yaw rate in two places (the inlier gate, see
// test_mc_ransac QuantizedAzimuthsInASteadyTurn, and descriptor matching of row keypoints,
// see Detector::setAzimuthPeaks).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>

#include "sim_test_util.hpp"
#include "spinradar/features/detector.hpp"
#include "spinradar/features/feature_extractor.hpp"
#include "spinradar/features/matcher.hpp"
#include "spinradar/estimation/mc_ransac.hpp"
// The CLI's option layer is not a library; compiled in here so that the test goes through the
// same `--azimuth-peaks` / YAML path as `spinradar odometry`.
#include "../../src/tools/pipeline_options.cpp"

using namespace spinradar;
using namespace spinradar::sim;
using namespace spinradar::sim::testing;

namespace {

const double kStep = 2 * M_PI / 400;

/// Point targets (no walls) scattered around the start, bright enough to saturate nearby.
World pointTargets(int n, uint32_t seed) {
  World w;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-120, 120);
  for (int i = 0; i < n; ++i) w.targets.push_back({u(rng), u(rng), 30, 0, 0});
  return w;
}

PhysicsConfig distortionOnly() {
  PhysicsConfig p;
  p.motion_distortion = true;
  return p;
}

/// Mean estimated / true yaw rate over `pairs` consecutive scan pairs, front end included.
double yawRatio(const Simulator& sim, double wz, int pairs, bool azimuth_peaks) {
  FeatureExtractor fx(DetectorConfig{}, FeatureConfig{});
  fx.setAzimuthPeaks(azimuth_peaks);
  McRansac mc;
  FeatureFrame f1, f2;
  std::vector<Match> m;
  double sum = 0.0;
  int n = 0;
  fx.extract(sim.renderScan(1), f1);
  for (int k = 2; k < 2 + pairs; ++k) {
    fx.extract(sim.renderScan(k), f2);
    matchDescriptors(f1.descriptors, f2.descriptors, FeatureConfig{}.nndr, m);
    MotionEstimate est;
    if (mc.estimate(f1.keypoints, f2.keypoints, m, f1.stamp_ns, f2.stamp_ns, est)) {
      sum += est.velocity(2);
      ++n;
    }
    std::swap(f1, f2);
  }
  EXPECT_EQ(n, pairs);
  return n > 0 ? sum / n / wz : 0.0;
}

}  // namespace

TEST(KeypointTruth, KeypointsAreWhereTheTrajectorySaysAndPeaksAreSubRow) {
  // Turning at 5 m/s, 0.625 rad/s with motion distortion; each keypoint is placed with the
  // pose at its own timestamp and compared with the nearest target (within 3 m; bright
  // targets also leave sidelobe detections several rows off, which are not counted). Within
  // one row of a target, keypoints are unbiased in azimuth and range. Row keypoints spread
  // over the rows that see a target (few within a quarter row); azimuth peaks sit on it.
  const World world = pointTargets(400, 3);
  const Trajectory traj = constantMotion(5.0, 0.625, {}, 2.0);
  Simulator sim(world, traj, SensorConfig{}, distortionOnly(), 5);
  const PolarScan scan = sim.renderScan(2);
  for (bool peaks : {false, true}) {
    Detector det;
    det.setAzimuthPeaks(peaks);
    std::vector<Keypoint> kps;
    det.detect(scan, kps);
    double sum_da = 0, sum_dr = 0;
    int n = 0, within_row = 0, within_quarter = 0;
    for (const Keypoint& k : kps) {
      const Pose2 p = traj.at(k.stamp_ns * 1e-9);
      const double c = std::cos(p.yaw), s = std::sin(p.yaw);
      double best = 3.0, da = 0, dr = 0;
      for (const Target& t : world.targets) {
        const double dx = t.x - p.x, dy = t.y - p.y;
        const double xs = c * dx + s * dy, ys = -s * dx + c * dy;
        const double d = std::hypot(xs - k.x, ys - k.y);
        if (d < best) {
          best = d;
          da = std::remainder(k.azimuth - std::atan2(-ys, xs), 2 * M_PI) / kStep;
          dr = k.range - std::hypot(xs, ys);
        }
      }
      if (best >= 3.0) continue;
      ++n;
      if (std::abs(da) > 1.0) continue;
      ++within_row;
      within_quarter += std::abs(da) <= 0.25;
      sum_da += da;
      sum_dr += dr;
    }
    ASSERT_GT(within_row, 300) << "peaks " << peaks;
    const double quarter = double(within_quarter) / n;
    std::cout << "[ info ] " << (peaks ? "azimuth peaks" : "row keypoints") << ": " << n
              << " keypoints at a target, " << within_row << " within a row, fraction within"
              << " a quarter row " << quarter << "; mean azimuth error " << sum_da / within_row
              << " rows, mean range error " << sum_dr / within_row << " m\n";
    EXPECT_LT(std::abs(sum_da / within_row), 0.05) << "peaks " << peaks;
    // Range: about one bin short for azimuth peaks (their rows saturate on these 30 dBsm
    // targets and a saturated run peaks at its first bin); a constant offset cancels in motion.
    EXPECT_LT(std::abs(sum_dr / within_row), 0.05) << "peaks " << peaks;
    if (peaks)
      EXPECT_GT(quarter, 0.6);
    else
      EXPECT_LT(quarter, 0.3);
  }
}

TEST(KeypointTruth, SteadyTurnYawRateThroughTheFrontEnd) {
  // 5 m/s on circles of 8 m radius (the city route's turns), both directions, 12 scan pairs.
  // Row keypoints: descriptor matching pairs each target's rows with the nearest whole-row
  // shift, ~-0.6 % / -0.8 % in yaw rate here (-1.2 % turning in place); azimuth peaks: within
  // 0.3 %.
  const World world = pointTargets(400, 3);
  for (double wz : {0.625, -0.625}) {
    Simulator sim(world, constantMotion(5.0, wz, {}, 4.0), SensorConfig{}, distortionOnly(), 5);
    const double rows = yawRatio(sim, wz, 12, false);
    const double peaks = yawRatio(sim, wz, 12, true);
    std::cout << "[ info ] wz " << wz << ": yaw rate ratio, row keypoints " << rows
              << ", azimuth peaks " << peaks << "\n";
    EXPECT_NEAR(peaks, 1.0, 0.003) << "wz " << wz;
  }
}

TEST(KeypointTruth, AzimuthPeaksParameterFromTheCommandLineGivesSubRowAzimuths) {
  // A still sensor and point targets at known bearings a fraction of a row off the row angles
  // (rows at a * 2 pi / 400). With `--azimuth-peaks 1` (the default; CLI options -> PipelineConfig ->
  // FeatureExtractor, as `spinradar odometry` builds it) each target gives one keypoint within
  // +-2 rows, at its bearing within 0.1 row (measured <= 0.05), i.e. off the row angle. Without
  // it (`--azimuth-peaks 0`, the paper's front end) each target gives keypoints on the 4 rows its beam covers, all exactly at
  // row angles. Both detectors. (The sidelobes ~3 rows off are azimuthal peaks of their own and
  // not counted.)
  const double fracs[] = {0.3, -0.3, 0.4, -0.4, 0.25, -0.2};
  World world;
  std::vector<std::pair<double, double>> truth;  // bearing (rows, clockwise), range (m)
  for (int i = 0; i < 6; ++i) {
    const double rows = 30 + 60 * i + fracs[i], r = 25.0 + 12.0 * i;
    const double phi = rows * kStep;
    world.targets.push_back({r * std::cos(phi), -r * std::sin(phi), 15.0, 0, 0});
    truth.emplace_back(rows, r);
  }
  Simulator sim(world, constantMotion(0.0, 0.0, {}, 2.0), SensorConfig{}, PhysicsConfig{}, 5);
  const PolarScan scan = sim.renderScan(2);
  ASSERT_EQ(scan.azimuths, 400);
  for (int a : {0, 30, 399}) ASSERT_NEAR(scan.azimuth[a], a * kStep, 1e-9);

  for (const char* detector : {"cen2018", "cfar"}) {
    for (bool peaks : {false, true}) {
      CLI::App app;
      cli::PipelineOptions opts;
      opts.add(app);
      std::vector<std::string> args = {"--detector", detector};
      args.insert(args.end(), {"--azimuth-peaks", peaks ? "1" : "0"});
      std::reverse(args.begin(), args.end());  // CLI11 takes the arguments last-first
      app.parse(args);
      const PipelineConfig cfg = opts.resolve();
      ASSERT_EQ(cfg.detector.azimuth_peaks, peaks);
      FeatureExtractor fx(cfg.detector, cfg.features);
      FeatureFrame f;
      fx.extract(scan, f);
      for (const auto& [rows, r] : truth) {
        int n = 0;
        for (const Keypoint& k : f.keypoints) {
          const double da = std::remainder(k.azimuth / kStep - rows, 400.0);
          if (std::abs(da) > 2.0 || std::abs(k.range - r) > 1.0) continue;
          ++n;
          const double off_row = std::abs(std::remainder(k.azimuth / kStep, 1.0));
          if (peaks) {
            EXPECT_LT(std::abs(da), 0.1) << detector << " target at row " << rows;
            EXPECT_GT(off_row, 0.05) << detector << " target at row " << rows;
          } else {
            EXPECT_LT(off_row, 1e-9) << detector << " target at row " << rows;
          }
        }
        if (peaks)
          EXPECT_EQ(n, 1) << detector << " target at row " << rows;
        else
          EXPECT_GE(n, 3) << detector << " target at row " << rows;
      }
    }
  }
  // The YAML form reaches the same field.
  PipelineConfig cfg;
  cli::setPipelineParam(cfg, "azimuth_peaks", "true", "test");
  EXPECT_TRUE(cfg.detector.azimuth_peaks);
  EXPECT_THROW(cli::setPipelineParam(cfg, "azimuth_peaks", "2", "test"), std::invalid_argument);
}
