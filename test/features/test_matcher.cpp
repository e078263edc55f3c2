// Brute-force Hamming matching with the ratio test, against a naive reference and on ORB
// descriptors of a shifted/rotated synthetic image.
#include <gtest/gtest.h>

#include <random>

#include <opencv2/imgproc.hpp>

#include "../../src/features/matcher_kernels.hpp"  // to check every kernel, not only the chosen one
#include "spinradar/features/cartesian.hpp"
#include "spinradar/features/matcher.hpp"
#include "spinradar/features/orb_descriptors.hpp"

using namespace spinradar;

namespace {

cv::Mat randomDescriptors(int rows, int cols, std::mt19937& rng) {
  cv::Mat d(rows, cols, CV_8UC1);
  std::uniform_int_distribution<int> u(0, 255);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) d.at<uint8_t>(i, j) = static_cast<uint8_t>(u(rng));
  return d;
}

std::vector<Match> naive(const cv::Mat& d1, const cv::Mat& d2, double nndr) {
  std::vector<Match> out;
  for (int i = 0; i < d1.rows; ++i) {
    int b1 = 1 << 30, b2 = 1 << 30, bj = -1;
    for (int j = 0; j < d2.rows; ++j) {
      int d = 0;
      for (int k = 0; k < d1.cols; ++k) d += __builtin_popcount(unsigned(d1.at<uint8_t>(i, k) ^ d2.at<uint8_t>(j, k)));
      if (d < b1) b2 = b1, b1 = d, bj = j;
      else if (d < b2) b2 = d;
    }
    if (d2.rows >= 2 && b1 < nndr * b2) out.push_back({i, bj, float(b1)});
  }
  return out;
}

void expectSame(const std::vector<Match>& a, const std::vector<Match>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].i1, b[k].i1);
    EXPECT_EQ(a[k].i2, b[k].i2);
    EXPECT_EQ(a[k].distance, b[k].distance);
  }
}

}  // namespace

TEST(Matcher, FindsPlantedPairsAndAgreesWithNaive) {
  std::mt19937 rng(3);
  const cv::Mat d1 = randomDescriptors(203, 32, rng);
  // d2: a permutation of d1 with 10 bits flipped per row, plus 150 random distractors.
  std::vector<int> perm(353);
  std::iota(perm.begin(), perm.end(), 0);
  std::shuffle(perm.begin(), perm.end(), rng);
  cv::Mat d2 = randomDescriptors(353, 32, rng);
  std::uniform_int_distribution<int> bit(0, 255);
  for (int i = 0; i < d1.rows; ++i) {
    d1.row(i).copyTo(d2.row(perm[i]));
    for (int f = 0; f < 10; ++f) {
      const int b = bit(rng);
      d2.at<uint8_t>(perm[i], b / 8) ^= static_cast<uint8_t>(1 << (b % 8));
    }
  }
  std::vector<Match> m;
  matchDescriptors(d1, d2, 0.8, m);
  EXPECT_EQ(m.size(), size_t(d1.rows));
  for (const auto& x : m) EXPECT_EQ(x.i2, perm[x.i1]);
  expectSame(m, naive(d1, d2, 0.8));
  // Each kernel on its own (the AVX-512 one only where the CPU has it).
  std::vector<Match> k;
  detail::matchScalar(d1, d2, 0.8, k);
  expectSame(k, naive(d1, d2, 0.8));
  for (int rows : {1, 2, 7, 8, 9, 15, 16, 17, 24, 64, 353}) {  // block tails (8 rows, pairs of 16)
    const cv::Mat sub = d2.rowRange(0, rows);
    k.clear();
    if (detail::matchAvx2(d1, sub, 0.8, k)) {
      expectSame(k, naive(d1, sub, 0.8));
    }
    k.clear();
    if (detail::matchAvx512(d1, sub, 0.8, k)) {
      expectSame(k, naive(d1, sub, 0.8));
    } else if (rows == 1) {
      std::printf("no AVX-512 VPOPCNTDQ on this CPU: only the portable kernel is tested\n");
    }
  }
  // Query groups of every size (the AVX-512 kernel takes six queries a pass).
  for (int queries : {1, 5, 6, 7, 13}) {
    const cv::Mat sub = d1.rowRange(0, queries);
    k.clear();
    if (detail::matchAvx512(sub, d2, 0.8, k)) expectSame(k, naive(sub, d2, 0.8));
  }
  // The public per-kernel entry (bench): the kernel in use exists, every kernel that runs agrees.
  EXPECT_TRUE(matchDescriptorsWith(matchKernelUsed(), d1, d2, 0.8, k));
  for (const MatchKernel kernel : {MatchKernel::Avx512, MatchKernel::Avx2, MatchKernel::Scalar})
    if (matchDescriptorsWith(kernel, d1, d2, 0.8, k)) expectSame(k, naive(d1, d2, 0.8));
  EXPECT_FALSE(matchDescriptorsWith(MatchKernel::Scalar, d1, cv::Mat(), 0.8, k));
  // Other widths take the generic path.
  const cv::Mat g1 = randomDescriptors(37, 61, rng), g2 = randomDescriptors(45, 61, rng);
  matchDescriptors(g1, g2, 0.95, m);
  expectSame(m, naive(g1, g2, 0.95));
  // Buffers are reused: a second call clears the output first.
  matchDescriptors(d1, d2, 0.8, m);
  EXPECT_EQ(m.size(), size_t(d1.rows));
}

