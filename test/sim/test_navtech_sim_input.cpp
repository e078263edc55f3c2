// The simulator as a driver input: scans pass through the protocol encoder, the stream parser
// and the assembler, and come out identical to the simulator's own rendering.
#include <gtest/gtest.h>

#include "spinradar/driver/navtech_driver.hpp"
#include "spinradar/sim/sim_radar_input.hpp"

using namespace spinradar;
using namespace spinradar::navtech;

TEST(NavtechSimInput, ScansSurviveTheProtocolUnchanged) {
  for (int depth : {8, 16}) {
    auto sim = sim::makeBuiltinSimulator("tight_turns", sim::PhysicsConfig{});
    sim::SimInputOptions o;
    o.first_scan = 2;
    o.n_scans = 2;
    o.bit_depth = depth;
    DriverConfig c;
    c.input = "sim";
    NavtechDriver d(c, sim::makeSimInput(sim, o));
    AssembledScan s;
    std::vector<AssembledScan> got;
    for (int i = 0; i < 100000; ++i) {
      const InputStatus st = d.poll(s, std::chrono::milliseconds(1000));
      if (st == InputStatus::Ok) got.push_back(s);
      if (st == InputStatus::End) break;
      ASSERT_NE(st, InputStatus::Error);
    }
    ASSERT_EQ(got.size(), 2u) << "bit depth " << depth;
    for (int k = 0; k < 2; ++k) {
      const PolarScan truth = sim->renderScan(2 + k);
      const PolarScan& p = got[k].scan;
      EXPECT_EQ(p.azimuths, truth.azimuths);
      EXPECT_EQ(p.bins, truth.bins);
      EXPECT_NEAR(p.range_resolution, truth.range_resolution, 1e-4);  // 0.1 mm units on the wire
      EXPECT_EQ(p.encoder, truth.encoder);
      EXPECT_EQ(p.power, truth.power);
      EXPECT_EQ(p.stamp_ns, truth.stamp_ns);
      EXPECT_EQ(got[k].missing, 0);
      EXPECT_EQ(got[k].bit_depth, depth);
    }
  }
}

TEST(NavtechSimInput, ServerFedBySimulator) {
  auto sim = sim::makeBuiltinSimulator("out_and_back", sim::PhysicsConfig{});
  ServerOptions so;
  so.rate = 0;  // as fast as the client reads
  so.wall_clock = false;
  so.log = [](LogLevel, const std::string&) {};
  NavtechServer server(so, sim::simScanSource(sim, 5));
  server.start();
  DriverConfig c;
  c.port = server.port();
  NavtechDriver d(c);
  d.setLog([](LogLevel, const std::string&) {});
  AssembledScan s;
  int n = 0;
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (n < 2 && std::chrono::steady_clock::now() < end)
    if (d.poll(s, std::chrono::milliseconds(200)) == InputStatus::Ok) ++n;
  ASSERT_EQ(n, 2);
  const PolarScan truth = sim->renderScan(6);
  EXPECT_EQ(s.scan.power, truth.power);
  EXPECT_EQ(s.scan.stamp_ns, truth.stamp_ns);  // simulator clock sent as sensor time
}
