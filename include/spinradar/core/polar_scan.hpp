#pragma once
// One rotation of a spinning FMCW radar in polar form, as the sensor reports it.
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace spinradar {

/// N azimuths x M range bins of power. Row-major: power[a * bins + b].
/// Angles are clockwise from forward (the sensor's own convention); a return at
/// (r, phi) lies at (r cos phi, -r sin phi) in the REP 103 sensor frame (x fwd, y left).
struct PolarScan {
  int azimuths = 0;                 ///< rows
  int bins = 0;                     ///< range bins per azimuth
  double range_resolution = 0.0438; ///< metres per bin
  double range_offset = 0.0;        ///< metres added to every range (Boreas: -0.31)
  int encoder_size = 5600;          ///< encoder counts per rotation
  std::vector<uint8_t> power;       ///< azimuths * bins, native log power (~1 dB / count)
  std::vector<double> azimuth;      ///< rad, clockwise from forward, per row
  std::vector<int64_t> stamp_ns;    ///< acquisition time of each row, ns (UNIX or sim clock)
  std::vector<uint16_t> encoder;    ///< raw encoder value per row
  std::vector<uint8_t> valid;       ///< 1 = row holds data, 0 = missing/duplicated row
  std::vector<uint8_t> chirp_up;    ///< optional per-row chirp direction (Boreas-RT); empty = unknown

  void resize(int n_azimuths, int n_bins) {
    resizeForOverwrite(n_azimuths, n_bins);
    std::fill(power.begin(), power.end(), uint8_t{0});
  }
  /// resize() without zeroing the power values, for readers that write every row over them
  /// (a 1.5 MB fill per Oxford scan saved); the per-azimuth fields are reset as by resize().
  void resizeForOverwrite(int n_azimuths, int n_bins) {
    azimuths = n_azimuths;
    bins = n_bins;
    power.resize(static_cast<size_t>(n_azimuths) * n_bins);
    azimuth.assign(n_azimuths, 0.0);
    stamp_ns.assign(n_azimuths, 0);
    encoder.assign(n_azimuths, 0);
    valid.assign(n_azimuths, 1);
  }
  uint8_t* row(int a) { return power.data() + static_cast<size_t>(a) * bins; }
  const uint8_t* row(int a) const { return power.data() + static_cast<size_t>(a) * bins; }
  /// Range of the centre of bin b (Oxford SDK convention: (b + 0.5) * resolution).
  double rangeOfBin(double b) const { return (b + 0.5) * range_resolution + range_offset; }
  /// Fractional bin index whose centre is at range r.
  double binOfRange(double r) const { return (r - range_offset) / range_resolution - 0.5; }
  int64_t firstStamp() const { return stamp_ns.empty() ? 0 : stamp_ns.front(); }
  int64_t lastStamp() const { return stamp_ns.empty() ? 0 : stamp_ns.back(); }
  bool empty() const { return azimuths == 0 || bins == 0; }
};

/// The sensor's rotation period (ns) told by a scan's own row stamps: the least-squares stamp
/// step per row over the valid rows, times the rows of one rotation (`azimuths`). A line, not
/// the first-to-last span: Oxford and MulRan stamps are packet arrival times, in bursts. This,
/// not the stamp step to the previous scan, is the period: after a dropped scan, or on a
/// recording read every other scan, the step is two periods (issue 19). 0 when it cannot be
/// told (fewer than two valid rows, or stamps not increasing).
inline int64_t rotationPeriodNs(const PolarScan& scan) {
  const int n = static_cast<int>(scan.stamp_ns.size());
  const bool flags = scan.valid.size() == scan.stamp_ns.size();
  if (n < 2 || scan.azimuths < 2) return 0;
  const int64_t t0 = scan.stamp_ns.front();
  double sw = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (int a = 0; a < n; ++a) {
    if (flags && !scan.valid[a]) continue;
    const double x = a, y = static_cast<double>(scan.stamp_ns[a] - t0);
    sw += 1; sx += x; sy += y; sxx += x * x; sxy += x * y;
  }
  const double den = sw * sxx - sx * sx;
  if (sw < 2 || !(den > 0)) return 0;
  const double per_row = (sw * sxy - sx * sy) / den;
  const double period = per_row * scan.azimuths;
  return period > 0 && period < 9.2e18 ? static_cast<int64_t>(period + 0.5) : 0;
}

}  // namespace spinradar
