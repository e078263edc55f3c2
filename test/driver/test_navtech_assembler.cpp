// ScanAssembler: rotations closed on wrap / last row, rows placed by encoder, holes and
// duplicates flagged, partial first rotation dropped or marked, configuration changes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "spinradar/driver/scan_assembler.hpp"

using namespace spinradar::navtech;

namespace {

Configuration smallConfig(int azimuths = 8, int encoder = 80) {
  Configuration c;
  c.azimuth_samples = uint16_t(azimuths);
  c.encoder_size = uint16_t(encoder);
  c.range_in_bins = 4;
  c.bin_size = 500;
  c.rotation_mhz = 4000;
  return c;
}

FftData msg(int encoder, uint16_t value, int bins = 4, int depth = 8) {
  FftData f;
  f.encoder = uint16_t(encoder);
  f.bit_depth = depth;
  f.power.assign(size_t(bins), value);
  return f;
}

// Feeds rows [from, to) of rotation `rot` (8 rows, encoder step 10); returns completed scans.
int feed(ScanAssembler& a, int rot, int from, int to, std::vector<AssembledScan>& out,
         std::initializer_list<int> skip = {}) {
  int n = 0;
  for (int r = from; r < to; ++r) {
    if (std::find(skip.begin(), skip.end(), r) != skip.end()) continue;
    AssembledScan s;
    const int64_t t = (int64_t(rot) * 8 + r) * 31'250'000;
    if (a.add(msg(r * 10, uint16_t(rot * 10 + r)), t, t + 1000, s)) {
      out.push_back(std::move(s));
      ++n;
    }
  }
  return n;
}

}  // namespace

TEST(NavtechAssembler, FullRotationsCloseOnLastRowWithPerRowData) {
  ScanAssembler a;
  a.setConfiguration(smallConfig());
  std::vector<AssembledScan> scans;
  EXPECT_EQ(feed(a, 0, 0, 8, scans), 1);  // closes on the last row, no wait for the wrap
  EXPECT_EQ(feed(a, 1, 0, 8, scans), 1);
  ASSERT_EQ(scans.size(), 2u);
  const auto& s = scans[1].scan;
  EXPECT_EQ(s.azimuths, 8);
  EXPECT_EQ(s.bins, 4);
  EXPECT_NEAR(s.range_resolution, 0.05, 1e-12);
  EXPECT_EQ(scans[1].missing, 0);
  EXPECT_EQ(scans[1].sequence, 1u);
  for (int r = 0; r < 8; ++r) {
    EXPECT_EQ(s.valid[r], 1);
    EXPECT_EQ(s.encoder[r], r * 10);
    EXPECT_NEAR(s.azimuth[r], 2 * M_PI * r / 8, 1e-12);
    EXPECT_EQ(s.stamp_ns[r], (8 + r) * 31'250'000);
    EXPECT_EQ(s.row(r)[0], 10 + r);
  }
}

TEST(NavtechAssembler, WrapClosesRotationWithoutLastRow) {
  ScanAssembler a;
  a.setConfiguration(smallConfig());
  std::vector<AssembledScan> scans;
  feed(a, 0, 0, 7, scans);  // last row lost
  EXPECT_TRUE(scans.empty());
  feed(a, 1, 0, 1, scans);  // encoder wraps -> rotation 0 closes
  ASSERT_EQ(scans.size(), 1u);
  EXPECT_EQ(scans[0].missing, 1);
  EXPECT_EQ(scans[0].scan.valid[7], 0);
  EXPECT_EQ(scans[0].scan.encoder[7], 70);  // nominal encoder for the hole
  // Stamp of the hole extrapolated at the rotation's row period.
  EXPECT_EQ(scans[0].scan.stamp_ns[7], 7 * 31'250'000);
}

