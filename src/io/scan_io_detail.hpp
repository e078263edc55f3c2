#pragma once
// Helpers shared by the scan loaders (private to src/core).
#include <string>

#include "spinradar/core/polar_scan.hpp"

namespace spinradar::detail {

/// Marks rows with all-zero metadata (missing) and rows repeating the previous valid row's
/// encoder (duplicated) as invalid, gives missing rows interpolated angles and stamps so that
/// geometry stays usable, and warns (does not throw) about stamps going backwards.
void markMissingAndDuplicates(PolarScan& scan, const std::string& name);

/// Parses the frame/stamp number in a file name stem ("1547131046353776.png" -> 1547131046353776).
/// Returns false when the stem is not all digits.
bool stemNumber(const std::string& path, long long& value);

}  // namespace spinradar::detail
