// The driver's diagnostic level reflects the last few seconds: hand-built counter snapshots at
// given times (no clock involved).
#include <gtest/gtest.h>

#include "spinradar/driver/driver_health.hpp"

using namespace spinradar::navtech;

namespace {
constexpr int64_t kS = 1'000'000'000;

/// Streaming at 1600 azimuths per second up to time t.
DriverStats streaming(int64_t t_ns) {
  DriverStats s;
  s.azimuths = uint64_t(1600 * t_ns / kS);
  s.scans = s.azimuths / 400;
  return s;
}
}  // namespace

TEST(DriverHealth, ErrorWithoutConfigurationOrData) {
  DriverHealth h(5.0, 2.0);
  const Health none = h.update(DriverStats{}, false, 0);
  EXPECT_EQ(none.level, HealthLevel::Error);
  EXPECT_NE(none.message.find("no sensor configuration"), std::string::npos);
  EXPECT_EQ(h.update(streaming(kS), true, kS).level, HealthLevel::Ok);
  EXPECT_EQ(h.update(streaming(kS), true, 2 * kS).level, HealthLevel::Ok);  // 1 s quiet
  const Health quiet = h.update(streaming(kS), true, 3 * kS + kS / 2);
  EXPECT_EQ(quiet.level, HealthLevel::Error);
  EXPECT_NE(quiet.message.find("no data for 2.5 s"), std::string::npos) << quiet.message;
  EXPECT_EQ(h.update(streaming(4 * kS), true, 4 * kS).level, HealthLevel::Ok);  // data again
}

TEST(DriverHealth, WarnWhileBadMessagesArriveThenOk) {
  DriverHealth h(5.0, 2.0);
  EXPECT_EQ(h.update(streaming(kS), true, kS).level, HealthLevel::Ok);
  DriverStats s = streaming(2 * kS);
  s.input.stream.garbage_bytes = 5000;
  s.input.stream.oversized = 1;
  s.input.stream.truncated = 2;
  s.input.unknown_types = 3;
  Health w = h.update(s, true, 2 * kS);
  EXPECT_EQ(w.level, HealthLevel::Warn);
  for (const char* what : {"5000 garbage bytes", "1 oversized headers", "2 truncated messages",
                           "3 messages of unknown type"})
    EXPECT_NE(w.message.find(what), std::string::npos) << what << " in: " << w.message;
  // The counters stay where they are: WARN for as long as the window still holds the event.
  for (int t = 3; t <= 6; ++t) {
    DriverStats later = s;
    later.azimuths = streaming(t * kS).azimuths;
    EXPECT_EQ(h.update(later, true, t * kS).level, HealthLevel::Warn) << t;
  }
  for (int t = 7; t <= 8; ++t) {
    DriverStats later = s;
    later.azimuths = streaming(t * kS).azimuths;
    EXPECT_EQ(h.update(later, true, t * kS).level, HealthLevel::Ok) << t;
  }
}

TEST(DriverHealth, RotationJoinedAtConnectIsNotAProblem) {
  DriverHealth h(5.0, 2.0);
  h.update(streaming(kS), true, kS);
  DriverStats s = streaming(2 * kS);
  s.partial_scans = 1;  // dropped as expected; its unsent rows are not missing azimuths
  EXPECT_EQ(h.update(s, true, 2 * kS).level, HealthLevel::Ok);
  s.missing_azimuths = 4;
  s.azimuths += 100;
  const Health w = h.update(s, true, 3 * kS);
  EXPECT_EQ(w.level, HealthLevel::Warn);
  EXPECT_NE(w.message.find("4 missing azimuths"), std::string::npos) << w.message;
}
