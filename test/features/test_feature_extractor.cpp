// The whole feature chain: keypoints and descriptors stay aligned, known motion is recovered by
// the matches, and on real Oxford scans the matches agree with the dataset's odometry. Prints
// per-stage timings (no wall-clock assertions).
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <new>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "support/count_allocations.hpp"
#include "support/feature_test_utils.hpp"
#include "spinradar/features/cartesian.hpp"
#include "spinradar/features/detector.hpp"
#include "spinradar/features/feature_extractor.hpp"
#include "spinradar/features/matcher.hpp"
#include "spinradar/features/orb_descriptors.hpp"
#include "spinradar/io/scan_folder.hpp"
#include "../../src/features/matcher_kernels.hpp"  // every matcher kernel on real descriptors

using namespace spinradar;
using spinradar::test::Target;

namespace {

struct Motion {
  double x, y, yaw;  ///< pose of the second scan in the first (REP 103)
};

/// Landmarks in the first sensor frame -> targets as seen from the first and second pose.
void makeScene(const Motion& m, std::vector<Target>& t1, std::vector<Target>& t2, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> xy(-110, 110), snr(32, 45);
  const double c = std::cos(m.yaw), s = std::sin(m.yaw);
  for (int i = 0; i < 700; ++i) {
    const double px = xy(rng), py = xy(rng), p = snr(rng);
    const double r1 = std::hypot(px, py);
    // second frame: p2 = R^T (p - t)
    const double dx = px - m.x, dy = py - m.y;
    const double qx = c * dx + s * dy, qy = -s * dx + c * dy;
    const double r2 = std::hypot(qx, qy);
    if (r1 < 5 || r2 < 5 || r1 > 115 || r2 > 115) continue;
    t1.push_back({std::atan2(-py, px), r1, p});  // clockwise azimuth
    t2.push_back({std::atan2(-qy, qx), r2, p});
  }
}

/// Fraction of matches whose points agree with p1 = R p2 + t within `tol` metres plus two
/// azimuth steps at their range (the same target is often detected on neighbouring azimuths).
double agreement(const FeatureFrame& f1, const FeatureFrame& f2, const std::vector<Match>& m, const Motion& mo,
                 double tol) {
  if (m.empty()) return 0;
  const double c = std::cos(mo.yaw), s = std::sin(mo.yaw);
  int ok = 0;
  for (const auto& x : m) {
    const Keypoint &a = f1.keypoints[x.i1], &b = f2.keypoints[x.i2];
    const double px = c * b.x - s * b.y + mo.x, py = s * b.x + c * b.y + mo.y;
    ok += std::hypot(px - a.x, py - a.y) < tol + 2.0 * a.range * 2.0 * M_PI / 400.0;
  }
  return double(ok) / m.size();
}

}  // namespace

TEST(FeatureExtractor, RecoversKnownMotionOnSyntheticScans) {
  const Motion mo{2.0, 0.4, 0.04};
  std::vector<Target> t1, t2;
  makeScene(mo, t1, t2, 21);
  const PolarScan s1 = test::syntheticScan(t1, 1), s2 = test::syntheticScan(t2, 2, 400, 3768, 0.0438, 30.0,
                                                                              1'000'250'000'000LL);
  FeatureExtractor fe(DetectorConfig{}, FeatureConfig{});
  FeatureFrame f1, f2;
  StageTimes times;
  fe.extract(s1, f1, &times);
  fe.extract(s2, f2, &times);
  for (const FeatureFrame* f : {&f1, &f2}) {
    ASSERT_EQ(f->descriptors.rows, static_cast<int>(f->keypoints.size()));
    ASSERT_EQ(f->descriptors.cols, 32);
  }
  EXPECT_EQ(f1.stamp_ns, s1.stamp_ns[0]);
  EXPECT_EQ(f2.stamp_ns, s2.stamp_ns[0]);
  EXPECT_GT(times.detect_ms, 0);
  EXPECT_GT(times.cartesian_ms, 0);
  EXPECT_GT(times.describe_ms, 0);
  EXPECT_EQ(fe.cartesianImage().rows, 964);
  std::vector<Match> m;
  matchDescriptors(f1.descriptors, f2.descriptors, 0.8, m);
  const double agree = agreement(f1, f2, m, mo, 0.75);
  std::printf("synthetic: %zu / %zu keypoints, %zu matches, %.0f %% agree with the true motion\n",
              f1.keypoints.size(), f2.keypoints.size(), m.size(), 100 * agree);
  EXPECT_GT(m.size(), 100u);
  EXPECT_GT(agree, 0.7);  // plenty for RANSAC; the rest are mostly look-alike isolated points
}

