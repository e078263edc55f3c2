#pragma once
// Internals shared by timing.cpp (stamps), timing_findings.cpp (jitter, findings, advice) and
// timing_report.cpp (JSON and Markdown).
#include <cstdint>
#include <string>
#include <vector>

#include "spinradar/diagnose/timing.hpp"

namespace spinradar::diagnose::detail {

/// The valid rows of one scan: source row, azimuth index from the first valid row (rows of a
/// missing azimuth leave a gap), stamp in s relative to the first valid row's stamp.
struct ScanRows {
  int scan = 0;
  int per_rotation = 0;  ///< azimuths per rotation (from the median azimuth step)
  int64_t first_ns = 0;
  std::vector<int> row, index;
  std::vector<double> t;
};
std::vector<ScanRows> scanRows(const std::vector<PolarScan>& scans);

/// First azimuth index of the packet holding `index` (packets of `size` start at `phase`).
int packetFirst(int index, int size, int phase);

/// |z| of a chi^2 statistic (Wilson-Hilferty; does not underflow for huge statistics).
double chi2ToZ(double chi2, int dof);

/// Sub-nanosecond RMS is rounding of a perfect fit: print it as 0 (s -> us).
inline double usRms(double s) { return s < 1e-9 ? 0.0 : s * 1e6; }

/// "1 scan", "3 scans".
inline std::string scansWord(int k) { return std::to_string(k) + (k == 1 ? " scan" : " scans"); }

/// Findings from the stamp analysis (bursts, period variation), with their evidence.
void addStampFindings(TimingReport& t, const TimingOptions& opt);

}  // namespace spinradar::diagnose::detail
