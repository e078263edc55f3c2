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
#include "spinradar/sim/simulator.hpp"

namespace spinradar::diagnose::scene_detail {

namespace {

// Share of a cell's own power over the floor that must remain unexplained for a new scatterer
// (the one-point scene's rule along azimuth, appearance_scene.cpp).
constexpr double kUnexplained = 0.3;

double dbToPower(double db) { return std::pow(10.0, db / 10.0); }

// Offset of a peak at 0 along a line of samples obs(k), k in [-reach, reach], within +-1 (a flat
// top of three equal counts is taken at either end): the
// shift of the model's response lmodel(i), its log at i/32 (i >= 0), that fits the samples within 13 dB of the peak best in
// log power (its level free), on a 1/32 grid. Not a parabola through three samples nor the
// midpoint of the half-power crossings: with the quantiser's 1 dB steps a point between bins
// reads 87 87 87, and a neighbour right at -3 dB moves a crossing by half a row; a point put 0.1
// row off leaves 45 % of its -8 dB neighbour row, which passed for a second return.
template <class F, class G>
double fitOffset(F obs, G lmodel, int reach) {
  const double peak = obs(0);
  std::vector<std::pair<int, double>> v;
  for (int k = -reach; k <= reach; ++k) {
    const double o = obs(k);
    if (o > 0.05 * peak) v.push_back({k, std::log(o)});
  }
  if (v.size() < 2) return 0.0;
  double best = 0.0, best_err = 1e300;
  for (int i = -32; i <= 32; ++i) {
    const double off = i / 32.0;
    double sum = 0, sum2 = 0;
    bool ok = true;
    for (const auto& [k, lo] : v) {
      const double lm = lmodel(std::abs(32 * k - i));  // log of the response at k - off
      if (!(lm > -13.8)) ok = false;  // 60 dB down: outside the model's response
      const double e = ok ? lo - lm : 0.0;
      sum += e;
      sum2 += e * e;
    }
    const double err = sum2 - sum * sum / double(v.size());
    if (ok && err < best_err - 1e-12) best_err = err, best = off;
  }
  return best;
}

// The model's two-way azimuth response in power at 1/kSub-row steps, 0..span rows, peak 1: one
// render of kSub equal strong targets a 1/kSub row apart in their rows' phase (45 deg apart in
// azimuth, noise 60 dB under them, no clutter), each read across its rows at its bin. Not the
// one-point scene's whole-row profile interpolated: a point 0.3 rows off a row is then put 2 dB
// off and its neighbours' shoulders passed for scatterers 15 dB down.
constexpr int kSub = 8;

double countPower(int c, const sim::SensorConfig& s) { return dbToPower(countToDb(c, s)); }

std::vector<double> fineBeam(const sim::SensorConfig& sensor) {
  sim::SensorConfig s = sensor;
  s.clutter_density = 0;
  s.noise_texture_db = 0;
  const int n = s.azimuths, span = 8;
  const double range = std::min(30.0, 0.5 * s.maxRange());
  const double want_db = std::min(s.noise_floor_db + 60.0, 0.9 * s.saturation / s.power_scale);
  sim::World w;
  std::vector<int> rows(kSub);
  for (int j = 0; j < kSub; ++j) {
    rows[size_t(j)] = (j * n) / kSub;
    const double phi = 2.0 * M_PI * (rows[size_t(j)] + double(j) / kSub) / n;
    w.targets.push_back(
        {range * std::cos(phi), -range * std::sin(phi), want_db - pointGainDb(range, s)});
  }
  const sim::Trajectory standing({{0.0, {}}, {2.0 / std::max(s.rotation_hz, 0.1), {}}});
  const PolarScan scan = sim::Simulator(w, standing, s, {}, 3).renderScan(0);
  // The targets' bin: the strongest at the first target's row.
  const uint8_t* r0 = scan.row(rows[0]);
  const int pb = int(std::max_element(r0, r0 + scan.bins) - r0);
  const double peak = countPower(r0[pb], s);
  std::vector<double> sum(size_t(span * kSub + 1), 0.0), cnt(sum.size(), 0.0);
  for (int j = 0; j < kSub; ++j)
    for (int d = -span; d <= span; ++d) {
      const double x = std::abs(d - double(j) / kSub);
      const int k = int(std::lround(x * kSub));
      if (k > span * kSub) continue;
      sum[size_t(k)] += countPower(scan.row((rows[size_t(j)] + d + n) % n)[pb], s) / peak;
      cnt[size_t(k)] += 1;
    }
  std::vector<double> t(sum.size(), 0.0);
  for (size_t k = 0; k < t.size(); ++k) {
    t[k] = cnt[k] > 0 ? std::min(sum[k] / cnt[k], 1.0) : 0.0;
    if (t[k] < 1e-3) {  // 30 dB down: the end of what the deconvolution takes off
      t.resize(k);
      break;
    }
  }
  t[0] = 1.0;
  return t;
}

// That table at a fractional row offset, log-linear between its 1/kSub steps, 0 beyond it.
double beamFine(const std::vector<double>& t, double x) {
  const double u = std::abs(x) * kSub;
  const size_t k = size_t(u);
  if (k + 1 >= t.size()) return k + 1 == t.size() && u == double(k) ? t[k] : 0.0;
  return std::exp(std::log(t[k]) + (u - double(k)) * (std::log(t[k + 1]) - std::log(t[k])));
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
  std::vector<double> power_of(256);  // count -> power, the quantiser inverted
  for (int c = 0; c < 256; ++c) power_of[size_t(c)] = dbToPower(countToDb(c, s));
  for (int r = 0; r < n; ++r) {
    if (src[size_t(r)] < 0) continue;
    const uint8_t* row = scan.row(src[size_t(r)]);
    for (int b = b0; b < nb; ++b) {
      const double p = power_of[row[b]] - floor_p[size_t(b)];
      const size_t i = size_t(r) * nb + b;
      res[i] = float(std::max(p, 0.0));
      if (p > thr[size_t(b)]) heap.push({res[i], int32_t(i)});
    }
  }
  obs = res;

  // The model's response: the beam read off a render (as the one-point scene), the range spread
  // from the model's formula at the scatterer's fraction of a bin.
  const std::vector<double> kern = fineBeam(s);
  const int span = int(std::ceil(double(kern.size() - 1) / kSub));
  const int half = std::min(s.range_psf_half_width,
                            int(std::ceil(s.range_psf_sigma_bins * std::sqrt(2 * std::log(1e5)))));
  std::vector<double> rk(size_t(2 * half + 1));
  // Log responses at 1/32 steps (the offsets' grid), -inf taken as -1e3.
  std::vector<double> lr_t(size_t(32 * (half + 1) + 1)), la_t(size_t(32 * (span + 1) + 1));
  for (size_t i = 0; i < lr_t.size(); ++i) lr_t[i] = std::log(std::max(rangePsf(s, i / 32.0), 1e-300));
  for (size_t i = 0; i < la_t.size(); ++i) {
    const double v = beamFine(kern, i / 32.0);
    la_t[i] = v > 0 ? std::log(v) : -1e3;
  }
  auto lr = [&](int i) { return size_t(i) < lr_t.size() ? lr_t[size_t(i)] : -1e3; };
  auto la = [&](int i) { return size_t(i) < la_t.size() ? la_t[size_t(i)] : -1e3; };
  std::vector<double> er_t(lr_t.size()), ea_t(la_t.size());
  for (size_t i = 0; i < lr_t.size(); ++i) er_t[i] = std::exp(lr_t[i]);
  for (size_t i = 0; i < la_t.size(); ++i) ea_t[i] = la_t[i] > -1e3 ? std::exp(la_t[i]) : 0.0;
  auto er = [&](int i) { return size_t(i) < er_t.size() ? er_t[size_t(i)] : 0.0; };
  auto ea = [&](int i) { return size_t(i) < ea_t.size() ? ea_t[size_t(i)] : 0.0; };
  const double step = 2.0 * M_PI / n;
  // A scatterer's response (power p at its cell's peak) added onto a map, at 1/32 offsets.
  auto addResponse = [&](std::vector<float>& map, int r, int b, int ib, int ir, double p) {
    for (int k = -half; k <= half; ++k) rk[size_t(k + half)] = er(std::abs(32 * k - ib));
    for (int d = -span; d <= span; ++d) {
      const int rr = (r + d + n) % n;
      const double a = ea(std::abs(32 * d - ir));
      if (src[size_t(rr)] < 0 || a <= 0) continue;
      float* out = &map[size_t(rr) * nb];
      const double pa = p * a;
      for (int k = std::max(-half, b0 - b); k <= std::min(half, nb - 1 - b); ++k)
        out[b + k] = float(out[b + k] + pa * rk[size_t(k + half)]);
    }
  };
  struct Taken {
    int r, b, ib, ir;  ///< cell, and the offsets from it in 1/32 bin and row
    double p;          ///< power at the response's peak, over the floor
  };
  std::vector<Taken> taken;
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
    const double db = fitOffset([&](int k) { return at(r, b + k); }, lr, 4);
    const double dr = fitOffset([&](int d) { return at(r + d, b); }, la, 2);
    // Offsets are 1/32 steps: the responses from the tables.
    const int ib = int(std::lround(32 * db)), ir = int(std::lround(32 * dr));
    const double p = now / (er(std::abs(ib)) * ea(std::abs(ir)));
    addResponse(res, r, b, ib, ir, -p);
    taken.push_back({r, b, ib, ir, p});
  }
  // Gain-1 CLEAN overshoots inside an extended return: the first scatterer takes the whole peak,
  // its neighbours' shares included, and the shoulders then add theirs (the bush of
  // test_appearance_clean.cpp came back 1 dB over its peak; Oxford's q90 5-9 counts over the
  // recording's at 10-100 m). The strengths are refined with the positions held: multiplicative
  // updates that bring the rendered response at each scatterer's own cell to the recording's
  // power there (non-negative; 4 passes).
  std::fill(res.begin(), res.end(), 0.f);  // from here: the scatterers' summed response
  for (int pass = 0; pass < 4 && !taken.empty(); ++pass) {
    for (const Taken& t : taken) addResponse(res, t.r, t.b, t.ib, t.ir, t.p);
    std::vector<double> ratio(taken.size());
    for (size_t k = 0; k < taken.size(); ++k) {
      const size_t c = size_t(taken[k].r) * nb + taken[k].b;
      ratio[k] = res[c] > 0 ? std::clamp(double(obs[c]) / res[c], 0.1, 10.0) : 1.0;
    }
    for (const Taken& t : taken) addResponse(res, t.r, t.b, t.ib, t.ir, -t.p);  // back to 0
    for (size_t k = 0; k < taken.size(); ++k) taken[k].p *= ratio[k];
  }
  sim::World w;
  for (const Taken& k : taken) {
    const double range = scan.rangeOfBin(k.b + k.ib / 32.0);
    const double phi = (k.r + k.ir / 32.0) * step;  // the rendered row grid (appearance_scene.cpp)
    sim::Target t;
    t.x = range * std::cos(phi);  // sensor frame: azimuth clockwise from forward
    t.y = -range * std::sin(phi);
    t.rcs = 10.0 * std::log10(k.p) - pointGainDb(range, s);
    w.targets.push_back(t);
  }
  return w;
}

}  // namespace spinradar::diagnose::scene_detail
