// Geometry of rendered scans against hand computation: bins, azimuths, offsets, Doppler,
// motion distortion.
#include <gtest/gtest.h>

#include <cmath>

#include "sim_test_util.hpp"

using namespace spinradar;
using namespace spinradar::sim;
using namespace spinradar::sim::testing;

namespace {

const double kStep = 2 * M_PI / 400;

PolarScan render(const World& w, const Trajectory& t, const PhysicsConfig& p, int k = 1,
                 uint64_t seed = 3) {
  return Simulator(w, t, SensorConfig{}, p, seed).renderScan(k);
}

}  // namespace

TEST(SimGeometry, SingleTargetLandsInTheRightBinAndAzimuth) {
  // Static sensor at (3, 2) with yaw 0.4; target at world (25, -4).
  Pose2 pose{3, 2, 0.4};
  World w = oneTarget(25, -4);
  PolarScan s = render(w, constantMotion(0, 0, pose), {});
  double dx = 22, dy = -6;
  double xs = std::cos(0.4) * dx + std::sin(0.4) * dy, ys = -std::sin(0.4) * dx + std::cos(0.4) * dy;
  double r = std::hypot(xs, ys);
  double psi = std::atan2(-ys, xs);  // clockwise
  if (psi < 0) psi += 2 * M_PI;
  Peak p = findPeak(s);
  EXPECT_EQ(p.azimuth, int(std::lround(psi / kStep)) % 400);
  EXPECT_NEAR(s.azimuth[p.azimuth], psi, kStep / 2 + 1e-9);
  EXPECT_NEAR(s.rangeOfBin(p.fine_bin), r, 0.02);
  EXPECT_EQ(p.bin, int(std::lround(s.binOfRange(r))));
}

TEST(SimGeometry, TargetLeftOfTheSensorIsAtClockwiseAzimuth270) {
  PolarScan s = render(oneTarget(0, 30), constantMotion(0, 0), {});
  Peak p = findPeak(s);
  EXPECT_EQ(p.azimuth, 300);  // 270 deg clockwise = 90 deg CCW = +y (left)
}

TEST(SimGeometry, RangeOffsetShiftsRangeOnly) {
  World w = oneTarget(30, -12);
  Trajectory t = constantMotion(0, 0);
  PhysicsConfig p0, p1;
  p1.range_offset = 0.5;
  PolarScan a = render(w, t, p0), b = render(w, t, p1);
  Peak pa = findPeak(a), pb = findPeak(b);
  EXPECT_EQ(pa.azimuth, pb.azimuth);
  EXPECT_NEAR((pb.fine_bin - pa.fine_bin) * a.range_resolution, 0.5, 0.02);
  EXPECT_EQ(a.stamp_ns, b.stamp_ns);
  EXPECT_EQ(a.azimuth, b.azimuth);
  EXPECT_EQ(a.encoder, b.encoder);
}

TEST(SimGeometry, AzimuthOffsetShiftsAzimuthOnly) {
  World w = oneTarget(30, -12);
  Trajectory t = constantMotion(0, 0);
  PhysicsConfig p0, p1;
  p1.azimuth_offset = 3 * kStep;  // reported minus true: the target shows 3 rows later
  PolarScan a = render(w, t, p0), b = render(w, t, p1);
  Peak pa = findPeak(a), pb = findPeak(b);
  EXPECT_EQ(pb.azimuth, pa.azimuth + 3);
  EXPECT_NEAR(pb.fine_bin, pa.fine_bin, 0.05);
  EXPECT_EQ(a.stamp_ns, b.stamp_ns);
  EXPECT_EQ(a.azimuth, b.azimuth);
}

TEST(SimGeometry, TimestampOffsetShiftsStampsOnly) {
  World w = oneTarget(30, -12);
  w.walls.push_back({10, 20, 40, 25, 3});
  Trajectory t = constantMotion(8, 0.2);
  PhysicsConfig p0, p1;
  p0.motion_distortion = p1.motion_distortion = true;
  p1.timestamp_offset = 0.03;
  PolarScan a = render(w, t, p0), b = render(w, t, p1);
  EXPECT_EQ(a.power, b.power);
  EXPECT_EQ(a.azimuth, b.azimuth);
  for (int i = 0; i < a.azimuths; ++i) EXPECT_EQ(b.stamp_ns[i] - a.stamp_ns[i], 30000000);
}

TEST(SimGeometry, StampsAreUniformFromTheScanStart) {
  Simulator sim(oneTarget(30, 0), constantMotion(0, 0), SensorConfig{}, {}, 1);
  PolarScan s = sim.renderScan(2);
  EXPECT_EQ(s.stamp_ns[0], 500000000);  // 2 / 4 Hz
  EXPECT_EQ(s.stamp_ns[1] - s.stamp_ns[0], 625000);
  EXPECT_EQ(s.stamp_ns[399] - s.stamp_ns[0], 399 * 625000);
  EXPECT_EQ(s.encoder[1], 14);
}

