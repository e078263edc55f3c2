// The Cartesian image puts a return at (r, phi) at the right pixel; tables are cached.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <thread>

#include <opencv2/core.hpp>

#include "spinradar/features/cartesian.hpp"

using namespace spinradar;

namespace {

PolarScan emptyScan(int azimuths = 400, int bins = 3768, double res = 0.0438, int first_encoder = 13) {
  PolarScan s;
  s.resize(azimuths, bins);
  s.range_resolution = res;
  const int step = 5600 / azimuths;
  for (int a = 0; a < azimuths; ++a) {
    s.encoder[a] = static_cast<uint16_t>((first_encoder + a * step) % 5600);
    s.azimuth[a] = 2 * M_PI * s.encoder[a] / 5600.0;
    s.stamp_ns[a] = a * 625000LL;
  }
  return s;
}

/// Puts a strong return of a few bins on the row nearest to phi.
int addReturn(PolarScan& s, double r, double phi) {
  int best = 0;
  for (int a = 1; a < s.azimuths; ++a)
    if (std::abs(std::remainder(s.azimuth[a] - phi, 2 * M_PI)) < std::abs(std::remainder(s.azimuth[best] - phi, 2 * M_PI)))
      best = a;
  const int b = static_cast<int>(std::lround(s.binOfRange(r)));
  for (int j = b - 3; j <= b + 3; ++j) s.row(best)[j] = 250;
  return best;
}

/// Intensity-weighted centre of the pixels at or above half the maximum.
cv::Point2d brightest(const cv::Mat& img) {
  double mx;
  cv::minMaxLoc(img, nullptr, &mx);
  double sw = 0, sx = 0, sy = 0;
  for (int v = 0; v < img.rows; ++v)
    for (int u = 0; u < img.cols; ++u) {
      const double w = img.at<uint8_t>(v, u);
      if (w >= 0.5 * mx) sw += w, sx += w * u, sy += w * v;
    }
  return {sx / sw, sy / sw};
}

}  // namespace

TEST(Cartesian, ReturnLandsOnItsPixel) {
  CartesianProjector proj;  // 0.2592 m/px, 964 px
  cv::Mat img;
  for (double phi : {0.0, 0.4, M_PI / 2, 2.0, M_PI, 4.0, 3 * M_PI / 2, 6.2, 2 * M_PI - 0.005}) {
    for (double r : {8.0, 40.0, 110.0}) {
      PolarScan s = emptyScan();
      const int row = addReturn(s, r, phi);
      proj.render(s, img);
      ASSERT_EQ(img.rows, 964);
      ASSERT_EQ(img.type(), CV_8UC1);
      const double a = s.azimuth[row];
      const cv::Point2f want = proj.toPixel(r * std::cos(a), -r * std::sin(a));
      const cv::Point2d got = brightest(img);
      EXPECT_LE(std::hypot(got.x - want.x, got.y - want.y), 0.5) << "r " << r << " phi " << phi;
    }
  }
  EXPECT_EQ(proj.tableBuilds(), 1);
}

TEST(Cartesian, OrientationForwardIsUpRightIsRight) {
  CartesianProjector proj(0.5, 401);
  cv::Mat img;
  PolarScan fwd = emptyScan();
  addReturn(fwd, 50, 0.0);  // straight ahead
  proj.render(fwd, img);
  cv::Point2d p = brightest(img);
  EXPECT_NEAR(p.x, 200, 1);
  EXPECT_NEAR(p.y, 100, 1);  // 50 m / 0.5 m above the centre
  PolarScan right = emptyScan();
  addReturn(right, 50, M_PI / 2);  // clockwise quarter turn = to the right = -y
  proj.render(right, img);
  p = brightest(img);
  EXPECT_NEAR(p.x, 300, 1);
  EXPECT_NEAR(p.y, 200, 1);
  const cv::Point2d m = proj.toMetric(proj.toPixel(12.3, -4.5));
  EXPECT_NEAR(m.x, 12.3, 1e-4);
  EXPECT_NEAR(m.y, -4.5, 1e-4);
}

TEST(Cartesian, RangeOffsetShiftsTheImage) {
  CartesianProjector proj(0.1, 801);
  cv::Mat img;
  PolarScan s = emptyScan();
  addReturn(s, 30, 0.0);
  s.range_offset = -0.31;
  proj.render(s, img, -0.5);  // total -0.81 m
  const cv::Point2d p = brightest(img);
  EXPECT_NEAR(400 - p.y, (30 - 0.81) / 0.1, 1.0);
}

