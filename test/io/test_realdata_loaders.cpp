// Every loader reads its real sample from ../shared/realdata with the right dimensions,
// resolution and stamps.
#include <gtest/gtest.h>

#include <filesystem>

#include "spinradar/io/scan_folder.hpp"
#include "spinradar/io/scan_io.hpp"

using namespace spinradar;
namespace fs = std::filesystem;

namespace {
const std::string kReal = std::string(SPINRADAR_SHARED_DIR) + "/realdata";

#define REQUIRE_PATH(p)                                                                  \
  if (!fs::exists(p)) {                                                                  \
    GTEST_SKIP() << "real sample " << (p)                                                \
                 << " not found (needs shared/realdata beside the clone, or set "        \
                    "-DSPINRADAR_SHARED_DIR=...)";                                       \
  }

int countValid(const PolarScan& s) { return static_cast<int>(std::count(s.valid.begin(), s.valid.end(), 1)); }
}  // namespace

TEST(RealData, OxfordFolder) {
  const std::string root = kReal + "/oxford_2019-01-10-14-36-48";
  REQUIRE_PATH(root);
  ScanFolder folder(root);
  EXPECT_EQ(folder.format(), ScanFormat::Oxford);
  ASSERT_EQ(folder.size(), 3u);
  EXPECT_EQ(folder.fileStampNs(0), 1547131046353776LL * 1000);
  EXPECT_EQ(folder.fileStampNs(2), 1547131046858560LL * 1000);
  for (size_t i = 0; i < folder.size(); ++i) {
    const PolarScan s = folder.load(i);
    EXPECT_EQ(s.azimuths, 400);
    EXPECT_EQ(s.bins, 3768);
    EXPECT_DOUBLE_EQ(s.range_resolution, 0.0438);
    EXPECT_EQ(countValid(s), 400);
    // File name = stamp of the first azimuth.
    EXPECT_EQ(s.stamp_ns.front(), folder.fileStampNs(i));
    EXPECT_EQ(s.encoder[0], 13);
    EXPECT_EQ(s.encoder[1] - s.encoder[0], 14);
    // One rotation takes about 250 ms; mean row spacing about 625 us.
    const double span_ms = (s.stamp_ns.back() - s.stamp_ns.front()) * 1e-6;
    EXPECT_GT(span_ms, 230.0);
    EXPECT_LT(span_ms, 260.0);
  }
  const PolarScan s = loadOxfordPng(folder.path(0), 0.0432);
  EXPECT_DOUBLE_EQ(s.range_resolution, 0.0432);
  EXPECT_NEAR(s.rangeOfBin(3767), 3768 * 0.0432, 0.03);
}

TEST(RealData, BoreasRtChirps) {
  const std::string p = kReal + "/boreas_rt/test_frame.png";
  REQUIRE_PATH(p);
  const PolarScan s = loadBoreasPng(p);
  EXPECT_EQ(s.azimuths, 400);
  EXPECT_EQ(s.bins, 6848);
  EXPECT_DOUBLE_EQ(s.range_resolution, 0.04381);
  EXPECT_DOUBLE_EQ(s.range_offset, -0.31);
  ASSERT_EQ(s.chirp_up.size(), 400u);
  int ups = 0;
  for (int a = 0; a < 400; ++a) {
    ups += s.chirp_up[a];
    if (a > 0) {
      EXPECT_NE(s.chirp_up[a], s.chirp_up[a - 1]) << "row " << a;
    }
  }
  EXPECT_EQ(ups, 200);
  EXPECT_EQ(countValid(s), 400);
  // Stamps uniform at about 625 us.
  const double mean_us = (s.stamp_ns.back() - s.stamp_ns.front()) * 1e-3 / 399.0;
  EXPECT_NEAR(mean_us, 625.0, 15.0);
}

TEST(RealData, MulranCsv) {
  const std::string dir = kReal + "/mulran";
  REQUIRE_PATH(dir);
  ScanFolder folder(dir);
  EXPECT_EQ(folder.format(), ScanFormat::MulRan);
  ASSERT_EQ(folder.size(), 1u);
  EXPECT_EQ(folder.fileStampNs(0), 1564718976161407002LL);
  const PolarScan s = folder.load(0);
  EXPECT_EQ(s.azimuths, 400);
  EXPECT_EQ(s.bins, 3360);
  EXPECT_DOUBLE_EQ(s.range_resolution, 0.0595238);
  EXPECT_EQ(s.stamp_ns.front(), 1564718975911638410LL);
  EXPECT_EQ(s.stamp_ns.back(), folder.fileStampNs(0));  // file name = last azimuth
  EXPECT_EQ(s.encoder[0], 9);
  EXPECT_NEAR(s.azimuth[0] * 180 / M_PI, 0.57857, 1e-4);
  EXPECT_EQ(s.row(0)[0], 31);
  EXPECT_EQ(countValid(s), 400);
}

TEST(RealData, RadiateFolder) {
  const std::string root = kReal + "/radiate_fog_6_0";
  REQUIRE_PATH(root);
  ScanFolder folder(root);
  EXPECT_EQ(folder.format(), ScanFormat::Radiate);
  ASSERT_EQ(folder.size(), 18u);
  EXPECT_EQ(folder.fileStampNs(0), 1574859771744660272LL);
  EXPECT_EQ(folder.fileStampNs(17), 1574859775933347134LL);
  const PolarScan s = folder.load(1);
  EXPECT_EQ(s.azimuths, 400);
  EXPECT_EQ(s.bins, 576);
  EXPECT_DOUBLE_EQ(s.range_resolution, 0.17361);
  EXPECT_EQ(s.stamp_ns.front(), 1574859771977525228LL);
  EXPECT_NEAR((s.stamp_ns.back() - s.stamp_ns.front()) * 1e-9, 0.25 * 399 / 400, 1e-6);
  // Also works when pointed at the image folder itself.
  ScanFolder inner(root + "/Navtech_Polar");
  EXPECT_EQ(inner.format(), ScanFormat::Radiate);
  EXPECT_EQ(inner.fileStampNs(0), folder.fileStampNs(0));
}

// A Navtech-layout PNG whose name is not a stamp (Boreas-RT's test_frame.png) is listed with
// the stamp embedded in its first row, so `spinradar odometry --input` accepts the folder.
TEST(RealData, BoreasRtFolderUsesEmbeddedStamp) {
  const std::string dir = kReal + "/boreas_rt";
  REQUIRE_PATH(dir);
  const ScanFolder folder(dir, ScanFormat::Boreas);
  ASSERT_EQ(folder.size(), 1u);
  const PolarScan s = folder.load(0);
  EXPECT_EQ(folder.fileStampNs(0), s.stamp_ns.front());
  EXPECT_EQ(s.bins, 6848);
}
