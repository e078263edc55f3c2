// The driver against a sensor whose clock steps back or jumps forward, and against a gap in
// the data (emulator faults ClockStep and Gap): no published scan holds the step, the status
// says what happened and when, and the smoothed mapping is re-anchored at once.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>

#include "navtech_test_util.hpp"
#include "spinradar/driver/driver_health.hpp"

using namespace spinradar;
using namespace spinradar::navtech;
using namespace spinradar::navtech::test;
using Clock = std::chrono::steady_clock;

namespace {

constexpr int64_t kRotationNs = 250'000'000;  // patternSource: 4 Hz

ServerFault fault(uint64_t at, ServerFault::Kind kind, double value) {
  ServerFault f;
  f.at_azimuth = at;
  f.kind = kind;
  f.value = value;
  return f;
}

struct Served {
  std::vector<AssembledScan> scans;
  std::vector<int> rotation;  ///< which source rotation each scan is (from its pattern)
  DriverStats before, after;  ///< stats after the first scan and at the end
  std::string log;
};

/// Serves patternSource with `faults`, returns the first `n` scans the driver publishes.
Served serveAndPoll(std::vector<ServerFault> faults, const std::string& time_source, int n) {
  ServerOptions o;
  o.rate = 5;
  o.faults = std::move(faults);
  o.log = [](LogLevel, const std::string&) {};
  NavtechServer server(o, patternSource());
  server.start();
  DriverConfig c = fastDriverConfig(server.port());
  c.time_source = time_source;
  NavtechDriver d(c);
  LogSink log;
  d.setLog(log.fn());
  Served r;
  AssembledScan s;
  const auto end = Clock::now() + std::chrono::seconds(20);
  while (int(r.scans.size()) < n && Clock::now() < end) {
    if (d.poll(s, std::chrono::milliseconds(100)) != InputStatus::Ok) continue;
    EXPECT_TRUE(wellFormed(s));
    r.scans.push_back(s);
    const int k = s.scan.row(0)[0] / 7;  // row 0 of rotation k starts at 7k (k < 36)
    r.rotation.push_back(k);
    if (r.scans.size() == 1) r.before = d.stats();
  }
  r.after = d.stats();
  r.log = log.all();
  return r;
}

/// Every scan's stamps strictly increase and span at most one rotation.
void expectEachScanOneTurn(const Served& r) {
  for (size_t i = 0; i < r.scans.size(); ++i) {
    const PolarScan& p = r.scans[i].scan;
    for (int a = 1; a < p.azimuths; ++a)
      ASSERT_GT(p.stamp_ns[a], p.stamp_ns[a - 1]) << "scan " << i << " row " << a;
    EXPECT_LT(p.stamp_ns.back() - p.stamp_ns.front(), kRotationNs) << "scan " << i;
  }
}

}  // namespace