TEST(Cartesian, TablesAreCachedPerGeometry) {
  CartesianProjector proj(0.5, 200);
  cv::Mat img;
  PolarScan s = emptyScan(400, 500);
  proj.render(s, img);
  proj.render(s, img);
  EXPECT_EQ(proj.tableBuilds(), 1);
  PolarScan tiny = s;  // one encoder count of jitter (1/14 of a step): not material
  for (auto& a : tiny.azimuth) a += 2 * M_PI / 5600;
  proj.render(tiny, img);
  EXPECT_EQ(proj.tableBuilds(), 1);
  PolarScan shifted = s;  // half a step: rebuild
  for (auto& a : shifted.azimuth) a += 0.5 * 2 * M_PI / 400;
  proj.render(shifted, img);
  EXPECT_EQ(proj.tableBuilds(), 2);
  PolarScan fewer = emptyScan(200, 500);
  proj.render(fewer, img);
  EXPECT_EQ(proj.tableBuilds(), 3);
  proj.setImageGeometry(0.25, 200);
  proj.render(fewer, img);
  EXPECT_EQ(proj.tableBuilds(), 4);
}

TEST(Cartesian, SharedTablesAreBuiltOnceForAllThreads) {
  PolarScan s = emptyScan();
  std::mt19937 rng(4);
  std::uniform_int_distribution<int> u(0, 255);
  for (auto& p : s.power) p = static_cast<uint8_t>(u(rng));
  CartesianProjector solo;
  cv::Mat want;
  solo.render(s, want);
  // Four projectors on four threads, one table cache: one build, the same tables, the same image.
  auto shared = std::make_shared<CartesianTableCache>(0.2592, 964);
  std::vector<CartesianProjector> projectors(4, CartesianProjector(shared));
  std::vector<cv::Mat> images(projectors.size());
  std::vector<std::thread> threads;
  for (size_t t = 0; t < projectors.size(); ++t)
    threads.emplace_back([&, t] { projectors[t].render(s, images[t]); });
  for (auto& t : threads) t.join();
  EXPECT_EQ(shared->builds(), 1);
  int builds = 0;
  for (size_t t = 0; t < projectors.size(); ++t) {
    builds += projectors[t].tableBuilds();
    EXPECT_EQ(projectors[t].remap(), projectors[0].remap());
    EXPECT_EQ(cv::norm(images[t], want, cv::NORM_INF), 0.0) << "thread " << t;
  }
  EXPECT_EQ(builds, 1);
  // One encoder count of jitter keeps the shared tables; a new geometry is built once more,
  // and the projector still holding the old tables may keep using them.
  PolarScan jitter = s;
  for (auto& a : jitter.azimuth) a += 2 * M_PI / 5600;
  projectors[1].render(jitter, images[1]);
  EXPECT_EQ(shared->builds(), 1);
  PolarScan shifted = s;
  for (auto& a : shifted.azimuth) a += 0.5 * 2 * M_PI / 400;
  projectors[2].render(shifted, images[2]);
  projectors[3].render(shifted, images[3]);
  EXPECT_EQ(shared->builds(), 2);
  EXPECT_EQ(projectors[3].remap(), projectors[2].remap());
  projectors[0].render(s, images[0]);
  EXPECT_EQ(cv::norm(images[0], want, cv::NORM_INF), 0.0);
  // Another image geometry gets tables of its own.
  projectors[0].setImageGeometry(0.5, 200);
  EXPECT_NE(projectors[0].tables(), shared);
}

TEST(Cartesian, InvalidRowsDoNotLeaveGapsAndFarPixelsAreBlack) {
  PolarScan s = emptyScan(400, 400, 0.1);  // 40 m of range
  std::fill(s.power.begin(), s.power.end(), 100);
  for (int a : {0, 57, 58, 399}) {
    s.valid[a] = 0;
    std::fill(s.row(a), s.row(a) + s.bins, 0);
  }
  CartesianProjector proj(0.25, 401);  // 50 m half width
  cv::Mat img;
  proj.render(s, img);
  int inside = 0;
  for (int v = 0; v < 401; ++v)
    for (int u = 0; u < 401; ++u) {
      const double r = std::hypot(v - 200, u - 200) * 0.25;
      if (r > 1.0 && r < 39.0) {
        ++inside;
        ASSERT_EQ(img.at<uint8_t>(v, u), 100) << v << "," << u;
      }
      if (r > 40.5) {
        ASSERT_EQ(img.at<uint8_t>(v, u), 0) << v << "," << u;
      }
    }
  EXPECT_GT(inside, 70000);
}

