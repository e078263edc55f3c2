// Rendering properties: determinism, PNG round trip, stamp bursts, realism sanity, threads.
#include <gtest/gtest.h>

#include <filesystem>
#include <thread>

#include "sim_test_util.hpp"
#include "spinradar/io/scan_io.hpp"
#include "spinradar/sim/realism.hpp"
#include "spinradar/sim/scenes.hpp"

using namespace spinradar;
using namespace spinradar::sim;
using namespace spinradar::sim::testing;
namespace fs = std::filesystem;

TEST(SimRender, DeterministicForASeed) {
  Scene sc = builtinScene("out_and_back");
  PhysicsConfig p;
  p.motion_distortion = true;
  p.doppler = 0.049;
  Simulator a(sc.world, sc.trajectory, SensorConfig{}, p, 7), b(sc.world, sc.trajectory, SensorConfig{}, p, 7),
      c(sc.world, sc.trajectory, SensorConfig{}, p, 8);
  PolarScan s1 = a.renderScan(40), s2 = b.renderScan(40), s3 = c.renderScan(40);
  EXPECT_EQ(s1.power, s2.power);
  EXPECT_EQ(s1.stamp_ns, s2.stamp_ns);
  EXPECT_NE(s1.power, s3.power);
  // Rendering other scans in between does not change a scan.
  a.renderScan(3);
  EXPECT_EQ(a.renderScan(40).power, s1.power);
}

TEST(SimRender, ThreadSafeConstRendering) {
  Scene sc = builtinScene("tight_turns");
  Simulator sim(sc.world, sc.trajectory, SensorConfig{}, PhysicsConfig{}, 2);
  PolarScan ref1 = sim.renderScan(10), ref2 = sim.renderScan(20);
  PolarScan t1, t2;
  std::thread th1([&] { t1 = sim.renderScan(10); });
  std::thread th2([&] { t2 = sim.renderScan(20); });
  th1.join();
  th2.join();
  EXPECT_EQ(t1.power, ref1.power);
  EXPECT_EQ(t2.power, ref2.power);
}

TEST(SimRender, PngRoundTrip) {
  Scene sc = builtinScene("city");
  Simulator sim(sc.world, sc.trajectory, SensorConfig{}, PhysicsConfig{}, 1);
  PolarScan s = sim.renderScan(12);
  fs::path p = fs::temp_directory_path() / ("spinradar_sim_png_" + std::to_string(::getpid()) + ".png");
  saveOxfordPng(s, p.string());
  PolarScan r = loadOxfordPng(p.string(), s.range_resolution);
  EXPECT_EQ(r.azimuths, s.azimuths);
  EXPECT_EQ(r.bins, s.bins);
  EXPECT_EQ(r.power, s.power);
  EXPECT_EQ(r.encoder, s.encoder);
  for (int a = 0; a < s.azimuths; ++a) EXPECT_EQ(r.stamp_ns[a], s.stamp_ns[a] / 1000 * 1000);
  fs::remove(p);
}

TEST(SimRender, WriteRecordingFolder) {
  Scene sc = builtinScene("out_and_back");
  PhysicsConfig p;
  p.doppler = 0.049;
  Simulator sim(sc.world, sc.trajectory, SensorConfig{}, p, 1);
  fs::path dir = fs::temp_directory_path() / ("spinradar_sim_rec_" + std::to_string(::getpid()));
  int n = writeRecording(sim, dir.string(), 5, 3);
  EXPECT_EQ(n, 3);
  for (const char* f : {"radar.timestamps", "trajectory.csv", "world.json", "physics.json", "sensor.json"})
    EXPECT_TRUE(fs::exists(dir / f)) << f;
  PolarScan first = sim.renderScan(5);
  EXPECT_TRUE(fs::exists(dir / "radar" / (std::to_string(first.firstStamp() / 1000) + ".png")));
  EXPECT_EQ(PhysicsConfig::load((dir / "physics.json").string()).doppler, 0.049);
  EXPECT_EQ(World::load((dir / "world.json").string()).toJson(), sim.world().toJson());
  fs::remove_all(dir);
}