TEST(Matcher, EdgeCases) {
  std::mt19937 rng(4);
  std::vector<Match> m = {{1, 2, 3.f}};
  matchDescriptors(cv::Mat(), randomDescriptors(5, 32, rng), 0.8, m);
  EXPECT_TRUE(m.empty());
  const cv::Mat one = randomDescriptors(1, 32, rng);
  matchDescriptors(one, one, 0.8, m);
  EXPECT_TRUE(m.empty()) << "a single train row gives no second neighbour, so no ratio test";
  // Identical duplicates in d2 are ambiguous: rejected by the ratio test.
  cv::Mat two;
  cv::vconcat(one, one, two);
  matchDescriptors(one, two, 0.8, m);
  EXPECT_TRUE(m.empty());
  EXPECT_THROW(matchDescriptors(one, randomDescriptors(3, 16, rng), 0.8, m), std::invalid_argument);
  EXPECT_THROW(matchDescriptors(cv::Mat(3, 32, CV_32F), cv::Mat(3, 32, CV_32F), 0.8, m), std::invalid_argument);
}

namespace {
struct RotationResult {
  size_t keypoints = 0, matches = 0;
  int correct = 0;
};

/// Textured "radar" image (random blobs), a second view rotated by `deg` and shifted; ORB at the
/// blob centres of both, matched. `correct` counts matches within 2 px of the true position.
RotationResult matchRotated(double deg, bool oriented) {
  std::mt19937 rng(8);
  cv::Mat img(600, 600, CV_8UC1, cv::Scalar(0));
  std::uniform_real_distribution<double> pos(20, 580), rad(1.0, 4.0), val(60, 255);
  std::vector<cv::Point2f> blobs;
  for (int i = 0; i < 900; ++i) {
    cv::Point2f p(float(pos(rng)), float(pos(rng)));
    cv::circle(img, p, static_cast<int>(rad(rng)), cv::Scalar(val(rng)), -1, cv::LINE_AA);
    blobs.push_back(p);
  }
  cv::GaussianBlur(img, img, cv::Size(5, 5), 1.0);
  cv::Mat A = cv::getRotationMatrix2D(cv::Point2f(310, 290), deg, 1.0);
  A.at<double>(0, 2) += 7.5;
  A.at<double>(1, 2) -= 4.25;
  cv::Mat img2;
  cv::warpAffine(img, img2, A, img.size(), cv::INTER_LINEAR);

  CartesianProjector proj(0.25, 600);
  std::vector<Keypoint> k1, k2;
  for (const auto& p : blobs) {
    const cv::Point2f q(float(A.at<double>(0, 0) * p.x + A.at<double>(0, 1) * p.y + A.at<double>(0, 2)),
                        float(A.at<double>(1, 0) * p.x + A.at<double>(1, 1) * p.y + A.at<double>(1, 2)));
    if (q.x < 30 || q.y < 30 || q.x > 570 || q.y > 570 || p.x < 30 || p.y < 30 || p.x > 570 || p.y > 570) continue;
    Keypoint a, b;
    const cv::Point2d m1 = proj.toMetric(p), m2 = proj.toMetric(q);
    a.x = m1.x, a.y = m1.y, b.x = m2.x, b.y = m2.y;
    k1.push_back(a);
    k2.push_back(b);
  }
  RotationResult r;
  r.keypoints = k1.size();
  OrbDescriber orb(21, oriented);
  cv::Mat d1, d2;
  orb.describe(img, proj, k1, d1);
  orb.describe(img2, proj, k2, d2);
  EXPECT_EQ(k1.size(), r.keypoints);  // 30 px margins > the 21 px edge threshold: none dropped
  EXPECT_EQ(k2.size(), r.keypoints);
  std::vector<Match> m;
  matchDescriptors(d1, d2, 0.8, m);
  r.matches = m.size();
  for (const auto& x : m)
    r.correct += std::hypot(k2[x.i2].x - k2[x.i1].x, k2[x.i2].y - k2[x.i1].y) < 2 * proj.resolution();
  std::printf("rotation %.0f deg, %s: %zu keypoints, %zu matches, %d correct\n", deg,
              oriented ? "oriented" : "upright", r.keypoints, r.matches, r.correct);
  return r;
}
}  // namespace

