// ClockMapper (time_source = smoothed): sensor time mapped onto the receive clock, robust to
// network delay spikes, following drift and clock jumps.
#include <gtest/gtest.h>

#include <cmath>

#include "spinradar/driver/navtech_time.hpp"

using namespace spinradar::navtech;

namespace {
constexpr int64_t kPeriod = 625'000;  // 1600 azimuths a second
}

TEST(NavtechTime, MinimumDelayRejectsLatencySpikes) {
  ClockMapper m;
  const int64_t offset = 5'000'000'000;  // receive clock 5 s ahead of the sensor
  int64_t worst = 0;
  for (int i = 0; i < 20000; ++i) {
    const int64_t sensor = 1'000'000'000'000 + i * kPeriod;
    // Delay 0.2 ms, with a 40 ms spike every 100 messages (TCP burst, scheduler).
    const int64_t delay = 200'000 + (i % 100 == 7 ? 40'000'000 : (i * 7919) % 300'000);
    const int64_t mapped = m.map(sensor, sensor + offset + delay);
    if (i > 10) worst = std::max(worst, std::abs(mapped - (sensor + offset + 200'000)));
  }
  EXPECT_LT(worst, 300'000);  // within the delay jitter, spikes ignored
  EXPECT_EQ(m.jumps(), 0u);
}

TEST(NavtechTime, FollowsDrift) {
  ClockMapper m(2'000'000'000);  // 2 s window
  int64_t err = 0;
  for (int i = 0; i < 16000 * 6; ++i) {  // 60 s at 1600/s
    const int64_t sensor = i * kPeriod;
    const int64_t truth = sensor + sensor / 10000;  // receive clock runs 100 ppm fast
    const int64_t mapped = m.map(sensor, truth + 100'000);
    if (i > 16000) err = std::max(err, std::abs(mapped - truth - 100'000));
  }
  EXPECT_LT(err, 250'000);  // drift over one 2 s window is 0.2 ms
}

TEST(NavtechTime, FollowsSensorClockJumps) {
  ClockMapper m(5'000'000'000, 500'000'000, 32);
  int64_t rx = 0, sensor = 0;
  auto step = [&](int n) {
    int64_t last = 0;
    for (int i = 0; i < n; ++i) {
      sensor += kPeriod;
      rx += kPeriod;
      last = m.map(sensor, rx);
    }
    return last;
  };
  EXPECT_EQ(step(1000), rx);
  sensor += 3'600'000'000'000;  // sensor clock jumps forward an hour: followed at once
  EXPECT_EQ(step(1), rx);
  sensor -= 7'200'000'000'000;  // and back two hours: followed after 32 samples
  step(40);
  EXPECT_EQ(step(1), rx);
  EXPECT_EQ(m.jumps(), 1u);
}

TEST(NavtechTime, ParseOptions) {
  EXPECT_EQ(parseTimeSource("smoothed"), TimeSource::Smoothed);
  EXPECT_THROW(parseTimeSource("gps"), std::invalid_argument);
  EXPECT_EQ(parseTimeByteOrder("big"), TimeByteOrder::Big);
  EXPECT_THROW(parseTimeByteOrder("middle"), std::invalid_argument);
}
