#include "spinradar/core/params.hpp"

#include <stdexcept>

#include "spinradar/core/param_check.hpp"

namespace spinradar {

void DetectorConfig::validate() const {
  checkParamRanges(*this, "detector");
  checkOneOf(detector, {"cen2018", "cfar"}, "detector");
  if (min_range >= max_range)
    throw std::invalid_argument("parameter 'min_range' must be smaller than 'max_range'");
}

void FeatureConfig::validate() const {
  checkParamRanges(*this, "features");
  if (orb_patch_size % 2 == 0)
    throw std::invalid_argument("parameter 'orb_patch_size' must be odd");
}

void EstimatorConfig::validate() const {
  checkParamRanges(*this, "estimator");
  checkOneOf(estimator, {"rigid", "mc", "mc_doppler", "refined", "keyframe", "surface"}, "estimator");
  checkOneOf(azimuth_times, {"stamps", "uniform"}, "azimuth_times");
}

}  // namespace spinradar
