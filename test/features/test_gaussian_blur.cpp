// GaussianBlur8u gives cv::GaussianBlur's bytes (8-bit, BORDER_REFLECT_101), on a whole image
// and on a view into a bordered copy (as cv::ORB calls it), on noise, on simulated and real
// Cartesian radar images and at tiny sizes, and reuses its buffers.
#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include <opencv2/imgproc.hpp>

#include "support/count_allocations.hpp"
#include "support/feature_test_utils.hpp"
#include "spinradar/features/cartesian.hpp"
#include "spinradar/features/gaussian_blur.hpp"
#include "spinradar/io/scan_folder.hpp"

using namespace spinradar;

namespace {

/// Pixels where our blur and OpenCV's differ (0 = identical): on the whole image, or for the
/// View path on a view into a copy with a reflected border, as cv::ORB blurs.
int differing(GaussianBlur8u& blur, const cv::Mat& src, int k, double sigma,
              GaussianBlur8u::Path path = GaussianBlur8u::Path::WholeImage) {
  cv::Mat ours, theirs;
  blur.apply(src, ours);
  if (path == GaussianBlur8u::Path::WholeImage) {
    cv::GaussianBlur(src, theirs, cv::Size(k, k), sigma, sigma, cv::BORDER_REFLECT_101);
  } else {
    const int b = k / 2 + 3;
    cv::Mat ext;
    cv::copyMakeBorder(src, ext, b, b, b, b, cv::BORDER_REFLECT_101);
    cv::GaussianBlur(ext(cv::Rect(b, b, src.cols, src.rows)), theirs, cv::Size(k, k), sigma, sigma,
                     cv::BORDER_REFLECT_101);
  }
  if (ours.size() != theirs.size() || ours.type() != theirs.type()) return -1;
  return cv::countNonZero(ours != theirs);
}

cv::Mat noise(int rows, int cols, unsigned seed) {
  cv::Mat m(rows, cols, CV_8UC1);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> u(0, 255);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) m.at<uint8_t>(r, c) = static_cast<uint8_t>(u(rng));
  return m;
}

}  // namespace

TEST(GaussianBlur8u, OrbsKernelHasOpenCvsFixedPointTaps) {
  // sigma 2: 0.0702, 0.1311, 0.1907, 0.2161 x 256 = 17.96, 33.56, 48.82, 55.32, rounded with the
  // error carried on (17.96 -> 18, 33.52 -> 34, 48.34 -> 48); the centre makes the sum 256.
  EXPECT_EQ(GaussianBlur8u(7, 2.0).taps(), (std::vector<uint32_t>{18, 34, 48, 56, 48, 34, 18}));
  EXPECT_THROW(GaussianBlur8u(6, 2.0), std::invalid_argument);
  EXPECT_THROW(GaussianBlur8u(7, 0.0), std::invalid_argument);
}

TEST(GaussianBlur8u, SameBytesAsOpenCvOnNoiseForSeveralKernelsAndSizes) {
  using Path = GaussianBlur8u::Path;
  for (Path path : {Path::WholeImage, Path::View}) {
    for (const auto& [k, sigma] : {std::pair{7, 2.0}, {3, 0.8}, {5, 1.2}, {9, 1.5}, {11, 3.0}, {1, 1.0}}) {
      GaussianBlur8u blur(k, sigma, path);
      for (const auto& [rows, cols] : {std::pair{120, 97}, {7, 7}, {3, 42}, {40, 2}, {1, 1}, {1, 13}, {964, 964}}) {
        EXPECT_EQ(differing(blur, noise(rows, cols, 7 + rows + cols), k, sigma, path), 0)
            << (path == Path::View ? "view" : "whole") << ", k " << k << " sigma " << sigma << ", " << rows
            << " x " << cols;
      }
    }
    // Saturated and black images: the sums are at their limits (the view's taps sum to 257).
    GaussianBlur8u blur(7, 2.0, path);
    EXPECT_EQ(differing(blur, cv::Mat(50, 61, CV_8UC1, cv::Scalar(255)), 7, 2.0, path), 0);
    EXPECT_EQ(differing(blur, cv::Mat(50, 61, CV_8UC1, cv::Scalar(0)), 7, 2.0, path), 0);
  }
  // The input may itself be a view (its step is not its width): it blurs as a copy of it would.
  GaussianBlur8u blur(7, 2.0);
  const cv::Mat big = noise(80, 90, 3);
  cv::Mat view_out, copy_out;
  blur.apply(big(cv::Rect(5, 7, 60, 50)), view_out);
  blur.apply(big(cv::Rect(5, 7, 60, 50)).clone(), copy_out);
  EXPECT_EQ(cv::countNonZero(view_out != copy_out), 0);
}

