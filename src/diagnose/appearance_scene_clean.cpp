// The recording's own reference scene by deconvolution (issue 20, AppearanceOptions::scene_clean).
// The one-point scene (appearance_scene.cpp, scene_clean off) turns each return standing out of
// its range bin's floor into one scatterer per local maximum along the row, so an extended or
// diffuse return (a wall spanning many bins, a bush) comes back with the model's point width:
// Boreas-RT's returns have a median -3 dB range width of 8 bins against the model's 6.1, and the
// re-simulated scan gave 2.3x its CA-CFAR cells at 50-100 m. Here the scene is taken by CLEAN
// (Hoegbom): in the scan's power over the floor, the strongest remaining cell becomes a
// scatterer, placed between bins and rows (parabola through the log powers), with the strength
// whose response is that cell's power; its response through the model (range point spread x the
// model's azimuth response, read off a render) is taken off the whole neighbourhood; repeat
// until no cell stands the margin over its bin's floor. A return wider than the model's response
// leaves shoulders that become scatterers of their own, so the re-simulated scan reproduces its
// width and texture. A cell whose remaining power is mostly (70 %) what the scatterers taken so
// far explain is left as explained: the quantiser (1 dB steps, 26 % in power) and speckle give
// such residuals around every strong return, and they are not returns.
#include <algorithm>
#include <cmath>
#include <queue>
#include <stdexcept>
#include <utility>

#include "appearance_scene_detail.hpp"

