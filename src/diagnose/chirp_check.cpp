// The in-scan Doppler check that `spinradar diagnose` runs on recordings whose chirps alternate
// (estimateChirpDoppler per scan, summarised over the recording).
#include <algorithm>

#include "spinradar/diagnose/chirp_doppler.hpp"

namespace spinradar::diagnose {
namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

bool hasAlternatingChirps(const PolarScan& scan) {
  const auto& up = scan.chirp_up;
  if (up.size() < 8 || up.size() != size_t(scan.azimuths)) return false;
  int pairs = 0, flips = 0;
  for (size_t i = 1; i < up.size(); ++i) {
    if (scan.valid.size() == up.size() && (!scan.valid[i] || !scan.valid[i - 1])) continue;
    ++pairs;
    flips += (up[i] != 0) != (up[i - 1] != 0);
  }
  return pairs > 0 && flips >= 0.9 * pairs;  // a dropped row may break the pattern once
}

nlohmann::json chirpDopplerSummary(const std::vector<PolarScan>& scans,
                                   const ChirpDopplerOptions& options) {
  nlohmann::json per_scan = nlohmann::json::array();
  std::vector<double> beta_v, speed;
  int detected = 0;
  for (size_t k = 0; k < scans.size(); ++k) {
    if (!hasAlternatingChirps(scans[k])) continue;
    const ChirpDopplerResult r = estimateChirpDoppler(scans[k], options);
    nlohmann::json j = r.toJson();
    j["scan"] = static_cast<int>(k);
    per_scan.push_back(std::move(j));
    detected += r.detected;
    beta_v.push_back(r.beta_v);
    if (r.speed) speed.push_back(*r.speed);
  }
  if (per_scan.empty()) return nullptr;
  nlohmann::json s = {{"scans_with_alternating_chirps", static_cast<int>(per_scan.size())},
                      {"scans_detected", detected},
                      {"median_beta_v_m", median(beta_v)},
                      {"per_scan", per_scan}};
  if (options.beta) {
    s["beta_given_s"] = *options.beta;
    s["median_speed_mps"] = median(speed);
  }
  return s;
}

}  // namespace spinradar::diagnose
