// Issue 10: timing effects in the diagnosis. Simulated recordings with one timing effect hidden
// (stamp bursts, rotation jitter, timestamp offset) must be named with their parameter within
// 15 %, null recordings must give no timing finding, with and without a world file; the real
// samples in ../shared/realdata are checked against their hand-read stamps.
#include <cmath>
#include <filesystem>
#include <iostream>
#include <random>

#include <gtest/gtest.h>

#include "../../src/sim/render_model.hpp"  // the simulator's RNG: realised per-scan stretches
#include "diagnose/diagnose_fixtures.hpp"
#include "spinradar/io/scan_folder.hpp"
#include "spinradar/io/scan_io.hpp"

using namespace spinradar;
using namespace spinradar::diagnose;
using namespace spinradar::diagnose::testing;

namespace {

const nlohmann::json kNone = nlohmann::json::object();  // no effects

bool hasFinding(const TimingReport& t, const std::string& name) {
  for (const auto& f : t.findings)
    if (f.name == name) return true;
  return false;
}

const TimingFinding* finding(const TimingReport& t, const std::string& name) {
  for (const auto& f : t.findings)
    if (f.name == name) return &f;
  return nullptr;
}

void print(const char* what, const DiagnoseReport& rep) {
  std::cout << what << ": " << rep.obs.size() << " obs, " << rep.scans << " scans\n";
  for (const auto& e : rep.effects)
    std::cout << "  catalogue " << e.name << " = " << e.value << " +- " << e.stddev << "\n";
  for (const auto& f : rep.timing.findings)
    std::cout << "  timing " << f.name << " = " << f.value << " +- " << f.stddev << " (z "
              << f.significance << ")\n";
  if (rep.timing.jitter_tested)
    std::cout << "  jitter std " << rep.timing.jitter_std << " chi2 " << rep.timing.jitter_chi2
              << " dof " << rep.timing.jitter_dof << "\n";
  for (const auto& a : rep.timing.advice) std::cout << "  advice: " << a << "\n";
}

// 8 m/s with turns both ways (the latency case of test_concealed).
Drive turning() { return {{{0.8, 8.0, 0.0}, {1.0, 8.0, 0.35}, {1.0, 6.0, -0.35}}, {-5, 0, 0.0}}; }
// 5 s at 8 m/s, turns both ways: room for 16 moving scans (from scan 2 at 4 Hz).
Drive longTurning() {
  return {{{0.8, 8.0, 0.0}, {1.5, 8.0, 0.35}, {1.5, 8.0, -0.35}, {1.2, 8.0, 0.2}}, {-8, 0, 0.0}};
}
// 6 m/s loop with turns both ways and a speed change (test_no_world).
Drive loop() {
  return {{{1.0, 6.0, 0.0}, {1.5, 6.0, 0.4}, {1.0, 3.0, 0.0}, {1.5, 6.0, -0.4}}, {-5, 0, 0.0}};
}

// ---- stamps alone: no world, no trajectory needed ----

std::vector<PolarScan> stampsOnly(const nlohmann::json& hidden, int n, uint64_t seed) {
  sim::World empty;  // stamps do not depend on the scene
  return makeInput(empty, loop(), sim::PhysicsConfig::fromJson(hidden), n, seed).scans;
}

TEST(TimingStamps, BurstsOfSixteenFoundAndFitted) {
  const auto scans = stampsOnly({{"stamp_bursts", {{"size", 16}, {"spacing", 135e-6}}}}, 3, 5);
  const TimingReport t = analyseStamps(scans, 4.0);
  ASSERT_TRUE(t.bursts);
  EXPECT_EQ(t.burst_size, 16);
  EXPECT_NEAR(t.burst_spacing, 135e-6, 0.15 * 135e-6);
  EXPECT_NEAR(t.burst_gap, 16 * 625e-6 - 15 * 135e-6, 2e-6);  // 7.975 ms
  EXPECT_NEAR(t.period_mean, 0.25, 1e-6);
  ASSERT_TRUE(hasFinding(t, "stamp_bursts"));
  EXPECT_FALSE(hasFinding(t, "rotation_period_variation"));
  // The corrected stamps are the uniform firing times (delay 0 here): within a microsecond.
  const auto fixed = correctedStamps(scans, t);
  for (int a = 0; a < fixed[1].azimuths; ++a)
    EXPECT_NEAR((fixed[1].stamp_ns[a] - fixed[1].stamp_ns[0]) * 1e-9, a * 625e-6, 1e-6);
  EXPECT_FALSE(hasFinding(analyseStamps(fixed, 4.0), "stamp_bursts"));
}

TEST(TimingStamps, OtherPacketSizeAndSpacing) {
  const auto scans =
      stampsOnly({{"stamp_bursts", {{"size", 10}, {"spacing", 300e-6}, {"delay", 0.004}}}}, 2, 6);
  const TimingReport t = analyseStamps(scans, 4.0);
  ASSERT_TRUE(t.bursts);
  EXPECT_EQ(t.burst_size, 10);
  EXPECT_NEAR(t.burst_spacing, 300e-6, 0.15 * 300e-6);
  EXPECT_DOUBLE_EQ(t.burst_size_agreement, 1.0);
}

TEST(TimingStamps, UniformStampsGiveNoFinding) {
  for (uint64_t seed : {7u, 8u}) {
    const TimingReport t = analyseStamps(stampsOnly(nlohmann::json::object(), 4, seed), 4.0);
    EXPECT_FALSE(t.bursts);
    EXPECT_TRUE(t.findings.empty()) << t.toJson().dump();
    EXPECT_EQ(t.stamp_model, "uniform");
  }
}

TEST(TimingStamps, StampsWrittenInMicrosecondsStayUniform) {
  // The Oxford PNG layout truncates stamps to microseconds: no pattern may be read into that.
  auto scans = stampsOnly(nlohmann::json::object(), 3, 9);
  for (auto& s : scans)
    for (auto& st : s.stamp_ns) st = st / 1000 * 1000 + 137;  // truncation plus a constant
  const TimingReport t = analyseStamps(scans, 4.0);
  EXPECT_TRUE(t.findings.empty()) << t.toJson().dump();
}

TEST(TimingStamps, NoisyUniformStampsGiveNoFinding) {
  // Uniform stamps with 30 us Gaussian noise (Boreas-RT has 36 us RMS about a line). Before the
  // gap-size and packet-size checks the burst search named "bursts" in 2 of these 20 draws.
  std::mt19937 g(1);
  std::normal_distribution<double> noise(0.0, 30e-6);
  for (int r = 0; r < 20; ++r) {
    auto scans = stampsOnly(kNone, 3, 300 + r);
    for (auto& s : scans)
      for (auto& st : s.stamp_ns) st += std::llround(noise(g) * 1e9);
    const TimingReport t = analyseStamps(scans, 4.0);
    EXPECT_FALSE(t.bursts) << "draw " << r << ": z " << t.burst_z;
    EXPECT_TRUE(t.findings.empty()) << "draw " << r << ": " << t.toJson()["findings"].dump();
  }
}

TEST(TimingStamps, StampsThatDoNotAdvanceGiveNoFinding) {
  auto scans = stampsOnly(kNone, 3, 10);
  for (auto& s : scans) std::fill(s.stamp_ns.begin(), s.stamp_ns.end(), 0);
  const TimingReport t = analyseStamps(scans, 4.0);
  EXPECT_TRUE(t.findings.empty());
  EXPECT_FALSE(std::isnan(t.period_rel_std));
}

// ---- with a world file: the catalogue stage runs on the corrected stamps ----

DiagnoseReport withWorld(const nlohmann::json& hidden, const nlohmann::json& base, int n,
                         uint64_t seed, const Drive& drive = turning()) {
  const sim::World world = randomWorld(seed, 90, 55.0, false);
  DiagnoseInput in = makeInput(world, drive, sim::PhysicsConfig::fromJson(hidden), n, seed);
  in.base = sim::PhysicsConfig::fromJson(base);
  return spinradar::diagnose::diagnose(in, {});
}

TEST(TimingWorld, BurstsNamedAndCatalogueStaysClean) {
  const DiagnoseReport rep =
      withWorld({{"stamp_bursts", {{"size", 16}, {"spacing", 135e-6}}}}, kNone, 6, 21);
  print("bursts, world", rep);
  ASSERT_TRUE(hasFinding(rep.timing, "stamp_bursts"));
  EXPECT_EQ(rep.timing.burst_size, 16);
  EXPECT_NEAR(rep.timing.burst_spacing, 135e-6, 0.15 * 135e-6);
  EXPECT_TRUE(rep.effects.empty());  // the stamps were corrected before the catalogue stage
  EXPECT_TRUE(rep.mismatch_found);
  EXPECT_NE(rep.toJson()["timing"]["advice"][0].get<std::string>().find("packet"),
            std::string::npos);
}

// A packet delay (arrival after the packet's last row is acquired) is not in the stamps' shape:
// after the correction it is left as a timestamp offset, which the catalogue stage measures.
TEST(TimingWorld, BurstDelayMeasuredAsTimestampOffset) {
  const DiagnoseReport rep = withWorld(
      {{"stamp_bursts", {{"size", 16}, {"spacing", 135e-6}, {"delay", 0.02}}}}, kNone, 6, 26);
  print("bursts + 20 ms delay, world", rep);
  ASSERT_TRUE(rep.timing.bursts);
  EXPECT_EQ(rep.timing.burst_size, 16);
  ASSERT_FALSE(rep.effects.empty());
  EXPECT_EQ(rep.effects.front().name, "timestamp_offset");
  EXPECT_NEAR(rep.effects.front().value, 0.02, 0.15 * 0.02);
  bool delay = false;
  for (const auto& a : rep.timing.advice) delay = delay || a.find("packet delay") != std::string::npos;
  EXPECT_TRUE(delay);
}

TEST(TimingWorld, TimestampOffsetNamedInTheTimingAdvice) {
  const DiagnoseReport rep = withWorld({{"timestamp_offset", 0.03}}, kNone, 6, 22);
  print("offset, world", rep);
  ASSERT_FALSE(rep.effects.empty());
  EXPECT_EQ(rep.effects.front().name, "timestamp_offset");
  EXPECT_NEAR(rep.effects.front().value, 0.03, 0.15 * 0.03);
  EXPECT_FALSE(rep.timing.bursts);
  bool named = false;
  for (const auto& a : rep.timing.advice)
    named = named || (a.find("timestamp_offset") != std::string::npos &&
                      a.find("correct them by -") != std::string::npos);
  EXPECT_TRUE(named);
  EXPECT_FALSE(hasFinding(rep.timing, "rotation_jitter"));
}

/// The simulator's per-scan stretches for makeInput's scans (renderScan(k): key 2k + 1).
double realisedJitterStd(uint64_t seed, double jitter, int first, int n) {
  std::vector<double> e;
  double mean = 0;
  for (int k = first; k < first + n; ++k) {
    sim::detail::Rng rng(seed * 0x9E3779B97F4A7C15ull ^ (uint64_t(k) * 2 + 1));
    e.push_back(jitter * rng.normal());
    mean += e.back() / n;
  }
  double ss = 0;
  for (double x : e) ss += (x - mean) * (x - mean);
  return std::sqrt(ss / (n - 1));
}

// Rotation jitter hides in the firing times only (stamps stay nominal), so it is seen only
// through where the targets appear: a stretch e_k shifts a row's true time by e_k * tau (up to
// 0.25 e_k s at the end of the sweep). At 3 % std that is up to ~7 ms, i.e. 6 cm at 8 m/s and
// ~2.5 mrad of yaw at 0.35 rad/s (10 cm at 40 m): a few bins, well above the peak noise, so
// each scan's stretch is measured to a fraction of the spread. 1 % would sit at the edge.
TEST(TimingWorld, RotationJitterNamedWithItsStd) {
  const nlohmann::json md = {{"motion_distortion", true}};
  nlohmann::json hidden = md;
  hidden["rotation_jitter"] = 0.03;
  const int n = 16;
  const uint64_t seed = 23;
  const DiagnoseReport rep = withWorld(hidden, md, n, seed, longTurning());
  print("jitter, world", rep);
  for (const auto& f : rep.timing.findings) std::cout << "  evidence: " << f.evidence << "\n";
  const double truth = realisedJitterStd(seed, 0.03, 2, n);
  std::cout << "  realised std " << truth << "\n";
  const TimingFinding* f = finding(rep.timing, "rotation_jitter");
  ASSERT_NE(f, nullptr);
  EXPECT_NEAR(f->value, truth, 0.15 * truth);
  EXPECT_FALSE(rep.timing.bursts);
}

// The catalogue effects leave no timing finding behind (their residual structure is the same
// in every scan, so the per-scan stretches stay equal).
TEST(TimingWorld, CatalogueEffectsGiveNoTimingFinding) {
  const Drive walking = {{{1.0, 1.5, 0.0}, {2.0, 1.5, 0.15}, {1.0, 0.6, 0.0}, {2.0, 1.5, -0.15}},
                         {0, 0, 0.3}};
  const Drive straight = {{{1.5, 10.0, 0.0}, {1.5, 10.0, 0.03}}, {-10, -5, 0.1}};
  struct C {
    nlohmann::json hidden;
    Drive drive;
    uint64_t seed;
  };
  for (const C& c : {C{{{"doppler", 0.049}}, walking, 31}, C{{{"motion_distortion", true}}, straight, 32},
                     C{{{"azimuth_offset", 0.0105}}, turning(), 33},
                     C{{{"range_offset", -0.3}}, turning(), 34}}) {
    const DiagnoseReport rep = withWorld(c.hidden, kNone, 6, c.seed, c.drive);
    print(c.hidden.dump().c_str(), rep);
    EXPECT_FALSE(rep.effects.empty()) << c.hidden.dump();
    EXPECT_TRUE(rep.timing.findings.empty()) << c.hidden.dump();
  }
}

TEST(TimingWorld, NullDrivesGiveNoTimingFinding) {
  for (uint64_t seed : {24u, 25u}) {
    const DiagnoseReport rep = withWorld(kNone, kNone, 6, seed);
    print("null, world", rep);
    EXPECT_TRUE(rep.timing.findings.empty()) << "seed " << seed;
    EXPECT_FALSE(rep.mismatch_found) << "seed " << seed;
  }
}

// ---- without a world file: scene mapped from the recording ----

DiagnoseReport withoutWorld(const nlohmann::json& hidden, const nlohmann::json& base,
                            uint64_t seed) {
  const sim::World world = randomWorld(seed, 90, 55.0, false);
  DiagnoseInput in = makeInput(world, loop(), sim::PhysicsConfig::fromJson(hidden), 16, seed);
  in.base = sim::PhysicsConfig::fromJson(base);
  return diagnoseRecording(in, {}, false, "early-late");
}

TEST(TimingNoWorld, BurstsNamedAndNullClean) {
  const DiagnoseReport bursts =
      withoutWorld({{"stamp_bursts", {{"size", 16}, {"spacing", 135e-6}}}}, kNone, 81);
  print("bursts, no world", bursts);
  ASSERT_TRUE(hasFinding(bursts.timing, "stamp_bursts"));
  EXPECT_EQ(bursts.timing.burst_size, 16);
  EXPECT_NEAR(bursts.timing.burst_spacing, 135e-6, 0.15 * 135e-6);
  EXPECT_TRUE(bursts.effects.empty());
  const DiagnoseReport null = withoutWorld(kNone, kNone, 83);
  print("null, no world", null);
  EXPECT_TRUE(null.timing.findings.empty());
  EXPECT_FALSE(null.mismatch_found);
}

// Without a world the per-scan stretch is fitted with its direct regressor (the map does not
// move with a test scan's own stretch) and the target positions are not refitted. On the
// noise-free loop the peaks are quantised (shifts below a bin read as 0), so the spread comes
// out somewhat low here (measured 0.79-0.97 of the realised std over seeds 85-88); the
// noisy-sensor case below is the accuracy check.
// Base and recording without motion distortion: the whole scan is rendered from the pose at
// mid-sweep, so a stretch e_k shifts it in time by e_k * T / 2 (the tau_fixed path).
TEST(TimingNoWorld, RotationJitterDetected) {
  const uint64_t seed = 85;
  const DiagnoseReport rep = withoutWorld({{"rotation_jitter", 0.03}}, kNone, seed);
  print("jitter, no world", rep);
  const double truth = realisedJitterStd(seed, 0.03, 2 + 8, 8);  // the 8 test scans
  std::cout << "  realised std (test scans) " << truth << "\n";
  const TimingFinding* f = finding(rep.timing, "rotation_jitter");
  ASSERT_NE(f, nullptr);
  EXPECT_GT(f->value, 0.7 * truth);
  EXPECT_LT(f->value, 1.15 * truth);
}

// Issue #10: named and fitted within 15 % without a world file. Drive: longTurning() (8 m/s,
// turns both ways), 20 scans, early-late split (map scans 2-11, test scans 12-21), noisy
// sensor (peaks scatter by a fraction of a bin instead of being quantised). The drive ends
// after scan 19: in the last two test scans the sensor stands still, a stretch moves nothing
// and they are left out (7 dof). Measured ratio fitted / realised: 1.00, 1.01, 1.04, 1.08 for
// seeds 85-88; nulls on the same drive: p 0.36, 0.12, 0.03, 0.94, no finding.
sim::SensorConfig noisyTimingSensor() {
  sim::SensorConfig s = smallSensor();
  s.noise_floor_db = s.radar_constant_db - 28.0;
  s.clutter_db = 0.0;
  return s;
}

DiagnoseReport withoutWorldNoisy(const nlohmann::json& hidden, uint64_t seed) {
  const sim::World world = randomWorld(seed, 90, 55.0, false);
  DiagnoseInput in = makeInput(world, longTurning(), sim::PhysicsConfig::fromJson(hidden), 20,
                               seed, noisyTimingSensor());
  in.base = sim::PhysicsConfig::fromJson(kNone);
  return diagnoseRecording(in, {}, false, "early-late");
}

TEST(TimingNoWorld, RotationJitterFittedWithin15Percent) {
  for (uint64_t seed : {85ull, 86ull}) {
    const DiagnoseReport rep = withoutWorldNoisy({{"rotation_jitter", 0.03}}, seed);
    print("jitter, no world, noisy sensor", rep);
    const double truth = realisedJitterStd(seed, 0.03, 12, 8);  // the 8 moving test scans
    std::cout << "  realised std (moving test scans) " << truth << "\n";
    const TimingFinding* f = finding(rep.timing, "rotation_jitter");
    ASSERT_NE(f, nullptr) << "seed " << seed;
    EXPECT_EQ(rep.timing.jitter_dof, 7) << "seed " << seed;
    EXPECT_NEAR(f->value, truth, 0.15 * truth) << "seed " << seed;
  }
}

TEST(TimingNoWorld, RotationJitterNullsClean) {
  for (uint64_t seed : {85ull, 86ull, 87ull}) {
    const DiagnoseReport rep = withoutWorldNoisy(kNone, seed);
    EXPECT_TRUE(rep.timing.jitter_tested) << "seed " << seed;
    EXPECT_FALSE(hasFinding(rep.timing, "rotation_jitter")) << "seed " << seed;
  }
}

// ---- real samples (../shared/realdata) ----

std::string shared() {
#ifdef SPINRADAR_SHARED_DIR
  return SPINRADAR_SHARED_DIR;
#else
  return "";
#endif
}

TEST(TimingRealData, OxfordStampsAreBurstsOfSixteen) {
  const std::string dir = shared() + "/realdata/oxford_2019-01-10-14-36-48";
  if (shared().empty() || !std::filesystem::exists(dir))
    GTEST_SKIP() << "real data not found (" << dir << "); set SPINRADAR_SHARED_DIR";
  ScanFolder folder(dir, ScanFormat::Oxford);
  std::vector<PolarScan> scans;
  for (size_t i = 0; i < folder.size(); ++i) scans.push_back(folder.load(i));
  ASSERT_EQ(scans.size(), 3u);
  const TimingReport t = analyseStamps(scans, 4.0);
  std::cout << t.summaryMarkdown();
  // Hand-read from the stamps (awk over the 1200 rows): 75 steps above 2 ms (mean 7863.5 us),
  // 72 complete packets of 16 rows, mean step inside a complete packet 146.8 us (median step
  // 133.9 us: arrivals clump, so some steps are ~8 us and others ~260 us); scan 1 starts with
  // 14 rows of a packet (its first gap follows row 13). README: ~16 rows ~135 us apart.
  ASSERT_TRUE(t.bursts);
  EXPECT_NEAR(t.burst_size, 16, 1);
  EXPECT_EQ(t.burst_size, 16);
  EXPECT_DOUBLE_EQ(t.burst_size_agreement, 1.0);
  EXPECT_NEAR(t.burst_spacing, 146.8e-6, 0.05 * 146.8e-6);
  EXPECT_NEAR(t.burst_spacing, 135e-6, 0.15 * 135e-6);
  EXPECT_NEAR(t.burst_gap, 7863.5e-6, 0.01 * 7863.5e-6);
  EXPECT_EQ(t.burst_phase.front(), 14);
  EXPECT_NEAR(t.row_interval, 625e-6, 10e-6);  // README: mean 625 us
  EXPECT_GT(t.stamp_rms_uniform, 5 * t.stamp_rms_model);
  ASSERT_TRUE(hasFinding(t, "stamp_bursts"));
  // Three scans: any scan-to-scan statement must say it is weak evidence.
  for (const auto& f : t.findings) {
    if (f.name == "rotation_period_variation") {
      EXPECT_NE(f.evidence.find("weak evidence"), std::string::npos);
    }
  }
}

TEST(TimingRealData, MulranBurstyBoreasRtUniform) {
  const std::string m = shared() + "/realdata/mulran/1564718976161407002.csv";
  const std::string b = shared() + "/realdata/boreas_rt/test_frame.png";
  if (shared().empty() || !std::filesystem::exists(m) || !std::filesystem::exists(b))
    GTEST_SKIP() << "real data not found (" << m << ", " << b << "); set SPINRADAR_SHARED_DIR";
  // MulRan, hand-read: 25 steps above 2 ms (mean 6976.1 us), 24 complete packets of 16 rows
  // with a mean step of 202.4 us inside (steps range from 5 to 650 us).
  const TimingReport tm = analyseStamps({loadMulranCsv(m)}, 4.0);
  std::cout << tm.summaryMarkdown();
  ASSERT_TRUE(tm.bursts);
  EXPECT_EQ(tm.burst_size, 16);
  EXPECT_NEAR(tm.burst_spacing, 202.4e-6, 0.05 * 202.4e-6);
  EXPECT_NEAR(tm.burst_gap, 6976.1e-6, 0.01 * 6976.1e-6);
  // Boreas-RT: stamps uniform at ~625 us (README), one scan.
  const TimingReport tb = analyseStamps({loadBoreasPng(b)}, 4.0);
  std::cout << tb.summaryMarkdown();
  EXPECT_FALSE(tb.bursts);
  EXPECT_EQ(tb.stamp_model, "uniform");
}

}  // namespace

