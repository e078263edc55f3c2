// Loading into an existing scan (ScanFolder::load(i, scan), loadOxfordPng/loadBoreasPng into a
// scan): the same scan as a fresh load, field by field, and no heap allocation once warmed up.
#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include "support/count_allocations.hpp"
#include "support/temp_dir.hpp"
#include "spinradar/io/scan_folder.hpp"
#include "spinradar/io/scan_io.hpp"

using namespace spinradar;
namespace fs = std::filesystem;

namespace {

/// A full-size Oxford-like scan; scan k has its own power, stamps and a few missing rows.
PolarScan makeScan(int k, int bins = 3768) {
  PolarScan s;
  s.resize(400, bins);
  std::mt19937 rng(k + 1);
  std::uniform_int_distribution<int> u(0, 255);
  for (auto& p : s.power) p = static_cast<uint8_t>(u(rng));
  const int64_t t0_us = 1547131046353776LL + k * 250000LL;
  for (int a = 0; a < 400; ++a) {
    s.encoder[a] = static_cast<uint16_t>((13 + a * 14) % 5600);
    s.azimuth[a] = 2.0 * M_PI * s.encoder[a] / 5600.0;
    s.stamp_ns[a] = (t0_us + a * 625) * 1000;
  }
  s.valid[(7 * k) % 400] = 0;
  return s;
}

void expectSameScan(const PolarScan& a, const PolarScan& b) {
  EXPECT_EQ(a.azimuths, b.azimuths);
  EXPECT_EQ(a.bins, b.bins);
  EXPECT_EQ(a.range_resolution, b.range_resolution);
  EXPECT_EQ(a.range_offset, b.range_offset);
  EXPECT_EQ(a.encoder_size, b.encoder_size);
  EXPECT_EQ(a.power, b.power);
  EXPECT_EQ(a.azimuth, b.azimuth);
  EXPECT_EQ(a.stamp_ns, b.stamp_ns);
  EXPECT_EQ(a.encoder, b.encoder);
  EXPECT_EQ(a.valid, b.valid);
  EXPECT_EQ(a.chirp_up, b.chirp_up);
}

}  // namespace

TEST(ScanReuse, FolderLoadIntoEqualsFreshLoadWithoutAllocating) {
  test::TempDir d("spinradar_scan_reuse");
  const int n = 6;
  for (int k = 0; k < n; ++k) {
    const PolarScan s = makeScan(k);
    saveOxfordPng(s, d.file(std::to_string(s.stamp_ns[0] / 1000) + ".png"));
  }
  const ScanFolder folder(d.path.string());
  ASSERT_EQ(folder.size(), size_t(n));
  PolarScan reused;
  folder.load(0, reused);  // warm-up: sizes the scan and this thread's decoder buffers
  for (int k = 1; k < n; ++k) {
    const long before = g_allocations.load();
    folder.load(k, reused);
    const long allocations = g_allocations.load() - before;
    EXPECT_EQ(allocations, 0) << "scan " << k;
    const PolarScan fresh = folder.load(k);
    expectSameScan(reused, fresh);
    EXPECT_EQ(reused.valid[(7 * k) % 400], 0);  // the file's own missing row, not a stale one
  }
}

TEST(ScanReuse, EveryFieldIsOverwritten) {
  test::TempDir d("spinradar_scan_reuse");
  // A Boreas-RT scan (chirps, 6848 bins, offset -0.31) loaded into first, then an Oxford scan:
  // nothing of the first may remain.
  PolarScan boreas = makeScan(3, 6848);
  boreas.chirp_up.resize(400);
  for (int a = 0; a < 400; ++a) boreas.chirp_up[a] = a % 2;
  boreas.valid.assign(400, 1);
  saveBoreasPng(boreas, d.file("b.png"));
  saveOxfordPng(makeScan(1), d.file("o.png"));
  PolarScan s;
  loadBoreasPng(d.file("b.png"), s);
  EXPECT_EQ(s.chirp_up, boreas.chirp_up);
  EXPECT_EQ(s.range_offset, -0.31);
  loadOxfordPng(d.file("o.png"), s, 0.05, 0.2);
  expectSameScan(s, loadOxfordPng(d.file("o.png"), 0.05, 0.2));
  EXPECT_TRUE(s.chirp_up.empty());
  loadBoreasPng(d.file("b.png"), s);
  expectSameScan(s, loadBoreasPng(d.file("b.png")));
  // A failed load names the file; the scan can be loaded into again afterwards.
  EXPECT_THROW(loadOxfordPng(d.file("missing.png"), s), std::runtime_error);
  loadOxfordPng(d.file("o.png"), s);
  expectSameScan(s, loadOxfordPng(d.file("o.png")));
}

TEST(ScanReuse, RealOxfordScans) {
  const std::string root = std::string(SPINRADAR_SHARED_DIR) + "/realdata/oxford_2019-01-10-14-36-48";
  if (!fs::exists(root)) GTEST_SKIP() << "real sample " << root << " not found (needs shared/realdata beside the clone)";
  const ScanFolder folder(root);
  ASSERT_EQ(folder.size(), 3u);
  PolarScan reused;
  folder.load(2, reused);
  for (size_t k = 0; k < 3; ++k) {
    const long before = g_allocations.load();
    folder.load(k, reused);
    EXPECT_EQ(g_allocations.load() - before, 0) << "scan " << k;
    expectSameScan(reused, folder.load(k));
  }
}
