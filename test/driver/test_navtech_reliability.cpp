// The driver against the sensor emulator on 127.0.0.1, with scripted faults. Every test is
// bounded (a wall-clock budget on its loop, never an assertion on timing) and checks: no crash,
// no hang, a clear log line, reconnection with backoff, and only well-formed scans.
#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <thread>

#include "navtech_test_util.hpp"

using namespace spinradar;
using namespace spinradar::navtech;
using namespace spinradar::navtech::test;
using Clock = std::chrono::steady_clock;

namespace {

struct PollResult {
  std::vector<AssembledScan> scans;
  int disconnects = 0, timeouts = 0;
};

/// Polls until `want` scans arrived or `budget` passed; checks every scan on the way.
PollResult pollScans(NavtechDriver& d, int want, double budget_s, int consumer_sleep_ms = 0) {
  PollResult r;
  const auto end = Clock::now() + std::chrono::duration<double>(budget_s);
  AssembledScan s;
  while (int(r.scans.size()) < want && Clock::now() < end) {
    const InputStatus st = d.poll(s, std::chrono::milliseconds(100));
    if (st == InputStatus::Ok) {
      EXPECT_TRUE(wellFormed(s)) << "scan " << r.scans.size();
      r.scans.push_back(s);
      if (consumer_sleep_ms) std::this_thread::sleep_for(std::chrono::milliseconds(consumer_sleep_ms));
    } else if (st == InputStatus::Disconnected) {
      ++r.disconnects;
    } else if (st == InputStatus::Timeout) {
      ++r.timeouts;
    } else {
      ADD_FAILURE() << "unexpected status " << toString(st);
      break;
    }
  }
  return r;
}

ServerOptions serverOptions(std::vector<ServerFault> faults = {}, double rate = 5.0) {
  ServerOptions o;
  o.rate = rate;
  o.faults = std::move(faults);
  o.log = [](LogLevel, const std::string&) {};
  return o;
}

ServerFault fault(uint64_t at, ServerFault::Kind kind, double value = 0) {
  ServerFault f;
  f.at_azimuth = at;
  f.kind = kind;
  f.value = value;
  return f;
}

/// The emulator (started, with its scripted faults) and a driver connected to it, logging
/// into `log`; `tune` adjusts the driver's configuration.
struct Rig {
  NavtechServer server;
  NavtechDriver d;
  LogSink log;
  explicit Rig(ServerOptions o, ScanSource source = patternSource(),
               const std::function<void(DriverConfig&)>& tune = {})
      : server(std::move(o), std::move(source)), d(startAndConfigure(server, tune)) {
    d.setLog(log.fn());
  }
  static DriverConfig startAndConfigure(NavtechServer& s,
                                        const std::function<void(DriverConfig&)>& tune) {
    s.start();
    DriverConfig c = fastDriverConfig(s.port());
    if (tune) tune(c);
    return c;
  }
};

}  // namespace