TEST(Cartesian, SimdAndPortableRemapAgree) {
  PolarScan s = emptyScan();
  std::mt19937 rng(2);
  std::uniform_int_distribution<int> u(0, 255);
  for (auto& p : s.power) p = static_cast<uint8_t>(u(rng));
  s.valid[100] = 0;
  CartesianProjector simd, avx2, portable;  // AVX-512 (when the CPU has it), AVX2, portable
  avx2.setSimdLevel(1);
  portable.setUseSimd(false);
  cv::Mat a, b, c;
  simd.render(s, a);
  avx2.render(s, c);
  portable.render(s, b);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(c, b, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::countNonZero(b), 500000);  // a real image: noise everywhere within range
}

TEST(Cartesian, SimdAndPortableTableBuildsAgree) {
  // Several scan geometries: the default, a range offset, fewer bins than the image's radius
  // (pixels beyond the last bin take the zero row), a coarse box and uneven azimuths.
  std::vector<std::pair<PolarScan, double>> cases;
  cases.push_back({emptyScan(), 0.0});
  cases.push_back({emptyScan(), -0.31});
  cases.push_back({emptyScan(400, 900, 0.0438), 0.2});
  cases.push_back({emptyScan(200, 3000, 0.175), 0.0});
  PolarScan uneven = emptyScan(400, 3768, 0.0438, 5000);  // wraps past 2 pi mid-sweep
  for (int a = 0; a < 400; a += 7) uneven.azimuth[a] += 0.3 * 2 * M_PI / 400;
  cases.push_back({uneven, 0.0});
  int zero_row_cases = 0;
  for (const auto& [res, width] : {std::pair{0.2592, 964}, {0.17, 301}}) {
    for (size_t c = 0; c < cases.size(); ++c) {
      CartesianTableCache simd(res, width), portable(res, width);
      portable.setUseSimd(false);
      bool built = false;
      const auto a = simd.remapFor(cases[c].first, cases[c].second, built);
      const auto b = portable.remapFor(cases[c].first, cases[c].second, built);
      ASSERT_EQ(a->offsets.size(), size_t(width) * width);
      EXPECT_TRUE(a->offsets == b->offsets) << "case " << c << ", width " << width;
      EXPECT_TRUE(a->weights == b->weights) << "case " << c << ", width " << width;
      const uint32_t zero_row = uint32_t(cases[c].first.azimuths + 1) * cases[c].first.bins;
      zero_row_cases += std::count(a->offsets.begin(), a->offsets.end(), zero_row) > 0;
    }
  }
  EXPECT_GE(zero_row_cases, 3);  // pixels beyond the last bin (or before the first) were covered
}

TEST(Cartesian, PixelGeometryEqualsHypotAndAtan2PerPixel) {
  // The projector computes one octant and mirrors it (exact integer offsets of the angle code);
  // every pixel must equal the direct per-pixel computation, for even and odd widths.
  for (const auto& [res, width] : {std::pair{0.2592, 964}, {0.2592, 965}, {0.17, 301}, {1.0, 2}, {0.5, 3},
                                   {0.0438 * 6, 1000}, {0.1, 64}}) {
    CartesianProjector proj(res, width);
    const double centre = 0.5 * (width - 1);
    const auto& range = proj.pixelRanges();
    const auto& angle = proj.pixelAngles();
    ASSERT_EQ(range.size(), size_t(width) * width);
    ASSERT_EQ(angle.size(), size_t(width) * width);
    int wrong = 0;
    for (int v = 0; v < width; ++v)
      for (int u = 0; u < width; ++u) {
        const double x = (centre - v) * res, y = (centre - u) * res;
        double turns = std::atan2(-y, x) / (2.0 * M_PI);
        if (turns < 0) turns += 1.0;
        const uint16_t code = static_cast<uint16_t>(std::lround(turns * 65536.0) & 0xffff);
        const size_t i = size_t(v) * width + u;
        wrong += range[i] != static_cast<float>(std::hypot(x, y)) || angle[i] != code;
      }
    EXPECT_EQ(wrong, 0) << "width " << width << ", resolution " << res;
  }
  // Sanity of the convention: forward (up) is angle 0, right a quarter turn clockwise.
  CartesianProjector proj(1.0, 5);
  EXPECT_EQ(proj.pixelAngles()[0 * 5 + 2], 0);      // row 0 (x = +2), centre column
  EXPECT_EQ(proj.pixelAngles()[2 * 5 + 4], 16384);  // centre row, right column (y = -2)
  EXPECT_FLOAT_EQ(proj.pixelRanges()[0], std::sqrt(8.0f));
}
