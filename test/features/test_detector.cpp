// Detectors find injected targets at known ranges/azimuths in a noisy scan with few false alarms.
#include <gtest/gtest.h>

#include "support/feature_test_utils.hpp"
#include "spinradar/features/detector.hpp"

using namespace spinradar;
using spinradar::test::Target;

namespace {

std::vector<Target> someTargets() {
  std::vector<Target> t;
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> az(0, 2 * M_PI), r(5, 150);
  for (int i = 0; i < 60; ++i) t.push_back({az(rng), r(rng), 35.0});
  return t;
}

struct Score {
  int found = 0, false_alarms = 0;
};

Score evaluate(const PolarScan& s, const std::vector<Target>& targets, const std::vector<Keypoint>& kps) {
  Score sc;
  const double daz = 2 * M_PI / s.azimuths;
  for (const auto& t : targets) {
    // the azimuth row closest to the target
    bool ok = false;
    for (const auto& k : kps) {
      if (std::abs(std::remainder(k.azimuth - t.azimuth, 2 * M_PI)) <= 0.5 * daz + 1e-9 &&
          std::abs(k.range - t.range) < 1.5 * s.range_resolution)
        ok = true;
    }
    sc.found += ok;
  }
  for (const auto& k : kps) {
    bool near = false;
    for (const auto& t : targets)
      near |= std::abs(std::remainder(k.azimuth - t.azimuth, 2 * M_PI)) <= 4.5 * daz &&
              std::abs(k.range - t.range) < 8 * s.range_resolution;
    sc.false_alarms += !near;
  }
  return sc;
}

void checkGeometry(const PolarScan& s, const std::vector<Keypoint>& kps, const DetectorConfig& c) {
  for (const auto& k : kps) {
    ASSERT_GE(k.azimuth_index, 0);
    ASSERT_LT(k.azimuth_index, s.azimuths);
    EXPECT_DOUBLE_EQ(k.azimuth, s.azimuth[k.azimuth_index]);
    EXPECT_EQ(k.stamp_ns, s.stamp_ns[k.azimuth_index]);
    EXPECT_NEAR(k.range, s.rangeOfBin(k.bin) + c.range_offset, 1e-4);  // bin is a float
    EXPECT_NEAR(k.x, k.range * std::cos(k.azimuth), 1e-9);
    EXPECT_NEAR(k.y, -k.range * std::sin(k.azimuth), 1e-9);
    EXPECT_GE(k.range, c.min_range);
    EXPECT_LE(k.range, c.max_range);
    EXPECT_GT(k.power, 0.f);
  }
}

}  // namespace

class DetectorTest : public ::testing::TestWithParam<std::string> {};

TEST_P(DetectorTest, FindsInjectedTargetsWithFewFalseAlarms) {
  const auto targets = someTargets();
  const PolarScan s = test::syntheticScan(targets);
  DetectorConfig c;
  c.azimuth_peaks = false;  // the paper's Cen2018 / CFAR: keypoints per row
  c.detector = GetParam();
  Detector d(c);
  std::vector<Keypoint> kps;
  d.detect(s, kps);
  const Score sc = evaluate(s, targets, kps);
  std::printf("%s: %zu keypoints, %d / %zu targets found, %d false alarms\n", c.detector.c_str(), kps.size(),
              sc.found, targets.size(), sc.false_alarms);
  EXPECT_EQ(sc.found, static_cast<int>(targets.size()));
  EXPECT_LE(sc.false_alarms, 20) << "out of " << s.azimuths * s.bins << " cells";
  checkGeometry(s, kps, c);
}