namespace spinradar::diagnose::scene_detail {

namespace {

// Share of a cell's own power over the floor that must remain unexplained for a new scatterer
// (the one-point scene's rule along azimuth, appearance_scene.cpp).
constexpr double kUnexplained = 0.3;

double dbToPower(double db) { return std::pow(10.0, db / 10.0); }

// Offset of a peak at 0 along a line of samples f(k), k in [-lim, lim]: the midpoint of its
// half-power crossings (log-linear between samples), within +-1. Not a parabola through three
// samples: the quantiser's flat tops (1 count = 1 dB, so a point between bins reads 87 87 87)
// put that off by half a bin, and a point misplaced by half a bin leaves a shoulder 4-5 bins out
// that passed for a second return 10 dB down.
template <class F>
double centre(F f, double peak, int lim) {
  auto edge = [&](int dir) {
    double prev = peak;
    for (int k = 1; k <= lim; ++k) {
      const double v = f(dir * k);
      if (v < 0.5 * peak) {
        const double t = v > 0 ? std::log(prev / (0.5 * peak)) / std::log(prev / v)
                               : (prev - 0.5 * peak) / (prev - v);
        return dir * (k - 1 + t);
      }
      prev = std::max(v, 1e-30);
    }
    return double(dir * lim);
  };
  return std::clamp(0.5 * (edge(-1) + edge(1)), -1.0, 1.0);
}

}  // namespace

double rangePsf(const sim::SensorConfig& s, double x) {
  // render_model.cpp: exp(-x^2/2) in units of sigma, plus window sidelobes flat to 2 sigma and
  // decaying as offset^-3 beyond; the peak is 1 + sidelobe level.
  const double u = std::abs(x) / s.range_psf_sigma_bins;
  const double sl = dbToPower(s.range_sidelobe_db);
  const double side = u > 2.0 ? sl * std::pow(2.0 / u, 3.0) : sl;
  return (std::exp(-0.5 * u * u) + side) / (1.0 + sl);
}

sim::World cleanWorld(const PolarScan& scan, const sim::SensorConfig& s,
                      const std::vector<int>& src, const std::vector<int>& floor_q, double per_db,
                      const AppearanceOptions& opt) {
  const int n = scan.azimuths, nb = scan.bins;
  if (int(src.size()) != n || int(floor_q.size()) != nb || !(per_db > 0))
    throw std::invalid_argument("appearance recording scene (CLEAN): rows, bins or counts/dB "
                                "do not match the scan");
  const int b0 = std::max(0, int(std::ceil(scan.binOfRange(2.5))));
  // Power over each bin's floor (linear, the model's quantiser inverted), and the margin a cell
  // must stand over its bin's floor to be a return.
  std::vector<double> floor_p(static_cast<size_t>(nb)), thr(static_cast<size_t>(nb));
  for (int b = 0; b < nb; ++b) {
    floor_p[size_t(b)] = dbToPower(countToDb(floor_q[size_t(b)], s));
    thr[size_t(b)] =
        dbToPower(countToDb(floor_q[size_t(b)] + opt.scene_margin_db * per_db, s)) -
        floor_p[size_t(b)];
  }
  std::vector<float> res(size_t(n) * nb, 0.f), obs;
  using Cell = std::pair<float, int32_t>;  // remaining power, cell index
  std::priority_queue<Cell> heap;
  for (int r = 0; r < n; ++r) {
    if (src[size_t(r)] < 0) continue;
    const uint8_t* row = scan.row(src[size_t(r)]);
    for (int b = b0; b < nb; ++b) {
      const double p = dbToPower(countToDb(row[b], s)) - floor_p[size_t(b)];
      const size_t i = size_t(r) * nb + b;
      res[i] = float(std::max(p, 0.0));
      if (p > thr[size_t(b)]) heap.push({res[i], int32_t(i)});
    }
  }
  obs = res;

  // The model's response: the beam read off a render (as the one-point scene), the range spread
  // from the model's formula at the scatterer's fraction of a bin.
  const std::vector<double> kern = beamProfile(s);
  const int span = int(kern.size()) - 1;
  const int half = std::min(s.range_psf_half_width,
                            int(std::ceil(s.range_psf_sigma_bins * std::sqrt(2 * std::log(1e5)))));
  std::vector<double> rk(size_t(2 * half + 1)), ak(size_t(2 * span + 1));
  const double step = 2.0 * M_PI / n;
  sim::World w;
  while (!heap.empty()) {
    const auto [v, i] = heap.top();
    heap.pop();
    const int r = i / nb, b = i % nb;
    const float now = res[size_t(i)];
    const bool eligible = now > thr[size_t(b)] && now > kUnexplained * obs[size_t(i)];
    if (now < v) {  // taken down since it was queued: back in with its remaining power
      if (eligible) heap.push({now, i});
      continue;
    }
    if (!eligible) continue;
    auto at = [&](int rr, int bb) {
      if (bb < b0 || bb >= nb) return 0.0;
      return double(res[size_t((rr + n) % n) * nb + bb]);
    };
    const double db = centre([&](int k) { return at(r, b + k); }, now, half);
    const double dr = centre([&](int d) { return at(r + d, b); }, now, span);
    for (int k = -half; k <= half; ++k) rk[size_t(k + half)] = rangePsf(s, k - db);
    for (int d = -span; d <= span; ++d) ak[size_t(d + span)] = beamAt(kern, d - dr);
    const double p = now / (rk[size_t(half)] * ak[size_t(span)]);
    for (int d = -span; d <= span; ++d) {
      const int rr = (r + d + n) % n;
      if (src[size_t(rr)] < 0 || ak[size_t(d + span)] <= 0) continue;
      float* out = &res[size_t(rr) * nb];
      const double pa = p * ak[size_t(d + span)];
      for (int k = std::max(-half, b0 - b); k <= std::min(half, nb - 1 - b); ++k)
        out[b + k] = float(out[b + k] - pa * rk[size_t(k + half)]);
    }
    const double range = scan.rangeOfBin(b + db), phi = scan.azimuth[size_t(r)] + dr * step;
    sim::Target t;
    t.x = range * std::cos(phi);  // sensor frame: azimuth clockwise from forward
    t.y = -range * std::sin(phi);
    t.rcs = 10.0 * std::log10(p) - pointGainDb(range, s);
    w.targets.push_back(t);
  }
  return w;
}

}  // namespace spinradar::diagnose::scene_detail
