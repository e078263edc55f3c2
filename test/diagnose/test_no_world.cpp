// Issue 10: diagnosis without a world file. The scene is mapped from one part of the recording
// (map-aware regressors: the mapped positions move with each effect), the rest is diagnosed;
// the split is chosen by --map-split auto. Every catalogue effect is hidden in turn and must be
// named first and fitted within 15 %, with the re-simulated residual lower after the fit (any
// further effect only a small remainder); drives recorded with the base model must come out
// clean.
#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include "diagnose/diagnose_fixtures.hpp"

using namespace spinradar;
using namespace spinradar::diagnose;
using namespace spinradar::diagnose::testing;

namespace {

// Noise floor 28 dB below the radar constant (as in test_concealed.cpp).
sim::SensorConfig noisySensor() {
  sim::SensorConfig s = smallSensor();
  s.noise_floor_db = s.radar_constant_db - 28.0;
  s.clutter_db = 0.0;
  return s;
}

struct Case {
  const char* name;
  nlohmann::json hidden;
  Drive drive;
  int scans;
  uint64_t seed;
  const char* split;   // the split --map-split auto must choose for this drive
  const char* expect;  // effect name, or "" for the null case
  double value;
  bool noisy = false;
};

// Out and back: straight, a U-turn to the left, straight back past the same targets.
Drive outBack() {
  return {{{1.5, 6.0, 0.0}, {M_PI / 0.9, 4.0, 0.9}, {1.5, 6.0, 0.0}}, {-8, -4, 0.0}};
}
// 6 m/s loop with turns both ways and a speed change.
Drive loop() {
  return {{{1.0, 6.0, 0.0}, {1.5, 6.0, 0.4}, {1.0, 3.0, 0.0}, {1.5, 6.0, -0.4}}, {-5, 0, 0.0}};
}

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

class NoWorld : public ::testing::TestWithParam<Case> {};

TEST_P(NoWorld, NamesAndFitsTheHiddenEffect) {
  const Case& c = GetParam();
  const sim::World world = randomWorld(c.seed, 90, 55.0, false);
  const DiagnoseInput in =
      makeInput(world, c.drive, sim::PhysicsConfig::fromJson(c.hidden), c.scans, c.seed,
                c.noisy ? noisySensor() : smallSensor());
  DiagnoseOptions opt;
  const DiagnoseReport rep = diagnoseWithoutWorld(in, opt, "auto");
  std::cout << c.name << ": " << rep.scene_model << "\n  " << rep.obs.size() << " obs, "
            << rep.targets_used << " targets, sigma_r " << rep.sigma_r << " sigma_az "
            << rep.sigma_az << ", runtime " << rep.runtime_s << " s\n";
  for (const auto& cand : rep.candidates)
    std::cout << "  cand " << effectName(cand.effect) << " est " << cand.estimate << " +- "
              << cand.stddev << " z " << cand.z << " dBIC " << cand.delta_bic << "\n";
  for (const auto& e : rep.effects)
    std::cout << "  found " << e.name << " = " << e.value << " +- " << e.stddev << " (z "
              << e.significance << ") rms " << e.residual_rms_before << " -> "
              << e.residual_rms_after << "\n";
  for (const auto& n : rep.notes) std::cout << "  note: " << n << "\n";
  EXPECT_NE(rep.scene_model.find(std::string("auto: ") + c.split), std::string::npos);
  if (std::string(c.expect).empty()) {
    EXPECT_FALSE(rep.mismatch_found);
    return;
  }
  ASSERT_TRUE(rep.mismatch_found);
  const EffectResult& first = rep.effects.front();
  EXPECT_EQ(first.name, c.expect);
  EXPECT_NEAR(first.value, c.value, 0.15 * std::fabs(c.value));
  EXPECT_LT(rep.after.position_rms, rep.before.position_rms);
  // A second effect may only be a small linearisation remainder of a large first one: its
  // re-simulated residual drop must be under 5 % of the first's.
  const double first_drop = first.residual_rms_before - first.residual_rms_after;
  for (size_t i = 1; i < rep.effects.size(); ++i)
    EXPECT_LT(rep.effects[i].residual_rms_before - rep.effects[i].residual_rms_after,
              0.05 * first_drop)
        << rep.effects[i].name;
}

// clang-format off
INSTANTIATE_TEST_SUITE_P(Diagnose, NoWorld, ::testing::Values(
  // Out and back (auto split: outbound maps, return leg is diagnosed).
  Case{"doppler_outback", {{"doppler", 0.049}}, outBack(), 24, 81, "out-back", "doppler", 0.049},
  Case{"range_offset_outback", {{"range_offset", -0.3}}, outBack(), 24, 82, "out-back", "range_offset", -0.3},
  Case{"range_offset_small_outback", {{"range_offset", 0.08}}, outBack(), 24, 92, "out-back", "range_offset", 0.08},
  Case{"azimuth_offset_outback", {{"azimuth_offset", 0.0105}}, outBack(), 24, 85, "out-back", "azimuth_offset", 0.0105},
  Case{"azimuth_offset_neg_outback", {{"azimuth_offset", -0.0052}}, outBack(), 24, 95, "out-back", "azimuth_offset", -0.0052},
  Case{"latency_30ms_outback", {{"timestamp_offset", 0.03}}, outBack(), 24, 86, "out-back", "timestamp_offset", 0.03},
  Case{"latency_22ms_outback", {{"timestamp_offset", 0.022}}, outBack(), 24, 96, "out-back", "timestamp_offset", 0.022},
  Case{"motion_distortion_outback", {{"motion_distortion", true}}, outBack(), 24, 87, "out-back", "motion_distortion", 1.0},
  // Loop with turns both ways and a speed change (auto split: no reversal, early-late).
  Case{"doppler_loop", {{"doppler", 0.049}}, loop(), 16, 81, "early-late", "doppler", 0.049},
  Case{"range_offset_loop", {{"range_offset", -0.3}}, loop(), 16, 82, "early-late", "range_offset", -0.3},
  Case{"azimuth_offset_loop", {{"azimuth_offset", 0.0105}}, loop(), 16, 85, "early-late", "azimuth_offset", 0.0105},
  Case{"latency_loop", {{"timestamp_offset", 0.03}}, loop(), 16, 86, "early-late", "timestamp_offset", 0.03},
  Case{"motion_distortion_loop", {{"motion_distortion", true}}, loop(), 16, 87, "early-late", "motion_distortion", 1.0},
  // Recorded with the base model.
  Case{"null_outback_a", nlohmann::json::object(), outBack(), 24, 83, "out-back", "", 0},
  Case{"null_outback_b", nlohmann::json::object(), outBack(), 24, 86, "out-back", "", 0},
  Case{"null_outback_c", nlohmann::json::object(), outBack(), 24, 88, "out-back", "", 0},
  Case{"null_loop_a", nlohmann::json::object(), loop(), 16, 83, "early-late", "", 0},
  Case{"null_loop_b", nlohmann::json::object(), loop(), 16, 84, "early-late", "", 0},
  Case{"null_loop_c", nlohmann::json::object(), loop(), 16, 86, "early-late", "", 0},
  // Weak returns (noise floor 28 dB below the radar constant): peaks scatter from scan to scan.
  Case{"noisy_doppler", {{"doppler", 0.049}}, outBack(), 24, 181, "out-back", "doppler", 0.049, true},
  Case{"noisy_range_offset", {{"range_offset", -0.3}}, outBack(), 24, 182, "out-back", "range_offset", -0.3, true},
  Case{"noisy_azimuth_offset", {{"azimuth_offset", 0.008}}, outBack(), 24, 185, "out-back", "azimuth_offset", 0.008, true},
  Case{"noisy_latency_35ms", {{"timestamp_offset", 0.035}}, outBack(), 24, 186, "out-back", "timestamp_offset", 0.035, true},
  Case{"noisy_motion_distortion", {{"motion_distortion", true}}, outBack(), 24, 187, "out-back", "motion_distortion", 1.0, true},
  Case{"noisy_null_a", nlohmann::json::object(), outBack(), 24, 183, "out-back", "", 0, true},
  Case{"noisy_null_b", nlohmann::json::object(), loop(), 16, 184, "early-late", "", 0, true},
  Case{"noisy_null_c", nlohmann::json::object(), loop(), 16, 188, "early-late", "", 0, true},
  Case{"noisy_null_d", nlohmann::json::object(), outBack(), 24, 189, "out-back", "", 0, true}),
  [](const ::testing::TestParamInfo<Case>& i) { return std::string(i.param.name); });
// clang-format on

// A latency on a straight road at constant speed displaces map and test returns alike: the
// map cancels it, and the report must say so (and which split would reveal it) rather than
// only "no significant mismatch".
TEST(NoWorldConcealed, LatencyOnAStraightRoadIsReportedAsCancelledByTheMap) {
  const uint64_t seed = 191;
  const sim::World world = randomWorld(seed, 90, 55.0, false);
  const Drive straight{{{4.0, 8.0, 0.0}}, {-20, 3, 0.0}};
  const DiagnoseInput in = makeInput(
      world, straight, sim::PhysicsConfig::fromJson({{"timestamp_offset", 0.03}}), 14, seed);
  const DiagnoseReport rep = diagnoseWithoutWorld(in, {}, "auto");
  EXPECT_FALSE(rep.mismatch_found);
  bool said = false;
  for (const auto& n : rep.notes)
    said = said || (n.find("timestamp_offset: 100% of its signature is cancelled by the map") !=
                        std::string::npos &&
                    n.find("out-back") != std::string::npos);
  EXPECT_TRUE(said);
}

}  // namespace