TEST_P(DetectorTest, RespectsRangeLimitsOffsetAndValidFlags) {
  std::vector<Target> targets = {{0.3, 2.0, 40}, {1.0, 10.0, 40}, {2.0, 40.0, 40}, {3.0, 120.0, 40}};
  PolarScan s = test::syntheticScan(targets, 3);
  DetectorConfig c;
  c.azimuth_peaks = false;  // the paper's Cen2018 / CFAR: keypoints per row
  c.detector = GetParam();
  c.min_range = 5.0;
  c.max_range = 100.0;
  c.range_offset = -0.31;
  Detector d(c);
  std::vector<Keypoint> kps;
  d.detect(s, kps);
  checkGeometry(s, kps, c);
  auto near = [&](const Target& t) {
    for (const auto& k : kps)
      if (std::abs(std::remainder(k.azimuth - t.azimuth, 2 * M_PI)) < 0.01 && std::abs(k.range - (t.range - 0.31)) < 0.1)
        return true;
    return false;
  };
  EXPECT_FALSE(near(targets[0]));  // closer than min_range
  EXPECT_TRUE(near(targets[1]));
  EXPECT_TRUE(near(targets[2]));
  EXPECT_FALSE(near(targets[3]));  // beyond max_range
  // Invalid rows are skipped.
  for (int a = 0; a < s.azimuths; ++a)
    if (std::abs(std::remainder(s.azimuth[a] - 1.0, 2 * M_PI)) < 0.1) s.valid[a] = 0;
  d.detect(s, kps);
  EXPECT_FALSE(near(targets[1]));
  EXPECT_TRUE(near(targets[2]));
  for (const auto& k : kps) EXPECT_TRUE(s.valid[k.azimuth_index]);
}

INSTANTIATE_TEST_SUITE_P(Both, DetectorTest, ::testing::Values("cen2018", "cfar"));

TEST(Detector, Cen2018PeakIsSubBinAccurate) {
  // A target between two bins: the parabola refinement puts it within a fraction of a bin.
  PolarScan s = test::syntheticScan({{1.0, 50.0 + 0.4 * 0.0438, 35}}, 9);
  Detector d;
  std::vector<Keypoint> kps;
  d.detect(s, kps);
  double best = 1e9;
  for (const auto& k : kps)
    if (std::abs(std::remainder(k.azimuth - 1.0, 2 * M_PI)) < 0.008) best = std::min(best, std::abs(k.range - (50.0 + 0.4 * 0.0438)));
  EXPECT_LT(best, 0.5 * 0.0438);
}

TEST(Detector, FlatAndEmptyRowsGiveNoKeypoints) {
  PolarScan s;
  s.resize(16, 500);
  for (int a = 0; a < 16; ++a) s.azimuth[a] = a * 2 * M_PI / 16;
  std::fill(s.power.begin(), s.power.end(), 40);
  std::vector<Keypoint> kps;
  for (const char* det : {"cen2018", "cfar"}) {
    DetectorConfig c;
    c.azimuth_peaks = false;  // the paper's Cen2018 / CFAR: keypoints per row
    c.detector = det;
    Detector d(c);
    d.detect(s, kps);
    EXPECT_TRUE(kps.empty()) << det;
    d.detect(PolarScan{}, kps);
    EXPECT_TRUE(kps.empty()) << det;
  }
}

