// The own reference scene's scatterer strengths refined jointly along azimuth (tenth round,
// AppearanceOptions::scene_refine_passes; docs/diagnose_scene.md). recordingWorld places one
// scatterer per row's local maximum, strongest first, each on the blur of the ones taken before
// it only: the weaker rows placed later blur back onto the strong rows, and MulRan's strong
// returns rendered -27 / -29 dB at +-2 rows against the recording's -33 / -36 dB. Here the
// strengths are fitted together, positions held: non-negative least squares of the model's
// azimuth response summed over the scatterers against the recording's power over the floor, on
// every row within the response's span of each scatterer (rows without a return count as 0
// over the floor), by multiplicative updates p *= (K^T y) / (K^T K p), which keep p >= 0 and
// never raise the misfit. Rows are read through `src` only, so the held-out rows stay unread.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "appearance_scene_detail.hpp"

namespace spinradar::diagnose::scene_detail {

void refineAlongAzimuth(const PolarScan& scan, const sim::SensorConfig& s,
                        const std::vector<int>& src, const std::vector<int>& floor_q,
                        const std::vector<double>& kern, std::vector<SceneScatterer>& sc,
                        int passes) {
  if (passes <= 0 || sc.empty()) return;
  if (passes > 1000) throw std::invalid_argument("appearance scene: scene_refine_passes over 1000");
  const int n = scan.azimuths, nb = scan.bins;
  if (int(src.size()) != n || int(floor_q.size()) != nb)
    throw std::invalid_argument("appearance scene refinement: rows or bins do not match the scan");
  const int span = int(kern.size());  // one row more: a scatterer sits up to half a row off
  auto power = [&](double c) { return std::pow(10.0, countToDb(c, s) / 10.0); };
  // The recording's power over its bin's floor, the largest of the bin and its two neighbours
  // (a return drifts by a bin from row to row; the local maxima are 2 sigma apart in a row).
  auto obs = [&](int r, int b) {
    if (src[size_t(r)] < 0) return -1.0;  // no row to compare with
    double v = 0;
    for (int bb = std::max(0, b - 1); bb <= std::min(nb - 1, b + 1); ++bb)
      v = std::max(v, power(scan.row(src[size_t(r)])[bb]) - power(floor_q[size_t(bb)]));
    return v;
  };
  std::vector<std::vector<double>> y(sc.size());
  for (size_t i = 0; i < sc.size(); ++i)
    for (int d = -span; d <= span; ++d) y[i].push_back(obs(((sc[i].r + d) % n + n) % n, sc[i].b));
  std::vector<double> acc(size_t(n) * nb, 0.0);
  auto model = [&](int r, int b) {
    double v = 0;
    for (int bb = std::max(0, b - 1); bb <= std::min(nb - 1, b + 1); ++bb) v += acc[size_t(r) * nb + bb];
    return v;
  };
  for (int pass = 0; pass < passes; ++pass) {
    std::fill(acc.begin(), acc.end(), 0.0);
    for (const SceneScatterer& t : sc)
      for (int d = -span; d <= span; ++d)
        acc[size_t(((t.r + d) % n + n) % n) * nb + t.b] += t.p * beamAt(kern, d - t.delta);
    std::vector<double> next(sc.size());
    for (size_t i = 0; i < sc.size(); ++i) {
      double num = 0, den = 0;
      for (int d = -span; d <= span; ++d) {
        const double yi = y[i][size_t(d + span)], k = beamAt(kern, d - sc[i].delta);
        if (yi < 0 || k <= 0) continue;
        num += k * yi;
        den += k * model(((sc[i].r + d) % n + n) % n, sc[i].b);
      }
      next[i] = den > 0 ? sc[i].p * num / den : sc[i].p;
    }
    for (size_t i = 0; i < sc.size(); ++i) sc[i].p = next[i];
  }
}

}  // namespace spinradar::diagnose::scene_detail