TEST(Matcher, OrbOnShiftedRotatedImage) {
  // Upright descriptors (default): a typical inter-scan turn of a few degrees.
  const RotationResult up = matchRotated(5.0, false);
  ASSERT_GT(up.keypoints, 600u);
  EXPECT_GT(up.matches, up.keypoints / 2);
  EXPECT_GT(up.correct, 0.85 * up.matches);
  // Oriented descriptors survive a large rotation that upright ones do not.
  const RotationResult big_up = matchRotated(45.0, false), big_or = matchRotated(45.0, true);
  EXPECT_GT(big_or.correct, 0.7 * big_or.matches);
  EXPECT_GT(big_or.correct, big_up.keypoints / 4);
  EXPECT_LT(big_up.correct, big_or.correct / 4);
}

TEST(Orb, DropsKeypointsWhosePatchLeavesTheImageAndStaysAligned) {
  std::mt19937 rng(9);
  cv::Mat img(300, 300, CV_8UC1);
  cv::randu(img, 0, 255);
  CartesianProjector proj(1.0, 300);
  std::vector<Keypoint> kps;
  std::vector<cv::Point2f> px = {{150, 150}, {3, 150}, {100, 100}, {150, 296}, {25, 275}, {200, 60}, {10, 10}};
  for (size_t i = 0; i < px.size(); ++i) {
    Keypoint k;
    const cv::Point2d m = proj.toMetric(px[i]);
    k.x = m.x, k.y = m.y;
    k.power = float(i);  // identifies the keypoint
    kps.push_back(k);
  }
  OrbDescriber orb(21);
  cv::Mat d;
  orb.describe(img, proj, kps, d);
  std::vector<float> kept;
  for (const auto& k : kps) kept.push_back(k.power);
  EXPECT_EQ(kept, (std::vector<float>{0, 2, 4, 5}));
  ASSERT_EQ(d.rows, 4);
  // Row i is the descriptor of keypoint i alone.
  for (size_t i = 0; i < kps.size(); ++i) {
    std::vector<Keypoint> single = {kps[i]};
    cv::Mat ds;
    orb.describe(img, proj, single, ds);
    ASSERT_EQ(ds.rows, 1);
    EXPECT_EQ(cv::norm(ds.row(0), d.row(int(i)), cv::NORM_HAMMING), 0.0) << i;
  }
  // Steady state: the same number of keypoints reuses the descriptor buffer.
  const uint8_t* before = d.data;
  std::vector<Keypoint> again = kps;
  orb.describe(img, proj, again, d);
  EXPECT_EQ(d.data, before);
}

TEST(Orb, KeepStrongest) {
  std::vector<Keypoint> kps(10);
  const float powers[10] = {5, 1, 9, 3, 9, 2, 7, 3, 8, 0};
  for (int i = 0; i < 10; ++i) kps[i].power = powers[i], kps[i].azimuth_index = i;
  std::vector<float> scratch;
  keepStrongest(kps, 4, scratch);
  ASSERT_EQ(kps.size(), 4u);
  std::vector<int> idx;
  for (const auto& k : kps) idx.push_back(k.azimuth_index);
  EXPECT_EQ(idx, (std::vector<int>{2, 4, 6, 8}));  // order preserved
  keepStrongest(kps, 0, scratch);
  EXPECT_EQ(kps.size(), 4u);
}
