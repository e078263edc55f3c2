#pragma once
// Synthetic polar scans with known targets for the feature tests (detector, Cartesian, extractor).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "spinradar/core/polar_scan.hpp"

namespace spinradar::test {

struct Target {
  double azimuth;  ///< rad, clockwise (sensor convention)
  double range;    ///< m
  double snr_db;   ///< peak power above the noise floor
};

/// Navtech-like scan: log-power (1 count / dB) of exponential speckle over a floor, plus point
/// targets spread over about one range bin and one azimuth step (the beam), added in linear power.
inline PolarScan syntheticScan(const std::vector<Target>& targets, unsigned seed = 1, int azimuths = 400,
                               int bins = 3768, double resolution = 0.0438, double floor_db = 30.0,
                               int64_t t0_ns = 1'000'000'000'000LL) {
  PolarScan s;
  s.resize(azimuths, bins);
  s.range_resolution = resolution;
  std::mt19937 rng(seed);
  std::exponential_distribution<double> speckle(1.0);
  const int step = 5600 / azimuths;
  for (int a = 0; a < azimuths; ++a) {
    s.encoder[a] = static_cast<uint16_t>(a * step);
    s.azimuth[a] = 2.0 * M_PI * s.encoder[a] / 5600.0;
    s.stamp_ns[a] = t0_ns + int64_t(a) * 625000;
  }
  std::vector<double> lin(size_t(azimuths) * bins);
  for (auto& v : lin) v = std::pow(10.0, floor_db / 10.0) * speckle(rng);
  const double daz = 2.0 * M_PI / azimuths;
  for (const auto& t : targets) {
    const double amp = std::pow(10.0, (floor_db + t.snr_db) / 10.0);
    const double b = s.binOfRange(t.range);
    for (int a = 0; a < azimuths; ++a) {
      double da = std::remainder(s.azimuth[a] - t.azimuth, 2.0 * M_PI) / daz;
      if (std::abs(da) > 4) continue;
      const double ga = std::exp(-0.5 * da * da / (0.8 * 0.8));
      for (int j = std::max(0, int(b) - 6); j <= std::min(bins - 1, int(b) + 6); ++j) {
        const double db = j - b;
        lin[size_t(a) * bins + j] += amp * ga * std::exp(-0.5 * db * db);
      }
    }
  }
  for (size_t i = 0; i < lin.size(); ++i)
    s.power[i] = static_cast<uint8_t>(std::clamp(std::lround(10.0 * std::log10(lin[i])), 0L, 255L));
  return s;
}

}  // namespace spinradar::test
