#include <gtest/gtest.h>

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
