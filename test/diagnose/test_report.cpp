// The report files: report.json with the documented fields, the summary and the PNG plots.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "diagnose/diagnose_fixtures.hpp"

using namespace spinradar;
using namespace spinradar::diagnose;
using namespace spinradar::diagnose::testing;
namespace fs = std::filesystem;

TEST(Report, WritesJsonSummaryAndPlots) {
  const sim::World world = randomWorld(71, 90, 55.0, true);
  const Drive drive{{{1.0, 6.0, 0.0}, {1.0, 6.0, 0.3}}, {0, 0, 0.0}};
  sim::PhysicsConfig hidden;
  hidden.range_offset = -0.2;
  const DiagnoseReport rep =
      spinradar::diagnose::diagnose(makeInput(world, drive, hidden, 4, 71));
  const fs::path out = fs::temp_directory_path() / "spinradar_test_diagnose_report";
  fs::remove_all(out);
  writeReport(rep, out.string());
  for (const char* f : {"report.json", "summary.md", "summary.txt", "residuals.png", "locate.png",
                        "fitted_physics.json"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  std::ifstream in(out / "report.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_TRUE(j.at("mismatch_found").get<bool>());
  ASSERT_EQ(j.at("effects").size(), 1u);
  const auto& e = j["effects"][0];
  EXPECT_EQ(e.at("name"), "range_offset");
  for (const char* k : {"parameter", "value", "stddev", "significance", "residual_rms_before",
                        "residual_rms_after", "absorbed_fraction"})
    EXPECT_TRUE(e.contains(k)) << k;
  EXPECT_NEAR(e["value"].get<double>(), -0.2, 0.02);
  EXPECT_LT(j.at("residual_rms_after").get<double>(), j.at("residual_rms_before").get<double>());
  EXPECT_FALSE(j.at("locate").empty());
  EXPECT_EQ(sim::PhysicsConfig::load((out / "fitted_physics.json").string()).activeEffects(),
            std::vector<std::string>{"range_offset"});
  fs::remove_all(out);
}