TEST(NavtechTimeAnomalies, ClockStepBackNeverInsideAScan) {
  // The sensor clock steps back 10 s at row 200 of rotation 2.
  Served r = serveAndPoll({fault(1000, ServerFault::Kind::ClockStep, -10.0)}, "sensor", 5);
  ASSERT_EQ(r.scans.size(), 5u) << r.log;
  expectEachScanOneTurn(r);
  // Rotation 2 straddles the step: dropped (both halves); the others are published whole.
  EXPECT_EQ(r.rotation, (std::vector<int>{0, 1, 3, 4, 5}));
  for (auto& s : r.scans) EXPECT_EQ(s.missing, 0);
  // With time_source sensor the scans follow the sensor clock: 10 s back after the step.
  EXPECT_EQ(r.scans[2].scan.stamp_ns[0] - r.scans[1].scan.stamp_ns[0], 2 * kRotationNs - 10'000'000'000);
  EXPECT_EQ(r.after.time_anomalies, 1u);
  EXPECT_NE(r.after.last_time_anomaly.find("sensor clock stepped back by 10.000 s at 20"),
            std::string::npos) << r.after.last_time_anomaly;
  EXPECT_NE(r.log.find("rotation in progress dropped, clock mapping re-anchored"), std::string::npos)
      << r.log;
  // The status: WARN with what happened and when while it is recent, OK once it is not.
  DriverHealth h(5.0, 2.0);
  EXPECT_EQ(h.update(r.before, true, 0).level, HealthLevel::Ok);
  const Health warn = h.update(r.after, true, 1'000'000'000);
  EXPECT_EQ(warn.level, HealthLevel::Warn);
  EXPECT_NE(warn.message.find("1 time anomalies"), std::string::npos) << warn.message;
  EXPECT_NE(warn.message.find("stepped back by 10.000 s at 20"), std::string::npos) << warn.message;
  DriverStats later = r.after;
  later.azimuths += 16000;
  h.update(later, true, 6'500'000'000);
  later.azimuths += 1600;
  EXPECT_EQ(h.update(later, true, 7'000'000'000).level, HealthLevel::Ok);
}

TEST(NavtechTimeAnomalies, ClockJumpForwardNeverInsideAScan) {
  Served r = serveAndPoll({fault(1000, ServerFault::Kind::ClockStep, 10.0)}, "sensor", 5);
  ASSERT_EQ(r.scans.size(), 5u) << r.log;
  expectEachScanOneTurn(r);
  EXPECT_EQ(r.rotation, (std::vector<int>{0, 1, 3, 4, 5}));
  EXPECT_EQ(r.scans[2].scan.stamp_ns[0] - r.scans[1].scan.stamp_ns[0], 2 * kRotationNs + 10'000'000'000);
  EXPECT_EQ(r.after.time_anomalies, 1u);
  EXPECT_NE(r.after.last_time_anomaly.find("sensor time jumped forward by 10.000 s"), std::string::npos)
      << r.after.last_time_anomaly;
}

TEST(NavtechTimeAnomalies, SmoothedStampsReanchoredAtOnce) {
  // time_source smoothed maps sensor time onto the receive clock. The step back comes 10 rows
  // before the end of rotation 2, so a mapping that took its usual 32 samples to notice would
  // stamp the start of rotation 3 ten seconds back; re-anchored at once, it does not.
  Served r = serveAndPoll({fault(1190, ServerFault::Kind::ClockStep, -10.0)}, "smoothed", 5);
  ASSERT_EQ(r.scans.size(), 5u) << r.log;
  EXPECT_EQ(r.rotation, (std::vector<int>{0, 1, 3, 4, 5}));
  for (size_t i = 0; i < r.scans.size(); ++i) {
    const PolarScan& p = r.scans[i].scan;
    const auto [lo, hi] = std::minmax_element(p.stamp_ns.begin(), p.stamp_ns.end());
    EXPECT_LT(*hi - *lo, 1'000'000'000) << "scan " << i;  // (receive-clock jitter aside)
    if (i > 0) {
      EXPECT_GE(p.stamp_ns.front(), r.scans[i - 1].scan.stamp_ns.front()) << "scan " << i;
    }
  }
  EXPECT_EQ(r.after.time_anomalies, 1u);
}

TEST(NavtechTimeAnomalies, GapInTheDataNeverInsideAScan) {
  // The sensor turns on for 0.3 s (1.2 rotations) without sending, from row 100 of rotation 2.
  Served r = serveAndPoll({fault(900, ServerFault::Kind::Gap, 0.3)}, "sensor", 4);
  ASSERT_EQ(r.scans.size(), 4u) << r.log;
  expectEachScanOneTurn(r);
  // Rotations 2 (cut) and 3 (joined mid-way after the gap) are not published.
  EXPECT_EQ(r.rotation, (std::vector<int>{0, 1, 4, 5}));
  EXPECT_EQ(r.after.time_anomalies, 1u);
  EXPECT_NE(r.after.last_time_anomaly.find("jumped forward by 0.250 s"), std::string::npos)
      << r.after.last_time_anomaly;
  EXPECT_EQ(r.after.missing_azimuths, 0u);
}

TEST(NavtechTimeAnomalies, StampCheckerFromHandComputedTimes) {
  Configuration c;  // 400 azimuths, encoder 5600, 4 Hz: 14 counts = 625 us
  StampChecker k(100'000'000);
  EXPECT_EQ(k.check(1'000'000'000, 0, c), 0);
  EXPECT_EQ(k.check(1'000'625'000, 14, c), 0);
  EXPECT_EQ(k.check(1'001'875'000, 56, c), 0);        // two azimuths lost: still on time
  EXPECT_EQ(k.check(1'001'875'000 + 250'000'000, 70, c), 249'375'000);  // a turn + 1 later
  EXPECT_EQ(k.check(1'251'875'000 - 10'000'000'000LL, 84, c), -10'000'625'000);
  // The same encoder a whole turn later: 400 azimuths lost, a gap of one turn.
  EXPECT_EQ(k.check(1'251'875'000 - 10'000'000'000LL + 625'000 * 400, 84, c), 250'000'000);
  EXPECT_EQ(k.check(1'501'875'000 - 10'000'000'000LL + 625'000, 98, c), 0);
}
