// The own reference scene's scatterer strengths refined jointly in azimuth and range (tenth round,
// AppearanceOptions::scene_refine_passes; docs/diagnose_scene.md). recordingWorld places one
// scatterer per row's local maximum, strongest first, each on the blur of the ones taken before
// it only: the weaker rows placed later blur back onto the strong rows, and MulRan's strong
// returns rendered -27 / -29 dB at +-2 rows against the recording's -33 / -36 dB. Here the
// strengths are fitted together, positions held: non-negative least squares of the model's
// response (azimuth response x range spread) summed over the scatterers against the recording's
// power over the floor, on every cell within the response's span of each scatterer (cells
// under the floor count as 0; a row's local maxima are only 2 range sigmas apart, so their
// spreads overlap in range as the rows' do in azimuth), by multiplicative updates
// p *= (K^T y) / (K^T K p), which keep p >= 0 and never raise the misfit. Rows are read through `src` only, so the held-out rows stay unread.
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
  // Range: the model's spread out to 2.5 sigma (the local maxima of a row are 2 sigma apart, so
  // neighbouring returns' spreads overlap: the row-by-row rebuild stacked them in range too).
  const int rh = std::max(1, int(std::ceil(2.5 * s.range_psf_sigma_bins)));
  const int nr = 2 * span + 1, nk = 2 * rh + 1;
  auto power = [&](double c) { return std::pow(10.0, countToDb(c, s) / 10.0); };
  // The recording's power over its bin's floor (-1: no row to compare with, or off the scan).
  auto obs = [&](int r, int b) {
    if (src[size_t(r)] < 0 || b < 0 || b >= nb) return -1.0;
    return std::max(0.0, power(scan.row(src[size_t(r)])[b]) - power(floor_q[size_t(b)]));
  };
  auto wrap = [&](int r) { return (r % n + n) % n; };
  // Weights of each scatterer's response on its neighbourhood, and the recording there.
  std::vector<double> wgt(sc.size() * size_t(nr * nk)), y(wgt.size());
  for (size_t i = 0; i < sc.size(); ++i)
    for (int d = -span; d <= span; ++d)
      for (int k = -rh; k <= rh; ++k) {
        const size_t at = i * size_t(nr * nk) + size_t((d + span) * nk + k + rh);
        wgt[at] = beamAt(kern, d - sc[i].delta) * rangePsf(s, k - sc[i].bin_offset);
        y[at] = obs(wrap(sc[i].r + d), sc[i].b + k);
      }
  std::vector<double> acc(size_t(n) * nb, 0.0), next(sc.size());
  for (int pass = 0; pass < passes; ++pass) {
    std::fill(acc.begin(), acc.end(), 0.0);
    for (size_t i = 0; i < sc.size(); ++i)
      for (int d = -span; d <= span; ++d)
        for (int k = -rh; k <= rh; ++k) {
          const int b = sc[i].b + k;
          if (b < 0 || b >= nb) continue;
          acc[size_t(wrap(sc[i].r + d)) * nb + b] +=
              sc[i].p * wgt[i * size_t(nr * nk) + size_t((d + span) * nk + k + rh)];
        }
    for (size_t i = 0; i < sc.size(); ++i) {
      double num = 0, den = 0;
      for (int d = -span; d <= span; ++d)
        for (int k = -rh; k <= rh; ++k) {
          const size_t at = i * size_t(nr * nk) + size_t((d + span) * nk + k + rh);
          if (y[at] < 0 || wgt[at] <= 0) continue;
          num += wgt[at] * y[at];
          den += wgt[at] * acc[size_t(wrap(sc[i].r + d)) * nb + sc[i].b + k];
        }
      next[i] = den > 0 ? sc[i].p * num / den : sc[i].p;
    }
    for (size_t i = 0; i < sc.size(); ++i) sc[i].p = next[i];
  }
}

}  // namespace spinradar::diagnose::scene_detail
