#pragma once
// One rotation of a spinning FMCW radar in polar form, as the sensor reports it.
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
    azimuths = n_azimuths;
    bins = n_bins;
    power.assign(static_cast<size_t>(n_azimuths) * n_bins, 0);
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

}  // namespace spinradar
