#include <gtest/gtest.h>

#include <type_traits>

#include "spinradar/core/params.hpp"

using namespace spinradar;

TEST(Params, DefaultsAreValid) { EXPECT_NO_THROW(PipelineConfig{}.validate()); }

TEST(Params, OutOfRangeIsRejectedWithItsName) {
  PipelineConfig c;
  c.detector.zq = -1.0;
  try {
    c.validate();
    FAIL() << "expected invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("zq"), std::string::npos) << e.what();
  }
  c.detector.zq = 3.0;
  c.estimator.estimator = "icp";
  EXPECT_THROW(c.validate(), std::invalid_argument);
}

TEST(Params, VisitSeesEveryParameterOnce) {
  PipelineConfig c;
  int n = 0;
  bool saw_beta = false;
  c.visit([&](const ParamMeta& m, auto&) {
    ++n;
    saw_beta |= std::string(m.name) == "beta";
  });
  EXPECT_TRUE(saw_beta);
  EXPECT_GT(n, 15);
}

TEST(Params, AzimuthPeaksIsADetectorParameterOnByDefault) {
  // On by default (the evaluation matrix, README); off reproduces the paper's front end (one
  // keypoint per azimuth row).
  PipelineConfig c;
  EXPECT_TRUE(c.detector.azimuth_peaks);
  int seen = 0;
  c.detector.visit([&](const ParamMeta& m, auto& v) {
    if (std::string(m.name) != "azimuth_peaks") return;
    ++seen;
    if constexpr (std::is_same_v<std::decay_t<decltype(v)>, bool>) v = false;
  });
  EXPECT_EQ(seen, 1);
  EXPECT_FALSE(c.detector.azimuth_peaks);
  EXPECT_NO_THROW(c.validate());
}