namespace {
/// Straightforward Cen2018 over every bin in double precision (the authors' formulation with
/// peaks instead of run middles), to check that the pruned, fixed-point detector agrees.
std::vector<std::pair<int, int>> referenceCen2018(const PolarScan& s, const DetectorConfig& c) {
  std::vector<std::pair<int, int>> out;
  const int R = (3 * c.sigma_gauss) / 2, n = s.bins;
  std::vector<double> g(2 * R + 1);
  double gs = 0;
  for (int i = -R; i <= R; ++i) gs += g[i + R] = std::exp(-0.5 * i * i / double(c.sigma_gauss * c.sigma_gauss));
  for (auto& v : g) v /= gs;
  auto refl = [n](int i) { return i < 0 ? -i : (i >= n ? 2 * n - 2 - i : i); };
  for (int a = 0; a < s.azimuths; ++a) {
    const uint8_t* row = s.row(a);
    double mean = 0;
    for (int j = 0; j < n; ++j) mean += row[j];
    mean /= n;
    double ss = 0;
    int cnt = 0;
    for (int j = 0; j < n; ++j)
      if (row[j] - mean < 0) ss += 2 * (row[j] - mean) * (row[j] - mean), ++cnt;
    const double sigma = std::sqrt(ss / cnt);
    int best = -1;
    double best_y = 0;
    for (int j = 0; j <= n; ++j) {
      bool hit = false;
      double y = 0;
      const double range = j < n ? s.rangeOfBin(j) : 1e9;
      if (j < n && range >= c.min_range && range <= c.max_range) {
        double p = 0;
        for (int k = -R; k <= R; ++k) p += g[k + R] * (row[refl(j + k)] - mean);
        const double q = row[j] - mean;
        const double nqp = std::exp(-0.5 * std::pow((q - p) / sigma, 2));
        const double npp = std::exp(-0.5 * std::pow(p / sigma, 2));
        y = q * (1 - nqp) + p * (nqp - npp);
        hit = y > c.zq * sigma;
      }
      if (hit) {
        if (best < 0 || y > best_y) best = j, best_y = y;
      } else if (best >= 0) {
        out.emplace_back(a, best);
        best = -1;
      }
    }
  }
  return out;
}
}  // namespace

TEST(Detector, Cen2018AgreesWithBruteForceReference) {
  std::vector<Target> targets;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> az(0, 2 * M_PI), r(3, 150), snr(15, 45);
  for (int i = 0; i < 300; ++i) targets.push_back({az(rng), r(rng), snr(rng)});
  const PolarScan s = test::syntheticScan(targets, 11, 100, 2000);
  for (double zq : {1.0, 2.0, 3.0}) {
    DetectorConfig c;
    c.azimuth_peaks = false;  // the paper's Cen2018 / CFAR: keypoints per row
    c.zq = zq;
    Detector d(c);
    std::vector<Keypoint> kps;
    d.detect(s, kps);
    const auto ref = referenceCen2018(s, c);
    int matched = 0;
    for (const auto& [a, b] : ref)
      for (const auto& k : kps)
        if (k.azimuth_index == a && std::abs(k.bin - b) <= 0.51f) {
          ++matched;
          break;
        }
    std::printf("zq %.0f: reference %zu, detector %zu, matched %d\n", zq, ref.size(), kps.size(), matched);
    EXPECT_NEAR(double(kps.size()), double(ref.size()), 0.01 * ref.size() + 1);
    EXPECT_GE(matched, 0.99 * ref.size() - 1);
  }
}

TEST(Detector, Cen2018CandidateBoundLosesNothing) {
  // Only bins that can reach zq sigma are scored (detector.cpp): the keypoints must be exactly
  // those of scoring every bin, on speckle with weak and strong targets and several thresholds.
  std::vector<Target> targets;
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> az(0, 2 * M_PI), r(3, 150), snr(3, 40);
  for (int i = 0; i < 500; ++i) targets.push_back({az(rng), r(rng), snr(rng)});
  for (unsigned seed : {1u, 2u}) {
    const PolarScan s = test::syntheticScan(targets, seed, 200, 3000);
    for (double zq : {0.5, 1.0, 2.0, 2.5, 3.0}) {
      DetectorConfig c;
      c.azimuth_peaks = false;  // the paper's Cen2018 / CFAR: keypoints per row
      c.zq = zq;
      Detector fast(c), every(c);
      every.setScoreEveryBin(true);
      std::vector<Keypoint> a, b;
      fast.detect(s, a);
      every.detect(s, b);
      ASSERT_EQ(a.size(), b.size()) << "zq " << zq;
      ASSERT_GT(a.size(), 100u) << "zq " << zq << ", seed " << seed;
      for (size_t i = 0; i < a.size(); ++i) {
        ASSERT_EQ(a[i].azimuth_index, b[i].azimuth_index) << "zq " << zq;
        ASSERT_EQ(a[i].bin, b[i].bin) << "zq " << zq;
        ASSERT_EQ(a[i].power, b[i].power) << "zq " << zq;
      }
    }
  }
}
