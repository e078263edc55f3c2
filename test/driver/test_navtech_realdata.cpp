// Real Oxford Radar RobotCar rotations (real encoder values, jitter, real stamps) sent through
// the sensor emulator and back through the driver: every row must land where it was.
#include <gtest/gtest.h>

#include <filesystem>

#include "navtech_test_util.hpp"
#include "spinradar/io/scan_io.hpp"

using namespace spinradar;
using namespace spinradar::navtech;
namespace fs = std::filesystem;

TEST(NavtechRealData, OxfordRotationsRoundTripThroughTheProtocol) {
  const fs::path dir = fs::path(SPINRADAR_SHARED_DIR) / "realdata/oxford_2019-01-10-14-36-48/radar";
  if (!fs::exists(dir)) GTEST_SKIP() << dir << " not found (shared real data absent)";
  std::vector<PolarScan> scans;
  for (const auto& e : fs::directory_iterator(dir)) scans.push_back(loadOxfordPng(e.path().string()));
  std::sort(scans.begin(), scans.end(),
            [](const PolarScan& a, const PolarScan& b) { return a.firstStamp() < b.firstStamp(); });
  ASSERT_GE(scans.size(), 2u);
  auto k = std::make_shared<size_t>(0);
  ServerOptions o;
  o.rate = 0;
  o.wall_clock = false;  // keep the recorded stamps
  o.log = [](LogLevel, const std::string&) {};
  NavtechServer server(o, [scans, k](PolarScan& out) {
    if (*k >= scans.size()) return false;
    out = scans[(*k)++];
    return true;
  });
  server.start();
  DriverConfig c = test::fastDriverConfig(server.port());
  NavtechDriver d(c);
  d.setLog([](LogLevel, const std::string&) {});
  std::vector<AssembledScan> got;
  AssembledScan s;
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (got.size() < scans.size() && std::chrono::steady_clock::now() < end) {
    const InputStatus st = d.poll(s, std::chrono::milliseconds(200));
    if (st == InputStatus::Ok) got.push_back(s);
    if (st == InputStatus::Disconnected && server.finished()) break;
  }
  ASSERT_GE(got.size(), 1u);
  for (size_t i = 0; i < got.size(); ++i) {
    const PolarScan& truth = scans[i];
    const PolarScan& p = got[i].scan;
    ASSERT_EQ(p.azimuths, truth.azimuths);
    ASSERT_EQ(p.bins, truth.bins);
    EXPECT_EQ(got[i].missing, 0) << "scan " << i;
    int compared = 0;
    for (int a = 0; a < p.azimuths; ++a) {
      if (!p.valid[a]) continue;
      ++compared;
      EXPECT_EQ(p.encoder[a], truth.encoder[a]) << "scan " << i << " row " << a;
      EXPECT_EQ(p.stamp_ns[a], truth.stamp_ns[a]) << "scan " << i << " row " << a;
      EXPECT_TRUE(std::equal(p.row(a), p.row(a) + p.bins, truth.row(a))) << "scan " << i << " row " << a;
    }
    EXPECT_GE(compared, p.azimuths - got[i].duplicated);
  }
}