TEST(FeatureExtractor, ExtractorsOnSeveralThreadsShareOneSetOfTables) {
  const Motion mo{1.5, -0.3, 0.03};
  std::vector<Target> t1, t2;
  makeScene(mo, t1, t2, 8);
  const std::vector<PolarScan> scans = {test::syntheticScan(t1, 1), test::syntheticScan(t2, 2)};
  FeatureExtractor solo(DetectorConfig{}, FeatureConfig{});
  std::vector<FeatureFrame> want(2);
  for (size_t i = 0; i < 2; ++i) solo.extract(scans[i], want[i]);
  FeatureExtractor first(DetectorConfig{}, FeatureConfig{});
  FeatureExtractor second(DetectorConfig{}, FeatureConfig{}, first.cartesianTables());
  ASSERT_EQ(second.cartesianTables(), first.cartesianTables());
  std::vector<FeatureFrame> got(2);
  std::thread a([&] { first.extract(scans[0], got[0]); });
  std::thread b([&] { second.extract(scans[1], got[1]); });
  a.join();
  b.join();
  EXPECT_EQ(first.cartesianTables()->builds(), 1);  // one build for both threads
  for (size_t i = 0; i < 2; ++i) {
    ASSERT_EQ(got[i].keypoints.size(), want[i].keypoints.size());
    ASSERT_GT(got[i].keypoints.size(), 300u);
    EXPECT_EQ(cv::norm(got[i].descriptors, want[i].descriptors, cv::NORM_HAMMING), 0) << "scan " << i;
  }
  // Tables of another image geometry are not taken.
  FeatureConfig other;
  other.cart_pixel_width = 500;
  FeatureExtractor third(DetectorConfig{}, other, first.cartesianTables());
  EXPECT_NE(third.cartesianTables(), first.cartesianTables());
}

TEST(FeatureExtractor, StampIsFirstValidAzimuthAndMaxKeypointsKeepsStrongest) {
  std::vector<Target> t;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> az(0, 2 * M_PI), r(10, 100), snr(30, 50);
  for (int i = 0; i < 200; ++i) t.push_back({az(rng), r(rng), snr(rng)});
  PolarScan s = test::syntheticScan(t, 5);
  s.valid[0] = s.valid[1] = 0;
  FeatureConfig fc;
  FeatureExtractor all(DetectorConfig{}, fc);
  fc.max_keypoints = 50;
  FeatureExtractor few(DetectorConfig{}, fc);
  FeatureFrame fa, ff;
  all.extract(s, fa);
  few.extract(s, ff);
  EXPECT_EQ(ff.stamp_ns, s.stamp_ns[2]);
  ASSERT_GT(fa.keypoints.size(), 60u);
  ASSERT_LE(ff.keypoints.size(), 50u);
  EXPECT_GE(ff.keypoints.size(), 45u);  // a few of the strongest may sit too close to the image edge
  EXPECT_EQ(ff.descriptors.rows, static_cast<int>(ff.keypoints.size()));
  // Every kept keypoint is at least as strong as the 50th strongest detection.
  Detector d;
  std::vector<Keypoint> det;
  d.detect(s, det);
  std::vector<float> p;
  for (const auto& k : det) p.push_back(k.power);
  std::sort(p.rbegin(), p.rend());
  for (const auto& k : ff.keypoints) EXPECT_GE(k.power, p[49]);
  // Empty scans give empty frames, not errors.
  FeatureFrame fe;
  all.extract(PolarScan{}, fe);
  EXPECT_TRUE(fe.keypoints.empty());
  EXPECT_EQ(fe.descriptors.rows, 0);
}