TEST(SimGeometry, DopplerMakesATargetAheadBetaVCloser) {
  const double v = 10, beta = 0.049;
  World w = oneTarget(60, 0);  // straight ahead of the mid-scan position (x = 1.25 + 10 * 0.25)
  Trajectory t = constantMotion(v, 0);
  PhysicsConfig p0, p1;
  p1.doppler = beta;
  PolarScan a = render(w, t, p0), b = render(w, t, p1);
  Peak pa = findPeak(a, 0, 5), pb = findPeak(b, 0, 5);
  EXPECT_EQ(pa.azimuth, pb.azimuth);
  EXPECT_NEAR((pa.fine_bin - pb.fine_bin) * a.range_resolution, beta * v, 0.02);
  // Behind the sensor the shift reverses: farther by beta * v.
  World wb = oneTarget(-40, 0);
  PolarScan c = render(wb, t, p0), d = render(wb, t, p1);
  Peak pc = findPeak(c, 195, 205), pd = findPeak(d, 195, 205);
  EXPECT_NEAR((pd.fine_bin - pc.fine_bin) * c.range_resolution, beta * v, 0.02);
}

TEST(SimGeometry, DopplerOfAMovingTargetUsesTheClosingSpeed) {
  // Static sensor, target 50 m ahead driving towards it at 8 m/s.
  World w;
  w.targets.push_back({50, 0, 25, -8, 0});
  Trajectory t = constantMotion(0, 0);
  PhysicsConfig p0, p1;
  p0.moving_objects = p1.moving_objects = true;
  p1.doppler = 0.049;
  PolarScan a = render(w, t, p0, 0), b = render(w, t, p1, 0);
  Peak pa = findPeak(a, 0, 5), pb = findPeak(b, 0, 5);
  EXPECT_NEAR((pa.fine_bin - pb.fine_bin) * a.range_resolution, 0.049 * 8, 0.02);
  // Without the moving_objects effect the (moving) target is not rendered at all.
  PolarScan c = render(w, t, PhysicsConfig{}, 0);
  EXPECT_LT(findPeak(c, 0, 5, 900, 1400).value, pa.value - 30);
}

TEST(SimGeometry, MotionDistortionRotatesAWallSeenWhileTurning) {
  // Sensor turning in place at w rad/s; wall along y = -20 (to the right). Each azimuth sees
  // the world from its own yaw, so the wall's image is rotated relative to the mid-scan view.
  const double w_z = 1.0;
  World world;
  world.walls.push_back({-15, -20, 15, -20, 10});
  Trajectory t = constantMotion(0, w_z, {0, 0, 0});
  auto fitAngle = [&](const PolarScan& s) {
    // Range peak per azimuth over the wall's sector, as points in the sensor frame; line fit.
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int n = 0;
    for (int a = 70; a <= 130; ++a) {
      Peak p = findPeak(s, a, a, 300, 1000);
      double r = s.rangeOfBin(p.fine_bin), psi = s.azimuth[a];
      double x = r * std::cos(psi), y = -r * std::sin(psi);
      sx += x, sy += y, sxx += x * x, sxy += x * y, ++n;
    }
    double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    return std::atan(slope);
  };
  auto expectedAngle = [&](bool distortion, double t0) {
    // Hand computation: ray of azimuth a at yaw(t_a) hits y = -20 at r = -20 / sin(yaw - psi).
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int n = 0;
    for (int a = 70; a <= 130; ++a) {
      double psi = a * kStep;
      double ta = distortion ? t0 + a * 0.25 / 400 : t0 + 0.125;
      double yaw = w_z * ta;
      double r = -20.0 / std::sin(yaw - psi);
      double x = r * std::cos(psi), y = -r * std::sin(psi);
      sx += x, sy += y, sxx += x * x, sxy += x * y, ++n;
    }
    return std::atan((n * sxy - sx * sy) / (n * sxx - sx * sx));
  };
  PhysicsConfig off, on;
  on.motion_distortion = true;
  Simulator s_off(world, t, SensorConfig{}, off, 5), s_on(world, t, SensorConfig{}, on, 5);
  // Scan 0 starts at t = 0: mid-scan yaw 0.125 rad.
  double a_off = fitAngle(s_off.renderScan(0)), a_on = fitAngle(s_on.renderScan(0));
  EXPECT_NEAR(a_off, expectedAngle(false, 0), 0.004);
  EXPECT_NEAR(a_on, expectedAngle(true, 0), 0.004);
  EXPECT_GT(std::abs(a_on - a_off), 0.02);  // the shear is real and much larger than the error
}

TEST(SimGeometry, MotionDistortionOffUsesTheMidScanPose) {
  // Moving sensor, no distortion: the target appears where the mid-scan pose sees it.
  World w = oneTarget(30, -15);
  Trajectory t = constantMotion(10, 0);
  PolarScan s = render(w, t, {}, 1);
  double xm = 10 * (0.25 + 0.125);
  Peak p = findPeak(s);
  EXPECT_NEAR(s.rangeOfBin(p.fine_bin), std::hypot(30 - xm, 15), 0.03);
}
