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
/// Returns false when the stem is not all digits; throws std::runtime_error naming the file when
/// it is all digits but too large for 64 bits.
bool stemNumber(const std::string& path, long long& value);

/// Limits of a plausible scan: a full rotation has tens to thousands of azimuths (Navtech: 400)
/// and range bins.
constexpr int kMinAzimuths = 16, kMaxAzimuths = 20000;
constexpr int kMinBins = 16, kMaxBins = 65536;

/// Throws std::runtime_error "<name>: <n> azimuths (<what>) ..." when the shape is implausible
/// for `format` (e.g. a file cut short to one row, or a transposed layout read the wrong way).
void checkScanShape(int azimuths, int bins, const std::string& name, const char* format,
                    const char* azimuth_what, const char* bin_what);

}  // namespace spinradar::detail