TEST(NavtechReliability, CleanStream) {
  Rig rig(serverOptions());
  NavtechDriver& d = rig.d;
  LogSink& log = rig.log;
  PollResult r = pollScans(d, 4, 10);
  ASSERT_EQ(r.scans.size(), 4u) << log.all();
  for (auto& s : r.scans) {
    EXPECT_EQ(s.scan.azimuths, 400);
    EXPECT_EQ(s.scan.bins, 64);
    EXPECT_EQ(s.missing, 0);
    EXPECT_EQ(s.duplicated, 0);
  }
  // Sensor time (wall clock) decoded in the emulator's little-endian order, stamps increasing.
  const auto& p = r.scans.back().scan;
  EXPECT_GT(p.stamp_ns[0], int64_t(1'600'000'000) * 1'000'000'000);
  for (int a = 1; a < p.azimuths; ++a) EXPECT_EQ(p.stamp_ns[a] - p.stamp_ns[a - 1], 625'000);
  EXPECT_TRUE(log.contains("sent Start FFT Data")) << log.all();
  EXPECT_EQ(d.stats().input.connects, 1u);
}

TEST(NavtechReliability, SensorNotUpAtStartThenComesUp) {
  const int port = freePort();
  NavtechDriver d(fastDriverConfig(port));
  LogSink log;
  d.setLog(log.fn());
  PollResult r = pollScans(d, 1, 0.6);  // connection refused for 0.6 s
  EXPECT_TRUE(r.scans.empty());
  const uint64_t failed = d.stats().input.failed_connects;
  // Backoff 0.05, 0.1, 0.2, 0.4 s: a handful of attempts, not a busy loop.
  EXPECT_GE(failed, 2u);
  EXPECT_LE(failed, 8u);
  EXPECT_TRUE(log.contains("Connection refused")) << log.all();
  EXPECT_TRUE(log.contains("retrying in")) << log.all();
  ServerOptions o = serverOptions();
  o.port = port;
  NavtechServer server(o, patternSource());
  server.start();
  r = pollScans(d, 2, 10);
  EXPECT_EQ(r.scans.size(), 2u) << log.all();
}

TEST(NavtechReliability, DisconnectMidRotationReconnects) {
  Rig rig(serverOptions({fault(600, ServerFault::Kind::Disconnect),
                         fault(1500, ServerFault::Kind::Disconnect)}));
  NavtechDriver& d = rig.d;
  LogSink& log = rig.log;
  PollResult r = pollScans(d, 5, 15);
  EXPECT_EQ(r.scans.size(), 5u) << log.all();
  EXPECT_EQ(r.disconnects, 2);
  EXPECT_GE(d.stats().input.connects, 3u);
  EXPECT_TRUE(log.contains("closed by the sensor")) << log.all();
  // The rotations cut by the disconnects and the partial ones after reconnecting are dropped.
  EXPECT_GE(d.stats().dropped_scans, 2u);
}

TEST(NavtechReliability, RestartWithNewConfiguration) {
  ServerFault f = fault(700, ServerFault::Kind::Restart, 0.3);
  f.has_config = true;
  f.config.azimuth_samples = 200;
  f.config.encoder_size = 5600;
  f.config.range_in_bins = 48;
  f.config.bin_size = 596;
  f.config.rotation_mhz = 4000;
  f.config.packet_rate = 800;
  Rig rig(serverOptions({f}));
  NavtechDriver& d = rig.d;
  LogSink& log = rig.log;
  PollResult r = pollScans(d, 4, 15);
  ASSERT_EQ(r.scans.size(), 4u) << log.all();
  EXPECT_EQ(r.scans.front().scan.bins, 64);
  EXPECT_EQ(r.scans.back().scan.azimuths, 200);
  EXPECT_EQ(r.scans.back().scan.bins, 48);
  EXPECT_NEAR(r.scans.back().scan.range_resolution, 0.0596, 1e-9);
  EXPECT_TRUE(log.contains("configuration 200 azimuths")) << log.all();
}

TEST(NavtechReliability, NewConfigurationMidStream) {
  ServerFault f = fault(900, ServerFault::Kind::NewConfiguration);
  f.has_config = true;
  f.config.azimuth_samples = 400;
  f.config.encoder_size = 5600;
  f.config.range_in_bins = 32;
  Rig rig(serverOptions({f}));
  NavtechDriver& d = rig.d;
  LogSink& log = rig.log;
  PollResult r = pollScans(d, 4, 15);
  ASSERT_EQ(r.scans.size(), 4u) << log.all();
  EXPECT_EQ(r.scans.back().scan.bins, 32);
  EXPECT_EQ(r.disconnects, 0);
  EXPECT_TRUE(log.contains("rotation in progress discarded")) << log.all();
}

TEST(NavtechReliability, StalledStreamReconnects) {
  Rig rig(serverOptions({fault(600, ServerFault::Kind::Stall, 1.0)}));  // stall_timeout 0.4 s
  LogSink& log = rig.log;
  PollResult r = pollScans(rig.d, 4, 15);
  EXPECT_EQ(r.scans.size(), 4u) << log.all();
  EXPECT_GE(r.disconnects, 1);
  EXPECT_TRUE(log.contains("stalled stream")) << log.all();
}

TEST(NavtechReliability, CorruptedBytesNeverMakeMalformedScans) {
  using K = ServerFault::Kind;
  Rig rig(serverOptions({fault(450, K::Truncate), fault(900, K::CorruptSignature),
                         fault(1300, K::Oversized, 50e6), fault(1700, K::Garbage, 5000),
                         fault(1702, K::Truncate), fault(2100, K::Oversized, 700e3)}),
          patternSource(), [](DriverConfig& c) { c.min_valid_fraction = 0.9; });
  NavtechDriver& d = rig.d;
  LogSink& log = rig.log;
  PollResult r = pollScans(d, 6, 20);
  EXPECT_EQ(r.scans.size(), 6u) << log.all();
  const DriverStats st = d.stats();
  EXPECT_GE(st.input.stream.truncated, 2u);
  EXPECT_GE(st.input.stream.oversized, 1u);
  EXPECT_GE(st.input.stream.garbage_bytes, 4000u);
  EXPECT_GE(st.missing_azimuths, 3u);  // the damaged azimuths are holes, flagged
  int with_holes = 0;
  for (auto& s : r.scans) with_holes += s.missing > 0;
  EXPECT_GE(with_holes, 1);
  EXPECT_TRUE(log.contains("garbage in stream")) << log.all();
  EXPECT_TRUE(log.contains("over 1 MB")) << log.all();
  EXPECT_TRUE(log.contains("cut short")) << log.all();
}

TEST(NavtechReliability, SlowConsumerAtTenTimesRealRate) {
  Rig rig(serverOptions({}, 10.0), patternSource(400, 256));
  NavtechDriver& d = rig.d;
  LogSink& log = rig.log;
  // The consumer takes 150 ms per scan while the sensor makes one every 25 ms: TCP pushes
  // back, the emulator waits (or drops us), the driver must only ever return whole scans.
  PollResult r = pollScans(d, 8, 20, 150);
  EXPECT_EQ(r.scans.size(), 8u) << log.all();
}

TEST(NavtechReliability, BigEndianSensorTimeAutoDetected) {
  ServerOptions o = serverOptions();
  o.time_order = TimeByteOrder::Big;
  o.wall_clock = false;  // small simulator clock (100 s): the hard case for detection
  NavtechServer server(o, patternSource());
  server.start();
  NavtechDriver d(fastDriverConfig(server.port()));
  PollResult r = pollScans(d, 2, 10);
  ASSERT_EQ(r.scans.size(), 2u);
  EXPECT_EQ(d.stats().byte_order, TimeByteOrder::Big);
  const auto& p = r.scans.back().scan;
  EXPECT_EQ(p.stamp_ns[1] - p.stamp_ns[0], 625'000);
  EXPECT_EQ(p.stamp_ns[0] % 250'000'000, 0);  // rotation starts on the 4 Hz grid from 100 s
}

TEST(NavtechReliability, NeverUpGivesUpNothingButStaysBounded) {
  DriverConfig c = fastDriverConfig(freePort());
  NavtechDriver d(c);
  d.setLog([](LogLevel, const std::string&) {});
  AssembledScan s;
  const auto t0 = Clock::now();
  for (int i = 0; i < 5; ++i) EXPECT_EQ(d.poll(s, std::chrono::milliseconds(50)), InputStatus::Timeout);
  // Each poll returns by its deadline (generous bound: no hang, not a timing assertion).
  EXPECT_LT(Clock::now() - t0, std::chrono::seconds(5));
}
