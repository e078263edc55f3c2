// Radial Statistics Descriptor: invariances, self-matching, gating, timing (printed only).
#include <ctime>
#include <cmath>
#include <cstdio>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "spinradar/localization/rsd.hpp"

namespace spinradar {
namespace {

/// A radar-like keypoint cloud: wall segments sampled every ~0.5 m plus scattered posts.
std::vector<Eigen::Vector2d> makeCloud(int posts, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-80.0, 80.0), L(5.0, 30.0), A(0.0, 2 * M_PI);
  std::vector<Eigen::Vector2d> pts;
  for (int w = 0; w < 12; ++w) {
    const Eigen::Vector2d a(U(rng), U(rng));
    const double len = L(rng), th = A(rng);
    for (double s = 0.0; s < len; s += 0.5) pts.emplace_back(a + s * Eigen::Vector2d(std::cos(th), std::sin(th)));
  }
  for (int i = 0; i < posts; ++i) pts.emplace_back(U(rng), U(rng));
  return pts;
}

std::vector<Eigen::Vector2d> transformed(const std::vector<Eigen::Vector2d>& p, double th,
                                         const Eigen::Vector2d& t) {
  const Eigen::Matrix2d C = Eigen::Rotation2Dd(th).toRotationMatrix();
  std::vector<Eigen::Vector2d> out;
  for (const auto& q : p) out.push_back(C * q + t);
  return out;
}

double correctFraction(const std::vector<Match>& m) {
  if (m.empty()) return 0.0;
  int ok = 0;
  for (const Match& x : m) ok += x.i1 == x.i2;
  return double(ok) / m.size();
}

TEST(Rsd, ConfigValidation) {
  RsdConfig c;
  EXPECT_NO_THROW(c.validate());
  c.rsd_slices = 7;
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c = RsdConfig{};
  c.rsd_rings = 1;
  try {
    c.validate();
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("rsd_rings"), std::string::npos);
  }
}

TEST(Rsd, QuarterTurnLeavesDescriptorUnchanged) {
  // A 90 degree turn maps the pixel grid onto itself: every range histogram is identical,
  // and the azimuth histogram is cyclically shifted by M/4 slices, so its DFT magnitudes
  // agree too (up to points on slice boundaries).
  RsdConfig cfg;
  cfg.rsd_slices = 16;
  RsdExtractor rsd(cfg);
  // Points on the grid (multiples of the resolution) so the rotation is exact.
  auto pts = makeCloud(300, 1);
  for (auto& p : pts) p = (p / cfg.rsd_resolution).array().round() * cfg.rsd_resolution;
  const auto rot = transformed(pts, M_PI / 2, Eigen::Vector2d::Zero());
  cv::Mat d1, d2;
  rsd.compute(pts.data(), int(pts.size()), d1);
  rsd.compute(rot.data(), int(rot.size()), d2);
  ASSERT_EQ(d1.rows, int(pts.size()));
  ASSERT_EQ(d1.cols, cfg.dimension());
  int valid = 0;
  double az_err = 0.0;
  for (int i = 0; i < d1.rows; ++i) {
    EXPECT_EQ(rsdValid(d1, i), rsdValid(d2, i));
    valid += rsdValid(d1, i);
    for (int k = 0; k < cfg.rsd_rings; ++k)
      ASSERT_NEAR(d1.at<float>(i, k), d2.at<float>(i, k), 1e-6f) << "point " << i << " ring " << k;
    for (int k = cfg.rsd_rings; k < d1.cols; ++k)
      az_err = std::max(az_err, double(std::abs(d1.at<float>(i, k) - d2.at<float>(i, k))));
  }
  EXPECT_GT(valid, d1.rows * 9 / 10);
  EXPECT_LT(az_err, 0.05);
}

TEST(Rsd, RangeHistogramIsRotationInvariant) {
  // Arbitrary angle: only rasterisation changes the histograms, so they stay close.
  RsdConfig cfg;
  cfg.rsd_slices = 0;
  cfg.rsd_radius = 40.0;  // fixed here: the test is about invariance, not the defaults
  cfg.rsd_rings = 20;
  RsdExtractor rsd(cfg);
  const auto pts = makeCloud(400, 2);
  const auto rot = transformed(pts, 0.6435, Eigen::Vector2d::Zero());
  cv::Mat d1, d2;
  rsd.compute(pts.data(), int(pts.size()), d1);
  rsd.compute(rot.data(), int(rot.size()), d2);
  std::vector<double> dist;
  for (int i = 0; i < d1.rows; ++i)
    if (rsdValid(d1, i)) dist.push_back(cv::norm(d1.row(i), d2.row(i), cv::NORM_L2));
  std::sort(dist.begin(), dist.end());
  ASSERT_FALSE(dist.empty());
  EXPECT_LT(dist[dist.size() / 2], 0.15);  // unit-norm histograms: small next to 2
  RsdMatcher matcher;
  std::vector<Match> m;
  matcher.match(d1, d2, 0.9, m);
  EXPECT_GT(m.size(), pts.size() / 4);
  EXPECT_GT(correctFraction(m), 0.9);
}

