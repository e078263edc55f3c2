// Capture record -> replay gives the very scans the live driver produced, deterministically.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "navtech_test_util.hpp"

using namespace spinradar;
using namespace spinradar::navtech;
using namespace spinradar::navtech::test;

namespace {

std::vector<AssembledScan> drain(NavtechDriver& d, int max_scans, int* disconnects = nullptr) {
  std::vector<AssembledScan> out;
  AssembledScan s;
  for (int guard = 0; guard < 100000 && int(out.size()) < max_scans; ++guard) {
    const InputStatus st = d.poll(s, std::chrono::milliseconds(100));
    if (st == InputStatus::Ok) out.push_back(s);
    if (st == InputStatus::Disconnected && disconnects) ++*disconnects;
    if (st == InputStatus::End || st == InputStatus::Error) break;
  }
  return out;
}

void expectSame(const AssembledScan& a, const AssembledScan& b) {
  EXPECT_EQ(a.scan.power, b.scan.power);
  EXPECT_EQ(a.scan.stamp_ns, b.scan.stamp_ns);
  EXPECT_EQ(a.scan.encoder, b.scan.encoder);
  EXPECT_EQ(a.scan.valid, b.scan.valid);
  EXPECT_EQ(a.scan.azimuth, b.scan.azimuth);
  EXPECT_EQ(a.last_receive_ns, b.last_receive_ns);
}

std::string tempPath(const char* name) {
  return ::testing::TempDir() + "/spinradar_" + name + "_" + std::to_string(::getpid()) + ".cap";
}

}  // namespace

TEST(NavtechCapture, RecordThenReplayGivesIdenticalScans) {
  const std::string path = tempPath("record");
  std::vector<AssembledScan> live;
  {
    using K = ServerFault::Kind;
    ServerOptions o;
    o.rate = 5;
    o.log = [](LogLevel, const std::string&) {};
    ServerFault garbage, disconnect;
    garbage.at_azimuth = 700;
    garbage.kind = K::Garbage;
    garbage.value = 300;
    disconnect.at_azimuth = 1300;
    disconnect.kind = K::Disconnect;
    o.faults = {garbage, disconnect};
    NavtechServer server(o, patternSource());
    server.start();
    DriverConfig c = fastDriverConfig(server.port());
    c.record_file = path;
    c.time_source = "smoothed";  // depends on receive stamps: must replay exactly too
    NavtechDriver d(c);
    d.setLog([](LogLevel, const std::string&) {});
    int disconnects = 0;
    live = drain(d, 5, &disconnects);
    ASSERT_EQ(live.size(), 5u);
    EXPECT_EQ(disconnects, 1);
  }  // driver closed: capture flushed
  for (int pass = 0; pass < 2; ++pass) {
    DriverConfig c;
    c.input = "capture";
    c.capture_file = path;
    c.time_source = "smoothed";
    NavtechDriver d(c);
    d.setLog([](LogLevel, const std::string&) {});
    int disconnects = 0;
    auto replay = drain(d, 100, &disconnects);
    ASSERT_GE(replay.size(), live.size());
    EXPECT_EQ(disconnects, 2);  // the fault, and the driver closing at the end of recording
    for (size_t i = 0; i < live.size(); ++i) expectSame(live[i], replay[i]);
  }
  std::remove(path.c_str());
}

TEST(NavtechCapture, ReplayAtRealRateIsPaced) {
  const std::string path = tempPath("paced");
  {
    CaptureWriter w(path);
    std::vector<uint8_t> b;
    Configuration c;
    c.azimuth_samples = 4;
    c.encoder_size = 40;
    c.range_in_bins = 2;
    encodeConfiguration(b, c);
    w.writeChunk(0, b.data(), b.size());
    const uint8_t bins[2] = {1, 2};
    for (int a = 0; a < 8; ++a) {
      b.clear();
      encodeFft8(b, 0, uint16_t((a % 4) * 10), 1'600'000'000'000'000'000 + a * 10'000'000, bins, 2);
      w.writeChunk(int64_t(a) * 10'000'000, b.data(), b.size());  // 10 ms apart
    }
  }
  DriverConfig c;
  c.input = "capture";
  c.capture_file = path;
  c.capture_rate = 1.0;
  NavtechDriver d(c);
  const auto t0 = std::chrono::steady_clock::now();
  auto scans = drain(d, 10);
  const auto took = std::chrono::steady_clock::now() - t0;
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_EQ(scans[1].scan.stamp_ns[3], 1'600'000'000'000'000'000 + 70'000'000);
  // 70 ms of recording: replay must not be instantaneous (lower bound only, no upper bound).
  EXPECT_GE(took, std::chrono::milliseconds(60));
  std::remove(path.c_str());
}

TEST(NavtechCapture, CorruptFilesGiveClearErrors) {
  const std::string path = tempPath("corrupt");
  {
    std::ofstream f(path, std::ios::binary);
    f << "NOTACAPTURE";
  }
  try {
    CaptureReader r(path);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("bad magic"), std::string::npos);
  }
  {
    std::ofstream f(path, std::ios::binary);
    f.write("SPINCAP1", 8);
    const uint8_t rec[12] = {0, 0, 0, 0, 0, 0, 0, 0, 0xFF, 0xFF, 0xFF, 0x7F};  // absurd length
    f.write(reinterpret_cast<const char*>(rec), 12);
  }
  DriverConfig c;
  c.input = "capture";
  c.capture_file = path;
  NavtechDriver d(c);
  std::string logged;
  d.setLog([&](LogLevel, const std::string& m) { logged += m; });
  AssembledScan s;
  EXPECT_EQ(d.poll(s, std::chrono::milliseconds(100)), InputStatus::Error);
  EXPECT_NE(logged.find("corrupt capture record"), std::string::npos) << logged;
  std::remove(path.c_str());
  EXPECT_THROW(CaptureReader("/nonexistent/x.cap"), std::runtime_error);
}