TEST(NavtechAssembler, MissingRowsLeaveHolesNotShifts) {
  ScanAssembler a;
  a.setConfiguration(smallConfig());
  std::vector<AssembledScan> scans;
  feed(a, 0, 0, 8, scans, {2, 3});
  ASSERT_EQ(scans.size(), 1u);
  const auto& s = scans[0].scan;
  EXPECT_EQ(scans[0].missing, 2);
  EXPECT_EQ(s.valid[2], 0);
  EXPECT_EQ(s.valid[3], 0);
  EXPECT_EQ(s.row(2)[0], 0);            // zero power in the hole
  EXPECT_EQ(s.row(4)[0], 4);            // row 4 still holds azimuth 4's data
  EXPECT_EQ(s.stamp_ns[2], 2 * 31'250'000);  // interpolated
  EXPECT_EQ(s.stamp_ns[3], 3 * 31'250'000);
  EXPECT_EQ(a.stats().missing_azimuths, 2u);
}

TEST(NavtechAssembler, DuplicatedRowFlaggedKeepsFirst) {
  ScanAssembler a;
  a.setConfiguration(smallConfig());
  AssembledScan s;
  for (int r = 0; r < 4; ++r) EXPECT_FALSE(a.add(msg(r * 10, uint16_t(r)), r, r, s));
  EXPECT_FALSE(a.add(msg(31, 99), 100, 100, s));  // encoder 31 -> row 3 again
  bool done = false;
  for (int r = 4; r < 8; ++r) done = a.add(msg(r * 10, uint16_t(r)), r, r, s);
  ASSERT_TRUE(done);
  EXPECT_EQ(s.duplicated, 1);
  EXPECT_EQ(s.scan.valid[3], 0);
  EXPECT_EQ(s.scan.row(3)[0], 3);
  EXPECT_EQ(s.scan.valid[4], 1);
}

TEST(NavtechAssembler, PartialFirstRotationDroppedOrMarked) {
  for (bool drop : {true, false}) {
    AssemblerOptions o;
    o.drop_partial = drop;
    o.min_valid_fraction = 0.0;
    ScanAssembler a(o);
    a.setConfiguration(smallConfig());
    std::vector<AssembledScan> scans;
    feed(a, 0, 5, 8, scans);  // joined at row 5
    feed(a, 1, 0, 8, scans);
    if (drop) {
      ASSERT_EQ(scans.size(), 1u);
      EXPECT_FALSE(scans[0].partial);
      EXPECT_EQ(scans[0].missing, 0);
      EXPECT_EQ(a.stats().partial_scans, 1u);
      EXPECT_EQ(a.stats().dropped_scans, 0u);
    } else {
      ASSERT_EQ(scans.size(), 2u);
      EXPECT_TRUE(scans[0].partial);
      EXPECT_EQ(scans[0].missing, 5);
      for (int r = 0; r < 5; ++r) EXPECT_EQ(scans[0].scan.valid[r], 0);
      EXPECT_EQ(scans[0].scan.valid[5], 1);
    }
    // The rows before we joined were never sent to us: not counted as lost.
    EXPECT_EQ(a.stats().missing_azimuths, 0u);
  }
}

TEST(NavtechAssembler, SparseRotationDropped) {
  AssemblerOptions o;
  o.min_valid_fraction = 0.75;
  ScanAssembler a(o);
  a.setConfiguration(smallConfig());
  std::vector<AssembledScan> scans;
  feed(a, 0, 0, 8, scans, {1, 2, 3});  // 5/8 valid < 0.75
  EXPECT_TRUE(scans.empty());
  EXPECT_EQ(a.stats().dropped_scans, 1u);
}

TEST(NavtechAssembler, ResetDiscardsRotationInProgress) {
  ScanAssembler a;
  a.setConfiguration(smallConfig());
  std::vector<AssembledScan> scans;
  feed(a, 0, 0, 5, scans);
  a.reset();             // disconnect mid-rotation
  feed(a, 1, 5, 8, scans);  // reconnected mid-rotation: partial, dropped
  feed(a, 2, 0, 8, scans);
  ASSERT_EQ(scans.size(), 1u);
  EXPECT_EQ(scans[0].missing, 0);
  EXPECT_EQ(scans[0].scan.row(0)[0], 20);
}