TEST(FeatureExtractor, RealOxfordScansMatchTheDatasetOdometry) {
  const std::string root = std::string(SPINRADAR_SHARED_DIR) + "/realdata/oxford_2019-01-10-14-36-48";
  if (!std::filesystem::exists(root)) {
    GTEST_SKIP() << "real sample " << root << " not found (needs shared/realdata beside the clone)";
  }
  ScanFolder folder(root);
  ASSERT_EQ(folder.size(), 3u);
  FeatureExtractor fe(DetectorConfig{}, FeatureConfig{});
  std::vector<FeatureFrame> frames(3);
  std::vector<PolarScan> scans;
  for (size_t i = 0; i < 3; ++i) scans.push_back(folder.load(i));
  StageTimes sum;
  const int reps = 5;
  for (int rep = 0; rep < reps + 1; ++rep)
    for (size_t i = 0; i < 3; ++i) {
      StageTimes t;
      fe.extract(scans[i], frames[i], &t);
      if (rep > 0) sum += t;  // the first round builds the tables
    }
  const double n = 3.0 * reps;
  std::vector<Match> m;
  const auto t0 = std::chrono::steady_clock::now();
  for (int rep = 0; rep < reps; ++rep) matchDescriptors(frames[0].descriptors, frames[1].descriptors, 0.8, m);
  const double match_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() / reps;
  std::printf("oxford: keypoints %zu %zu %zu; mean ms: detect %.2f cartesian %.2f describe %.2f match %.2f\n",
              frames[0].keypoints.size(), frames[1].keypoints.size(), frames[2].keypoints.size(), sum.detect_ms / n,
              sum.cartesian_ms / n, sum.describe_ms / n, match_ms);
  for (const auto& f : frames) {
    EXPECT_GT(f.keypoints.size(), 500u);
    EXPECT_EQ(f.descriptors.rows, static_cast<int>(f.keypoints.size()));
  }
  EXPECT_EQ(frames[0].stamp_ns, 1547131046353776LL * 1000);

  // The dataset's odometry (x forward, y right, yaw clockwise) of scan 1 in scan 0: matches of
  // the same landmark agree with it (azimuths match, so motion distortion mostly cancels).
  std::ifstream gt(root + "/gt/radar_odometry.csv");
  ASSERT_TRUE(gt.good());
  std::string line;
  std::getline(gt, line);
  std::getline(gt, line);
  std::vector<double> v;
  std::stringstream ss(line);
  for (std::string f; std::getline(ss, f, ',');) v.push_back(std::stod(f));
  ASSERT_GE(v.size(), 10u);
  const Motion mo{v[2], -v[3], -v[7]};
  matchDescriptors(frames[0].descriptors, frames[1].descriptors, 0.8, m);
  const double agree = agreement(frames[0], frames[1], m, mo, 1.0);
  std::printf("oxford: %zu matches between scans 0 and 1, %.0f %% agree with the dataset odometry\n", m.size(),
              100 * agree);
  EXPECT_GT(m.size(), 100u);
  EXPECT_GT(agree, 0.5);

  // Every matcher kernel gives the same matches as a plain double loop on real descriptors.
  for (const auto& [a, b] : {std::pair{0, 1}, std::pair{1, 2}, std::pair{2, 0}}) {
    const cv::Mat &d1 = frames[a].descriptors, &d2 = frames[b].descriptors;
    std::vector<Match> ref;
    for (int i = 0; i < d1.rows; ++i) {
      int best = 1 << 30, second = 1 << 30, j_best = -1;
      for (int j = 0; j < d2.rows; ++j) {
        int d = 0;
        for (int w = 0; w < 4; ++w) {
          uint64_t x, y;
          std::memcpy(&x, d1.ptr<uint8_t>(i) + 8 * w, 8);
          std::memcpy(&y, d2.ptr<uint8_t>(j) + 8 * w, 8);
          d += __builtin_popcountll(x ^ y);
        }
        if (d < best) second = best, best = d, j_best = j;
        else if (d < second) second = d;
      }
      if (best < 0.8 * second) ref.push_back({i, j_best, float(best)});
    }
    auto same = [&](const std::vector<Match>& got, const char* kernel) {
      ASSERT_EQ(got.size(), ref.size()) << kernel;
      for (size_t k = 0; k < ref.size(); ++k) {
        EXPECT_EQ(got[k].i1, ref[k].i1) << kernel;
        EXPECT_EQ(got[k].i2, ref[k].i2) << kernel;
        EXPECT_EQ(got[k].distance, ref[k].distance) << kernel;
      }
    };
    matchDescriptors(d1, d2, 0.8, m);
    same(m, "chosen");
    m.clear();
    detail::matchScalar(d1, d2, 0.8, m);
    same(m, "scalar");
    m.clear();
    if (detail::matchAvx2(d1, d2, 0.8, m)) same(m, "avx2");
    m.clear();
    if (detail::matchAvx512(d1, d2, 0.8, m)) same(m, "avx512");
  }
}

