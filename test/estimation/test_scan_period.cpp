// The rotation period the keyframe and surface trackers place a scan's mid-scan reference
// with (ScanPeriod). Known truth: frames whose keypoints span one rotation, fed with stamp
// steps of one rotation, of two (a dropped scan, or a recording read every other scan) and of
// a slower sensor. Half of a two-rotation step would put the reference at the scan's end.
#include <gtest/gtest.h>

#include "spinradar/estimation/scan_period.hpp"

using namespace spinradar;

namespace {

/// A scan starting at `start_s` whose keypoints sit on rows spread over `period_s` (400 rows).
FeatureFrame scan(double start_s, double period_s, int rows_with_returns = 400) {
  FeatureFrame f;
  f.stamp_ns = static_cast<int64_t>(start_s * 1e9);
  for (int r = 0; r < rows_with_returns; ++r) {
    Keypoint k;
    k.stamp_ns = f.stamp_ns + static_cast<int64_t>(period_s * 1e9 * r / 400.0);
    f.keypoints.push_back(k);
  }
  return f;
}

}  // namespace

TEST(ScanPeriod, EveryRotationThePeriodIsTheStep) {
  ScanPeriod p;
  for (int k = 0; k < 5; ++k) EXPECT_DOUBLE_EQ(p.update(scan(0.25 * k, 0.25), 0.25), 0.25);
  // A slower sensor (2 Hz): its steps of 0.5 s are its period, not gaps.
  ScanPeriod slow;
  EXPECT_DOUBLE_EQ(slow.update(scan(0.0, 0.5), 0.5), 0.5);
  EXPECT_DOUBLE_EQ(slow.update(scan(0.5, 0.5), 0.5), 0.5);
}

TEST(ScanPeriod, ADroppedScanKeepsTheLastPeriod) {
  ScanPeriod p;
  p.update(scan(0.0, 0.25), 0.25);
  p.update(scan(0.25, 0.25), 0.25);
  EXPECT_DOUBLE_EQ(p.update(scan(0.75, 0.25), 0.5), 0.25);   // scan at 0.5 s lost
  EXPECT_DOUBLE_EQ(p.update(scan(1.00, 0.25), 0.25), 0.25);  // back to normal
}

TEST(ScanPeriod, EveryOtherScanFromTheStartUsesTheScansOwnSpan) {
  ScanPeriod p;
  for (int k = 0; k < 4; ++k) {
    const double got = p.update(scan(0.5 * k, 0.25), 0.5);
    EXPECT_NEAR(got, 0.25, 0.25 / 400.0 + 1e-9) << "scan " << k;  // within one row
  }
}

TEST(ScanPeriod, AScanWithoutKeypointsUsesTheStep) {
  ScanPeriod p;
  EXPECT_DOUBLE_EQ(p.update(scan(0.0, 0.25, 0), 0.5), 0.5);
}