TEST(GaussianBlur8u, SameBytesAsOpenCvOnCartesianRadarImages) {
  std::vector<test::Target> targets;
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> az(0, 2 * M_PI), r(5, 160), snr(15, 45);
  for (int i = 0; i < 400; ++i) targets.push_back({az(rng), r(rng), snr(rng)});
  CartesianProjector proj;
  GaussianBlur8u whole(7, 2.0), view(7, 2.0, GaussianBlur8u::Path::View);
  cv::Mat image;
  proj.render(test::syntheticScan(targets, 4), image);
  EXPECT_EQ(differing(whole, image, 7, 2.0), 0) << "simulated scan";
  EXPECT_EQ(differing(view, image, 7, 2.0, GaussianBlur8u::Path::View), 0) << "simulated scan, view";

  const std::string root = std::string(SPINRADAR_SHARED_DIR) + "/realdata/oxford_2019-01-10-14-36-48";
  if (!std::filesystem::exists(root)) {
    GTEST_SKIP() << "real sample " << root << " not found (needs shared/realdata beside the clone)";
  }
  ScanFolder folder(root);
  ASSERT_GT(folder.size(), 0u);
  for (size_t i = 0; i < folder.size(); ++i) {
    proj.render(folder.load(i), image);
    EXPECT_EQ(differing(whole, image, 7, 2.0), 0) << "Oxford scan " << i;
    EXPECT_EQ(differing(view, image, 7, 2.0, GaussianBlur8u::Path::View), 0) << "Oxford scan " << i << ", view";
  }
}

TEST(GaussianBlur8u, EverySimdLevelGivesTheSameBytes) {
  // Levels 2 (AVX-512) and 1 (AVX2 + FMA) equal OpenCV's AVX2 build here; level 0 follows its
  // non-FMA build, which this machine does not run: off by at most 1 in a few pixels.
  std::vector<test::Target> targets;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> az(0, 2 * M_PI), r(5, 160), snr(15, 45);
  for (int i = 0; i < 300; ++i) targets.push_back({az(rng), r(rng), snr(rng)});
  CartesianProjector proj;
  cv::Mat radar;
  proj.render(test::syntheticScan(targets, 6), radar);
  for (const cv::Mat& image : {radar, noise(101, 203, 5)}) {
    cv::Mat out[3];
    for (int level = 0; level <= 2; ++level) {
      GaussianBlur8u blur(7, 2.0, GaussianBlur8u::Path::View);
      blur.setSimdLevel(level);
      if (level > 0) {
        EXPECT_EQ(differing(blur, image, 7, 2.0, GaussianBlur8u::Path::View), 0) << "level " << level;
      }
      blur.apply(image, out[level]);
    }
    EXPECT_EQ(cv::countNonZero(out[1] != out[2]), 0);
    EXPECT_LE(cv::norm(out[0], out[2], cv::NORM_INF), 1.0);
    EXPECT_LT(cv::countNonZero(out[0] != out[2]), image.total() / 100);
  }
}

TEST(GaussianBlur8u, NoAllocationOnceTheOutputHasItsSize) {
  const cv::Mat a = noise(300, 310, 1), b = noise(300, 310, 2);
  GaussianBlur8u blur(7, 2.0, GaussianBlur8u::Path::View);
  cv::Mat out;
  blur.apply(a, out);
  const long before = g_allocations;
  blur.apply(b, out);
  blur.apply(a, out);
  EXPECT_EQ(g_allocations - before, 0);
  EXPECT_THROW(blur.apply(out, out), std::invalid_argument);
}