TEST(FeatureExtractor, HotPathsDoNotAllocateAfterWarmUp) {
  std::vector<Target> t1, t2;
  makeScene({1.0, 0.2, 0.02}, t1, t2, 5);
  const PolarScan s1 = test::syntheticScan(t1, 1), s2 = test::syntheticScan(t2, 2);
  Detector det;
  CartesianProjector proj;
  FeatureExtractor fe(DetectorConfig{}, FeatureConfig{});
  std::vector<Keypoint> k1, k2;
  cv::Mat img;
  FeatureFrame f1, f2;
  std::vector<Match> m;
  for (int warm = 0; warm < 2; ++warm) {
    det.detect(s1, k1);
    det.detect(s2, k2);
    proj.render(s1, img);
    proj.render(s2, img);
    fe.extract(s1, f1);
    fe.extract(s2, f2);
    matchDescriptors(f1.descriptors, f2.descriptors, 0.8, m);
  }
  long before = g_allocations;
  det.detect(s1, k1);
  det.detect(s2, k2);
  EXPECT_EQ(g_allocations - before, 0) << "detector";
  before = g_allocations;
  proj.render(s1, img);
  proj.render(s2, img);
  EXPECT_EQ(g_allocations - before, 0) << "Cartesian projector";
  before = g_allocations;
  matchDescriptors(f1.descriptors, f2.descriptors, 0.8, m);
  matchDescriptors(f2.descriptors, f1.descriptors, 0.8, m);
  EXPECT_EQ(g_allocations - before, 0) << "matcher";
  // The whole extractor, ORB stage included (its blur used to allocate ~23 blocks per image
  // inside cv::GaussianBlur, plus a copy of the image).
  before = g_allocations;
  fe.extract(s1, f1);
  fe.extract(s2, f2);
  EXPECT_EQ(g_allocations - before, 0) << "feature extractor (detect, Cartesian, ORB)";
  ASSERT_GT(f1.keypoints.size(), 100u);  // real work was done
  EXPECT_EQ(f1.descriptors.rows, static_cast<int>(f1.keypoints.size()));
  // The ORB stage on its own, with a fresh describer on the same image after its warm-up.
  OrbDescriber orb;
  std::vector<Keypoint> kp = k1;
  cv::Mat desc;
  orb.describe(img, proj, kp, desc);
  kp = k1;
  before = g_allocations;
  orb.describe(img, proj, kp, desc);
  EXPECT_EQ(g_allocations - before, 0) << "ORB describer";
  EXPECT_GT(desc.rows, 100);
}