TEST(Rsd, ShiftedRotatedCopyMatchesItself) {
  RsdExtractor rsd;  // defaults, with the azimuth part
  const auto pts = makeCloud(400, 3);
  const auto moved = transformed(pts, 2.9, Eigen::Vector2d(12.34, -4.71));
  cv::Mat d1, d2;
  rsd.compute(pts.data(), int(pts.size()), d1);
  rsd.compute(moved.data(), int(moved.size()), d2);
  RsdMatcher matcher;
  std::vector<Match> m;
  matcher.match(d1, d2, 0.9, m);
  EXPECT_GT(m.size(), pts.size() / 4);
  EXPECT_GT(correctFraction(m), 0.9);
  for (const Match& x : m) EXPECT_GE(x.distance, 0.f);
}

TEST(Rsd, IsolatedPointsGetNoDescriptorAndAreNotMatched) {
  RsdConfig cfg;
  cfg.rsd_min_neighbours = 3;
  RsdExtractor rsd(cfg);
  std::vector<Eigen::Vector2d> pts = {{0, 0}, {1, 0}, {0, 1}, {1, 1}, {150, 150}};
  cv::Mat d;
  rsd.compute(pts.data(), int(pts.size()), d);
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(rsdValid(d, i));
  EXPECT_FALSE(rsdValid(d, 4));
  // Two keypoints in one pixel share one occupied pixel (binary grid) and one descriptor.
  std::vector<Eigen::Vector2d> dup = {{0, 0}, {0.01, 0.01}, {1, 0}, {0, 1}, {1, 1}};
  cv::Mat dd;
  rsd.compute(dup.data(), int(dup.size()), dd);
  EXPECT_EQ(cv::norm(dd.row(0), dd.row(1), cv::NORM_L2), 0.0);
  EXPECT_EQ(cv::norm(dd.row(0), d.row(0), cv::NORM_L2), 0.0);
  RsdMatcher matcher;
  std::vector<Match> m;
  matcher.match(d, d, 1.0, m);
  for (const Match& x : m) EXPECT_NE(x.i1, 4);
  cv::Mat empty(0, cfg.dimension(), CV_32F);
  matcher.match(empty, d, 0.8, m);
  EXPECT_TRUE(m.empty());
  rsd.compute(nullptr, 0, dd);
  EXPECT_EQ(dd.rows, 0);
}

TEST(Rsd, GateRestrictsCandidates) {
  RsdExtractor rsd;
  const auto pts = makeCloud(400, 4);
  const Eigen::Vector2d t(30.0, 5.0);
  const auto moved = transformed(pts, 0.0, t);
  cv::Mat d1, d2;
  rsd.compute(pts.data(), int(pts.size()), d1);
  rsd.compute(moved.data(), int(moved.size()), d2);
  // Prior: moved = pts + t. Predict the first cloud in the second's frame.
  const auto pred = transformed(pts, 0.0, t + Eigen::Vector2d(0.7, -0.4));  // prior 0.8 m off
  RsdMatcher matcher;
  std::vector<Match> gated, ungated;
  matcher.match(d1, d2, 0.9, gated, pred.data(), moved.data(), 3.0);
  matcher.match(d1, d2, 0.9, ungated);
  for (const Match& x : gated) EXPECT_LT((pred[x.i1] - moved[x.i2]).norm(), 3.0);
  EXPECT_GT(correctFraction(gated), 0.95);
  EXPECT_GE(gated.size(), ungated.size());
  // A gate that excludes everything yields nothing.
  const auto far = transformed(pts, 0.0, Eigen::Vector2d(1000, 1000));
  matcher.match(d1, d2, 0.9, gated, far.data(), moved.data(), 3.0);
  EXPECT_TRUE(gated.empty());
}

TEST(Rsd, TimingPrinted) {
  // Radar-scan-sized input: ~3000 keypoints within 120 m. Printed, never asserted.
  std::mt19937 rng(5);
  std::vector<Eigen::Vector2d> pts = makeCloud(1500, 5);
  std::normal_distribution<double> n(0.0, 0.05);
  auto moved = transformed(pts, 3.0, Eigen::Vector2d(4.0, 1.0));
  for (auto& p : moved) p += Eigen::Vector2d(n(rng), n(rng));
  RsdExtractor rsd;
  RsdMatcher matcher;
  cv::Mat d1, d2;
  std::vector<Match> m;
  rsd.compute(pts.data(), int(pts.size()), d1);  // warm-up
  // Thread CPU time: the machine is shared, wall time would measure the neighbours.
  auto cpuMs = [] {
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return 1e3 * ts.tv_sec + 1e-6 * ts.tv_nsec;
  };
  const double t0 = cpuMs();
  const int reps = 5;
  for (int r = 0; r < reps; ++r) rsd.compute(moved.data(), int(moved.size()), d2);
  const double t1 = cpuMs();
  for (int r = 0; r < reps; ++r) matcher.match(d1, d2, 0.9, m);
  const double t2 = cpuMs();
  const double ms_c = (t1 - t0) / reps, ms_m = (t2 - t1) / reps;
  std::printf("RSD %zu keypoints, dim %d: compute %.2f ms, match %.2f ms CPU (%zu matches, %.0f%% correct)\n",
              pts.size(), d1.cols, ms_c, ms_m, m.size(), 100.0 * correctFraction(m));
  EXPECT_GT(correctFraction(m), 0.8);
}

}  // namespace
}  // namespace spinradar
