// Core PolarScan / driver scans <-> spinradar/RadarScan and the Oxford-layout image, byte-exact.
#include <gtest/gtest.h>

#include "spinradar_ros/polar_scan_conversions.hpp"

using namespace spinradar;

namespace {
navtech::AssembledScan makeScan(int depth) {
  navtech::AssembledScan s;
  s.scan.resize(4, 3);
  s.scan.range_resolution = 0.0596;
  s.scan.range_offset = -0.31;
  s.scan.encoder_size = 5600;
  for (int a = 0; a < 4; ++a) {
    s.scan.encoder[a] = uint16_t(a * 1400);
    s.scan.azimuth[a] = a * M_PI / 2;
    s.scan.stamp_ns[a] = 1'600'000'000'123'456'789 + a * 62'500'000;
    for (int b = 0; b < 3; ++b) s.scan.row(a)[b] = uint8_t(10 * a + b);
  }
  s.scan.valid[1] = 0;
  s.bit_depth = depth;
  if (depth == 16)
    for (uint8_t v : s.scan.power) s.power16.push_back(uint16_t(v * 256 + 7));
  s.config.rotation_mhz = 4000;
  s.missing = 1;
  s.sequence = 42;
  return s;
}
}  // namespace

TEST(NavtechConversions, MessageRoundTrip8And16Bit) {
  for (int depth : {8, 16}) {
    const auto s = makeScan(depth);
    spinradar::RadarScan msg;
    spinradar_ros::toMsg(s, "radar", 256.0f, msg);
    EXPECT_EQ(msg.header.frame_id, "radar");
    EXPECT_EQ(msg.header.stamp.toNSec(), uint64_t(s.scan.stamp_ns[0]));
    EXPECT_EQ(msg.bit_depth, depth);
    EXPECT_EQ(msg.missing_azimuths, 1u);
    EXPECT_EQ(msg.sequence, 42u);
    EXPECT_FLOAT_EQ(msg.rotation_hz, 4.0f);
    if (depth == 16) {
      EXPECT_EQ(msg.data16, s.power16);
      EXPECT_TRUE(msg.data8.empty());
    }
    PolarScan back;
    spinradar_ros::fromMsg(msg, back);
    EXPECT_EQ(back.power, s.scan.power);  // (v*256+7)/256 rounds back to v
    EXPECT_EQ(back.stamp_ns, s.scan.stamp_ns);
    EXPECT_EQ(back.encoder, s.scan.encoder);
    EXPECT_EQ(back.valid, s.scan.valid);
    EXPECT_EQ(back.azimuth, s.scan.azimuth);
    EXPECT_DOUBLE_EQ(back.range_resolution, 0.0596);
    EXPECT_DOUBLE_EQ(back.range_offset, -0.31);
  }
}

TEST(NavtechConversions, MalformedMessageThrowsNamingField) {
  spinradar::RadarScan msg;
  spinradar_ros::toMsg(makeScan(8).scan, "radar", 4.0f, msg);
  msg.data8.pop_back();
  PolarScan out;
  try {
    spinradar_ros::fromMsg(msg, out);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("data8"), std::string::npos) << e.what();
  }
}

TEST(NavtechConversions, OxfordImageLayoutAndRoundTrip) {
  const auto s = makeScan(8);
  std_msgs::Header h;
  h.frame_id = "radar";
  sensor_msgs::Image img;
  spinradar_ros::toOxfordImage(s.scan, h, img);
  ASSERT_EQ(img.height, 4u);
  ASSERT_EQ(img.width, 3u + 11u);
  EXPECT_EQ(img.encoding, "mono8");
  // Row 2: int64 LE microseconds, uint16 LE encoder 2800 = 0x0AF0, valid 255, bins 20 21 22.
  const uint8_t* r = img.data.data() + 2 * img.step;
  int64_t us = 0;
  for (int i = 7; i >= 0; --i) us = (us << 8) | r[i];
  EXPECT_EQ(us, (s.scan.stamp_ns[2]) / 1000);
  EXPECT_EQ(r[8], 0xF0);
  EXPECT_EQ(r[9], 0x0A);
  EXPECT_EQ(r[10], 255);
  EXPECT_EQ(r[11], 20);
  EXPECT_EQ(img.data[1 * img.step + 10], 0);  // invalid row
  PolarScan back;
  spinradar_ros::fromOxfordImage(img, back, 0.0596, -0.31);
  EXPECT_EQ(back.power, s.scan.power);
  EXPECT_EQ(back.encoder, s.scan.encoder);
  EXPECT_EQ(back.valid, s.scan.valid);
  EXPECT_EQ(back.stamp_ns[3], s.scan.stamp_ns[3] / 1000 * 1000);
  img.encoding = "rgb8";
  EXPECT_THROW(spinradar_ros::fromOxfordImage(img, back), std::runtime_error);
}