TEST(NavtechAssembler, NewConfigurationResets) {
  ScanAssembler a;
  a.setConfiguration(smallConfig());
  std::vector<AssembledScan> scans;
  feed(a, 0, 0, 4, scans);
  a.setConfiguration(smallConfig());  // same configuration re-sent: no reset
  feed(a, 0, 4, 8, scans);
  ASSERT_EQ(scans.size(), 1u);
  Configuration c = smallConfig(4, 40);
  a.setConfiguration(c);
  AssembledScan s;
  bool done = false;
  for (int r = 0; r < 4; ++r) done = a.add(msg(r * 10, 1), r, r, s);
  ASSERT_TRUE(done);
  EXPECT_EQ(s.scan.azimuths, 4);
  EXPECT_EQ(s.scan.encoder_size, 40);
}

TEST(NavtechAssembler, WrongBinCountIsMalformedNotPlaced) {
  ScanAssembler a;
  a.setConfiguration(smallConfig());
  AssembledScan s;
  bool done = false;
  for (int r = 0; r < 8; ++r) done = a.add(msg(r * 10, 1, r == 3 ? 5 : 4), r, r, s);
  ASSERT_TRUE(done);
  EXPECT_EQ(s.scan.valid[3], 0);
  EXPECT_EQ(s.malformed, 1);
  EXPECT_EQ(a.stats().malformed, 1u);
  EXPECT_FALSE(a.add(msg(80, 1), 0, 0, s));  // encoder beyond the encoder size
  EXPECT_EQ(a.stats().malformed, 2u);
}

TEST(NavtechAssembler, SixteenBitKeptAndMapped) {
  AssemblerOptions o;
  ScanAssembler a(o);
  a.setConfiguration(smallConfig());
  AssembledScan s;
  bool done = false;
  for (int r = 0; r < 8; ++r) {
    FftData f = msg(r * 10, 0, 4, 16);
    f.power = {uint16_t(r * 256 + 100), 0xFFFF, 127, 128};
    done = a.add(f, r, r, s);
  }
  ASSERT_TRUE(done);
  EXPECT_EQ(s.bit_depth, 16);
  ASSERT_EQ(s.power16.size(), 32u);
  EXPECT_EQ(s.power16[5 * 4 + 0], 5 * 256 + 100);
  EXPECT_EQ(s.scan.row(5)[0], 5);    // round(1380 / 256) = 5
  EXPECT_EQ(s.scan.row(5)[1], 255);  // saturates
  EXPECT_EQ(s.scan.row(5)[2], 0);    // 127 / 256 rounds down
  EXPECT_EQ(s.scan.row(5)[3], 1);    // 128 / 256 rounds up
}

TEST(NavtechAssembler, NoDataBeforeConfiguration) {
  ScanAssembler a;
  AssembledScan s;
  EXPECT_FALSE(a.add(msg(0, 1), 0, 0, s));
  EXPECT_EQ(a.stats().malformed, 1u);
  Configuration bad = smallConfig();
  bad.encoder_size = 0;
  a.setConfiguration(bad);
  EXPECT_FALSE(a.hasConfiguration());
}

TEST(NavtechAssembler, EncoderPhaseOfRealSensorKeepsRowOrder) {
  // Oxford CIR204-H data reports encoders 13, 27, ..., 5599 (phase 13 of a 14-count step).
  Configuration c = smallConfig(400, 5600);
  ScanAssembler a;
  a.setConfiguration(c);
  AssembledScan s;
  bool done = false;
  for (int r = 0; r < 400; ++r) {
    if (r == 200) continue;  // one lost azimuth
    done = a.add(msg(14 * r + 13, uint16_t(r % 256)), r, r, s);
  }
  ASSERT_TRUE(done);  // closed on row 399 = encoder 5599
  EXPECT_EQ(s.missing, 1);
  EXPECT_EQ(s.duplicated, 0);
  EXPECT_EQ(s.scan.encoder[0], 13);
  EXPECT_EQ(s.scan.row(0)[0], 0);
  EXPECT_EQ(s.scan.row(399)[0], 399 % 256);
  EXPECT_EQ(s.scan.valid[200], 0);
  EXPECT_EQ(s.scan.encoder[200], 14 * 200 + 13);  // the hole gets the encoder it should have had
  EXPECT_EQ(s.scan.row(201)[0], 201 % 256);
}
