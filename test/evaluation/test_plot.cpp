// Plot rendering: series land where their data says, histogram counts, ticks, file errors.
#include <filesystem>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "spinradar/evaluation/plot.hpp"

using namespace spinradar::plot;
namespace fs = std::filesystem;

namespace {

int countColor(const cv::Mat& img, const cv::Scalar& c, int tol = 40) {
  int n = 0;
  for (int r = 0; r < img.rows; ++r)
    for (int q = 0; q < img.cols; ++q) {
      const auto& p = img.at<cv::Vec3b>(r, q);
      if (std::abs(p[0] - c[0]) + std::abs(p[1] - c[1]) + std::abs(p[2] - c[2]) < tol) ++n;
    }
  return n;
}

}  // namespace

TEST(Plot, LineIsDrawnInsideAxesInItsColour) {
  const cv::Scalar red(0, 0, 255);
  Plot p;
  p.title("t").xlabel("x").ylabel("y").xlim(0, 10).ylim(0, 10);
  p.line({0, 10}, {5, 5}, "", red, 3);  // horizontal line at mid-height
  const cv::Mat img = p.render(400, 300);
  ASSERT_EQ(img.size(), cv::Size(400, 300));
  EXPECT_GT(countColor(img, red), 100);
  // All red pixels lie on one row band (the line), none outside the axes.
  int rmin = img.rows, rmax = 0;
  for (int r = 0; r < img.rows; ++r)
    for (int c = 0; c < img.cols; ++c) {
      const auto& px = img.at<cv::Vec3b>(r, c);
      if (px[2] > 200 && px[0] < 60 && px[1] < 60) {
        rmin = std::min(rmin, r);
        rmax = std::max(rmax, r);
      }
    }
  EXPECT_LE(rmax - rmin, 4);
}

TEST(Plot, LegendScatterAndClipping) {
  Plot p;
  p.xlim(0, 1).ylim(0, 1).scatter({0.5, 5.0}, {0.5, 5.0}, "points", cv::Scalar(255, 0, 0), 4);
  p.line({-10, 10}, {-10, 10}, "diag", cv::Scalar(0, 200, 0));
  const cv::Mat img = p.render(300, 300);
  EXPECT_GT(countColor(img, cv::Scalar(255, 0, 0)), 20);
  EXPECT_GT(countColor(img, cv::Scalar(0, 200, 0)), 100);
}

TEST(Plot, HistogramCountsAndBars) {
  const Histogram h = histogram({0.1, 0.2, 0.6, 0.9, 1.0, 5.0}, 2, 0.0, 1.0);
  ASSERT_EQ(h.counts.size(), 2u);
  EXPECT_EQ(h.counts[0], 2);
  EXPECT_EQ(h.counts[1], 3);  // 1.0 belongs to the last bin; 5.0 is outside
  EXPECT_DOUBLE_EQ(h.centres[1], 0.75);
  Plot p;
  p.bars(h, "h", cv::Scalar(0, 128, 255));
  EXPECT_GT(countColor(p.render(300, 200), cv::Scalar(0, 128, 255)), 500);
}

TEST(Plot, NiceTicks) {
  const auto t = niceTicks(0, 10, 5);
  ASSERT_FALSE(t.empty());
  EXPECT_DOUBLE_EQ(t.front(), 0);
  EXPECT_DOUBLE_EQ(t.back(), 10);
  const auto u = niceTicks(-0.013, 0.021, 4);
  for (size_t i = 1; i < u.size(); ++i) EXPECT_NEAR(u[i] - u[i - 1], 0.01, 1e-12);
}

TEST(Plot, EmptyAndDegenerateDataStillRender) {
  Plot p;
  EXPECT_NO_THROW(p.render(200, 150));
  p.line({1, 1}, {2, 2});
  EXPECT_NO_THROW(p.equalAspect().render(200, 150));
  EXPECT_THROW(p.line({1, 2}, {1}), std::invalid_argument);
}

TEST(Plot, TileAndSave) {
  Plot p;
  p.line({0, 1}, {0, 1});
  const cv::Mat a = p.render(200, 100), b = p.render(150, 120);
  const cv::Mat t = tile({a, b, a}, 2);
  EXPECT_EQ(t.size(), cv::Size(400, 200));
  const std::string path = (fs::temp_directory_path() / "spinradar_test_plot.png").string();
  saveImage(t, path);
  EXPECT_EQ(cv::imread(path).size(), t.size());
  fs::remove(path);
  EXPECT_THROW(saveImage(t, "/nonexistent/dir/plot.png"), std::runtime_error);
}