TEST(SimRender, StampBurstsLikeTheOxfordSample) {
  PhysicsConfig p = PhysicsConfig::fromJson(nlohmann::json::parse(R"({"stamp_bursts": true})"));
  Simulator sim(oneTarget(20, 0), constantMotion(0, 0), SensorConfig{}, p, 1);
  PolarScan s = sim.renderScan(1);
  // 16 rows 135 us apart, then a gap; mean spacing still 625 us.
  EXPECT_EQ(s.stamp_ns[1] - s.stamp_ns[0], 135000);
  EXPECT_EQ(s.stamp_ns[15] - s.stamp_ns[14], 135000);
  EXPECT_EQ(s.stamp_ns[16] - s.stamp_ns[15], 16 * 625000 - 15 * 135000);
  EXPECT_NEAR(double(s.stamp_ns[399] - s.stamp_ns[0]) / 399, 625000, 20000);
  // Stamps are never earlier than the true acquisition time.
  for (int a = 0; a < 400; ++a) EXPECT_GE(s.stamp_ns[a], 250000000 + a * 625000);
}

TEST(SimRender, ChirpAlternationFlipsDopplerOnAlternateAzimuths) {
  PhysicsConfig p = PhysicsConfig::fromJson(
      nlohmann::json::parse(R"({"doppler": 0.049, "chirp_alternate": true})"));
  Simulator sim(oneTarget(60, 0), constantMotion(10, 0), SensorConfig{}, p, 1);
  PolarScan s = sim.renderScan(1);
  ASSERT_EQ(s.chirp_up.size(), 400u);
  EXPECT_EQ(s.chirp_up[0], 1);
  EXPECT_EQ(s.chirp_up[1], 0);
  Peak up = findPeak(s, 0, 0), down = findPeak(s, 1, 1);
  // Up: 0.49 m closer; down: 0.49 m farther.
  EXPECT_NEAR((down.fine_bin - up.fine_bin) * s.range_resolution, 2 * 0.049 * 10, 0.05);
}

TEST(SimRender, WallsOccludeWhatIsBehindThem) {
  World w = oneTarget(40, 0, 25);
  w.walls.push_back({20, -3, 20, 3, 0});
  Simulator sim(w, constantMotion(0, 0), SensorConfig{}, PhysicsConfig{}, 1);
  PolarScan s = sim.renderScan(0);
  Peak p = findPeak(s, 0, 3, 100, 3000);
  EXPECT_NEAR(s.rangeOfBin(p.fine_bin), 20, 0.1);  // the wall, not the target at 40 m
  int b40 = int(s.binOfRange(40));
  EXPECT_LT(findPeak(s, 0, 2, b40 - 5, b40 + 5).value, 40);
}

TEST(SimRender, BuiltinScenesLookLikeRealScans) {
  // Coarse bounds around the Oxford and MulRan figures (see `spinradar realism`).
  Scene sc = builtinScene("city");
  PhysicsConfig p;
  p.moving_objects = true;
  Simulator sim(sc.world, sc.trajectory, SensorConfig{}, p, 1);
  std::vector<PolarScan> scans{sim.renderScan(100), sim.renderScan(400)};
  RealismOptions o;
  o.detect = false;
  RealismStats st = computeRealism(scans, "city", o);
  EXPECT_GT(st.zero_fraction, 0.2);
  EXPECT_LT(st.zero_fraction, 0.45);
  EXPECT_GT(st.q99, 50);
  EXPECT_GT(st.azimuth_corr, 0.6);
  EXPECT_GT(st.range_corr_short, 0.7);
}

TEST(SimRender, MultipathGhostAppearsAtTheMirrorImage) {
  // Target at (30, 5), wall along y = 10 (beside it): the double-bounce ghost is the mirror
  // image (30, 15), seen through the wall.
  World w = oneTarget(30, 5, 30);
  w.walls.push_back({0, 10, 60, 10, -30});
  PhysicsConfig p = PhysicsConfig::fromJson(nlohmann::json::parse(R"({"multipath": -10})"));
  Simulator with(w, constantMotion(0, 0), SensorConfig{}, p, 1);
  Simulator without(w, constantMotion(0, 0), SensorConfig{}, PhysicsConfig{}, 1);
  double psi = 2 * M_PI - std::atan2(15.0, 30.0);  // clockwise azimuth of the ghost
  int a = int(std::lround(psi / (2 * M_PI / 400))) % 400;
  PolarScan s1 = with.renderScan(0), s0 = without.renderScan(0);
  int b = int(s1.binOfRange(std::hypot(30.0, 15.0)));
  int ghost = findPeak(s1, a - 1, a + 1, b - 4, b + 4).value;
  int none = findPeak(s0, a - 1, a + 1, b - 4, b + 4).value;
  EXPECT_GT(ghost, none + 20);
}
