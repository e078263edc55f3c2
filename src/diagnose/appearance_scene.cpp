// Reference scene of the appearance stage taken from the recording itself (issue 20,
// AppearanceOptions::scene = "recording"). The built-in city scene has other content than a real
// street (45 % of its rows have a strong hit within 10 m, Oxford 23 %), and row-wise figures such
// as Cen2018's keypoints measure that content, not the sensor (docs/diagnose_cen2018.md). Here
// each recorded scan of the FIT part becomes a world of point scatterers in the sensor frame,
// one per compact return (a local maximum standing well above its range bin's median), with the
// strength that the sensor model under test needs to give that count: the count is decoded
// through the model's quantiser and the real floor's power removed, then the model's range gain
// chain is divided out. The scene is re-derived for every sensor the fit tries, so the returns'
// absolute gain and range gain are carried by the scene (not identifiable from one recording
// without known targets), while everything that is not a compact return, the noise floor, its
// texture, weak clutter, the blur widths, is left for the sensor to explain.
#include <algorithm>
#include <array>
#include <cstdint>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <stdexcept>

#include "appearance_detail.hpp"
#include "appearance_scene_detail.hpp"
#include "spinradar/diagnose/appearance.hpp"
#include "spinradar/sim/simulator.hpp"

namespace spinradar::diagnose {

using sim::SensorConfig;

namespace scene_detail {

// Count -> received power in dB, the inverse of the quantiser (render_model.cpp): counts are
// power_scale per dB, compressed above the knee by compression_ratio.
double countToDb(double c, const SensorConfig& s) {
  if (c > s.compression_knee) c = s.compression_knee + (c - s.compression_knee) / s.compression_ratio;
  return c / s.power_scale;
}

// Gain chain of a 0 dBsm point return at range r (RenderModel::pointPower without the near STC,
// which only acts inside the 2.5 m the scene leaves out).
double pointGainDb(double r, const SensorConfig& s) {
  const double lr = std::log10(std::max(r, 0.1));
  return s.radar_constant_db - 40.0 * lr + s.range_gain_db_per_decade * lr + s.stcCurveDb(r) +
         s.returnGainDb(r);
}

// The rows the scene is taken from. A masked scan (one-scan recording: quarters 0 and 2 fit)
// lends each missing row the fit row a quarter turn away, so the held-out rows are never read.
std::vector<int> sourceRows(const PolarScan& scan) {
  const int n = scan.azimuths, q = std::max(n / 4, 1);
  std::vector<int> src(n, -1);
  auto ok = [&](int r) { return scan.valid.empty() || scan.valid[r]; };
  for (int r = 0; r < n; ++r) {
    if (ok(r)) src[r] = r;
    else if (ok((r + n - q) % n)) src[r] = (r + n - q) % n;
    else if (ok((r + q) % n)) src[r] = (r + q) % n;
  }
  return src;
}

// The model's two-way azimuth response in power, relative to the peak, at 0..span rows: one
// strong target rendered by the model from a standing sensor (noise 40 dB under it, no
// clutter), the profile across rows at the target's bin. Read off the render rather than a
// formula: it holds the beam shape and the smear of the rotation during a row alike.
std::vector<double> beamProfile(const SensorConfig& sensor) {
  SensorConfig s = sensor;
  s.clutter_density = 0;
  s.noise_texture_db = 0;
  const double range = std::min(30.0, 0.5 * s.maxRange());
  const int probe = s.azimuths / 4;
  const double phi = 2.0 * M_PI * probe / s.azimuths;
  sim::World w;
  // As strong as the quantiser allows 40 dB over the noise: rcs from the model's gain chain.
  const double want_db = std::min(s.noise_floor_db + 60.0, 0.9 * s.saturation / s.power_scale);
  w.targets.push_back({range * std::cos(phi), -range * std::sin(phi), want_db - pointGainDb(range, s)});
  const sim::Trajectory standing({{0.0, {}}, {2.0 / std::max(s.rotation_hz, 0.1), {}}});
  const PolarScan scan = sim::Simulator(w, standing, s, {}, 3).renderScan(0);
  int pr = 0, pb = 0;
  for (int r = 0; r < scan.azimuths; ++r)
    for (int b = 0; b < scan.bins; ++b)
      if (scan.row(r)[b] > scan.row(pr)[pb]) pr = r, pb = b;
  const double peak = std::pow(10.0, countToDb(scan.row(pr)[pb], s) / 10.0);
  std::vector<double> k{1.0};
  for (int d = 1; d <= 8; ++d) {
    double v = 0;  // both sides, the mean: the row grid need not be centred on the target
    for (const int r : {(pr + d) % scan.azimuths, (pr - d + scan.azimuths) % scan.azimuths})
      v += 0.5 * std::pow(10.0, countToDb(scan.row(r)[pb], s) / 10.0) / peak;
    if (v < 1e-3) break;  // 30 dB down: below what a 4-sweep deconvolution resolves
    k.push_back(std::min(v, 1.0));
  }
  return k;
}

double beamAt(const std::vector<double>& kern, double x) {
  const int span = int(kern.size()) - 1;
  x = std::abs(x);
  const int d = int(x);
  if (d >= span) return d == span && x == span ? kern[size_t(span)] : 0.0;
  return std::exp(std::log(kern[size_t(d)]) +
                  (x - d) * (std::log(kern[size_t(d) + 1]) - std::log(kern[size_t(d)])));
}

}  // namespace scene_detail

using namespace scene_detail;

sim::World recordingWorld(const PolarScan& scan, const SensorConfig& s,
                          const AppearanceOptions& opt) {
  if (scan.empty() || scan.power.size() != size_t(scan.azimuths) * scan.bins ||
      scan.azimuth.size() != size_t(scan.azimuths))
    throw std::invalid_argument("appearance recording scene: malformed scan (rows, bins or azimuths)");
  if (!(opt.scene_margin_db > 0 && opt.scene_margin_db < 60))
    throw std::invalid_argument("appearance recording scene: scene_margin_db must be in (0, 60)");
  const int n = scan.azimuths, nb = scan.bins;
  const std::vector<int> src = sourceRows(scan);
  auto at = [&](int r, int b) { return int(scan.row(src[r])[b]); };

  // The real floor per range bin: the upper quartile of the counts over the rows (a count
  // histogram per bin). Not the median: with a low noise floor most counts are the quantiser's
  // code 0 and the median says nothing of the speckle's spread; the upper quartile of
  // exponential speckle is 3 dB over its median, and still a floor while fewer than a quarter
  // of the rows see a return in that bin.
  std::vector<int> floor_q(nb, 0), iqr(nb, 0);
  std::array<int, 256> hist{};
  std::array<bool, 31> seen{};  // codes 1-30 that occur: 19 in a native product, all rescaled
  int rows = 0;
  for (int r = 0; r < n; ++r) rows += src[r] >= 0;
  if (rows == 0) return {};
  for (int b = 0; b < nb; ++b) {
    hist.fill(0);
    for (int r = 0; r < n; ++r)
      if (src[r] >= 0) ++hist[at(r, b)];
    for (int c = 1; c <= 30; ++c) seen[size_t(c)] = seen[size_t(c)] || hist[size_t(c)] > 0;
    int acc = 0, c = 0, q1 = -1;
    for (; c < 255 && acc * 4 < 3 * rows; ++c) {
      acc += hist[c];
      if (q1 < 0 && acc * 4 >= rows) q1 = c;
      if (acc * 4 >= 3 * rows) break;
    }
    floor_q[b] = c;
    iqr[b] = c - std::max(q1, 0);
  }
  // Counts per dB for the margin: the model's, or, in a rescaled product (every code among
  // 1-30, as the code-set fit tests it), the recording's own where its speckle is wider
  // (RADIATE has 2.4 counts/dB against the base model's 1 before its code-set fit).
  // Exponential speckle spans 6.8 dB between its quartiles; the median over the bins keeps the
  // returns out (bins that are all code 0 give 0 and fall back to the model). Not in a native
  // product: there the spread over the rows of a bin is the scene's (walls in some rows, open
  // road in others: a median of 14-15 counts on Oxford, MulRan and Boreas-RT, native 1 count
  // per dB), and it raised the margin to 21-22 dB, leaving most returns to noise and clutter.
  int distinct = 0;
  for (int c = 1; c <= 30; ++c) distinct += seen[size_t(c)];
  std::vector<int> spread = iqr;
  std::nth_element(spread.begin(), spread.begin() + nb / 2, spread.end());
  const double per_db =
      distinct >= 27 ? std::max(s.power_scale, spread[size_t(nb / 2)] / 6.8) : s.power_scale;
  if (opt.scene_clean) {  // deconvolution in range and azimuth (appearance_scene_clean.cpp)
    sim::World w = cleanWorld(scan, s, src, floor_q, per_db, opt);
    if (std::getenv("SPINRADAR_APPEARANCE_VERBOSE"))
      std::cerr << "recording scene (CLEAN): codes 1-30 " << distinct << ", counts/dB " << per_db
                << ", scatterers " << w.targets.size() << "\n";
    return w;
  }

  // A return is a local maximum along its row within the range mainlobe (2 sigma either side).
  // Along azimuth every row keeps its own: an extended object (a wall, a car) spans rows, and
  // one scatterer per blob would render it narrower, a spurious wide beam in the fit.
  const int wb = std::max(1, int(std::ceil(2 * s.range_psf_sigma_bins)));
  // Margin per bin: scene_margin_db, or the band's own (scene_margin_bands_db: 2.5-10, 10-25,
  // 25-50, 50 m and on).
  const std::vector<double>& mb = opt.scene_margin_bands_db;
  if (!mb.empty() && mb.size() != 4)
    throw std::invalid_argument("appearance recording scene: scene_margin_bands_db needs 4 values");
  for (const double m : mb)
    if (!(m > 0 && m < 60))
      throw std::invalid_argument("appearance recording scene: each band margin must be in (0, 60) dB");
  std::vector<double> margin_at(size_t(nb), opt.scene_margin_db * per_db);
  if (!mb.empty())
    for (int b = 0; b < nb; ++b) {
      const double r = scan.rangeOfBin(b);
      margin_at[size_t(b)] = per_db * mb[r < 10 ? 0 : r < 25 ? 1 : r < 50 ? 2 : 3];
    }
  const int b0 = std::max(0, int(std::ceil(scan.binOfRange(2.5))));
  struct Peak {
    int r, b;
    double obs, p;  ///< power over the floor (linear), and the same with the beam removed
  };
  std::vector<Peak> peaks;
  std::vector<int32_t> index(size_t(n) * nb, -1);
  for (int r = 0; r < n; ++r) {
    if (src[r] < 0) continue;
    for (int b = b0; b < nb; ++b) {
      const int c = at(r, b);
      if (c < floor_q[b] + margin_at[size_t(b)]) continue;
      bool peak = true;
      for (int bb = std::max(0, b - wb); bb <= std::min(nb - 1, b + wb) && peak; ++bb)
        // Ties go to the nearer bin, so a flat top gives one return.
        if (bb != b) peak = at(r, bb) < c || (at(r, bb) == c && bb > b);
      if (!peak) continue;
      const double obs = std::pow(10.0, countToDb(c, s) / 10.0) -
                         std::pow(10.0, countToDb(floor_q[b], s) / 10.0);
      if (!(obs > 0)) continue;
      index[size_t(r) * nb + b] = int32_t(peaks.size());
      peaks.push_back({r, b, obs, 0.0});
    }
  }
  // The model's beam is taken out with its two-way azimuth response, read off the model itself
  // (beamProfile).
  const std::vector<double> kern = beamProfile(s);
  const int span = int(kern.size()) - 1;
  auto K = [&](double x) { return beamAt(kern, x); };  // log-linear between rows; 0 beyond
  auto neighbour = [&](int r, int b) {
    for (int bb = std::max(0, b - 1); bb <= std::min(nb - 1, b + 1); ++bb)
      if (index[size_t(r) * nb + bb] >= 0) return index[size_t(r) * nb + bb];
    return int32_t(-1);
  };
  // CLEAN along azimuth, strongest first: what the scatterers taken so far give at a row
  // through the model's response is taken off; a return standing out of its neighbours is
  // placed between rows (parabola through the log powers), so that a target between two rows
  // is one scatterer, not two (two would render as a wider return: a spurious narrow beam).
  std::vector<size_t> order(peaks.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t x, size_t y) { return peaks[x].obs > peaks[y].obs; });
  std::vector<double> at_row(peaks.size(), 0.0);  // sub-row position of the taken ones
  std::vector<SceneScatterer> placed;
  for (const size_t i : order) {
    Peak& pk = peaks[i];
    double blur = 0;
    for (int d = -span; d <= span; ++d) {
      const int32_t j = neighbour((pk.r + d + n) % n, pk.b);
      if (j >= 0 && peaks[size_t(j)].p > 0) blur += peaks[size_t(j)].p * K(d + at_row[size_t(j)]);
    }
    const double resid = pk.obs - blur;
    // A row whose return is mostly (70 %) the blur of the ones taken is taken as that blur:
    // the returns fluctuate row to row, and at 10 % those fluctuations became scatterers of
    // their own (a null recording of another scene then named a beam 12 % narrower).
    if (!(resid > 0.3 * pk.obs)) continue;
    const int32_t lo = neighbour((pk.r - 1 + n) % n, pk.b), hi = neighbour((pk.r + 1) % n, pk.b);
    double delta = 0;
    if (lo >= 0 && hi >= 0 && peaks[size_t(lo)].obs <= pk.obs && peaks[size_t(hi)].obs <= pk.obs) {
      const double l = std::log(peaks[size_t(lo)].obs), c = std::log(pk.obs),
                   h = std::log(peaks[size_t(hi)].obs);
      const double den = l - 2 * c + h;
      if (den < 0) delta = std::clamp(0.5 * (l - h) / den, -0.5, 0.5);
    }
    pk.p = resid / K(delta);
    at_row[i] = delta;  // a later row i' sees it at (row(i) - row(i')) + delta rows
    placed.push_back({pk.r, pk.b, delta, pk.p, 0.0});
    if (opt.scene_range_subbin) {
      // The middle of the peak's flat top (ties went to its first bin), then a parabola through
      // the log powers of the top and the bins either side of it.
      const int c0 = at(pk.r, pk.b);
      int b1 = pk.b, b2 = pk.b;
      while (b1 > 0 && pk.b - b1 < wb && at(pk.r, b1 - 1) == c0) --b1;
      while (b2 + 1 < nb && b2 - pk.b < wb && at(pk.r, b2 + 1) == c0) ++b2;
      double off = 0.5 * (b1 + b2) - pk.b;
      if (b1 > 0 && b2 + 1 < nb) {
        const double l = countToDb(at(pk.r, b1 - 1), s), c = countToDb(c0, s),
                     h = countToDb(at(pk.r, b2 + 1), s), den = l - 2 * c + h;
        if (den < 0) off += std::clamp(0.5 * (l - h) / den, -0.5, 0.5);
      }
      placed.back().bin_offset = off;
    }
  }
  // Optionally the strengths fitted together, positions held (appearance_scene_refine.cpp).
  refineAlongAzimuth(scan, s, src, floor_q, kern, placed, opt.scene_refine_passes);
  sim::World w;
  for (const SceneScatterer& t0 : placed) {
    if (!(t0.p > 0)) continue;
    const double step = 2.0 * M_PI / n;
    // On the rendered scan's row grid (row a at a * step), not at the recording's azimuth:
    // MulRan's rows sit 9/14 of a row past it (encoder 14 a + 9), and its scene came out
    // 0.64 rows late, every strong return split over two rows (docs/diagnose_scene.md).
    const double range = scan.rangeOfBin(t0.b + t0.bin_offset), phi = (t0.r + t0.delta) * step;
    sim::Target t;
    t.x = range * std::cos(phi);  // sensor frame: azimuth clockwise from forward
    t.y = -range * std::sin(phi);
    // Off a bin's centre the recorded peak is the range spread's value there, not its top.
    const double top = t0.bin_offset != 0 ? std::max(rangePsf(s, t0.bin_offset), 0.25) : 1.0;
    t.rcs = 10.0 * std::log10(t0.p / top) - pointGainDb(range, s);
    w.targets.push_back(t);
  }
  if (std::getenv("SPINRADAR_APPEARANCE_VERBOSE"))
    std::cerr << "recording scene: codes 1-30 " << distinct << ", counts/dB " << per_db
              << " (median spread " << spread[size_t(nb / 2)] << "), returns " << peaks.size()
              << ", scatterers " << w.targets.size() << "\n";
  return w;
}

std::vector<PolarScan> renderRecordingScene(const SensorConfig& sensor,
                                            const sim::PhysicsConfig& physics,
                                            const AppearanceOptions& opt, uint64_t seed) {
  if (!opt.scene_scans || opt.scene_scans->empty())
    throw std::invalid_argument("appearance: reference scene 'recording' without recorded scans");
  // A standing sensor: every rendered scan sees its recorded scan's returns where they were.
  const auto& scans = *opt.scene_scans;
  // Every fit scan at least once: the figures of the fit part are means over all of them.
  const int renders = std::max(opt.scans, int(scans.size()));
  const double dur = (renders + 2) / std::max(sensor.rotation_hz, 0.1);
  const sim::Trajectory standing({{0.0, {}}, {dur, {}}});
  std::vector<PolarScan> out;
  for (int i = 0; i < renders; ++i) {
    const PolarScan& sc = scans[size_t(i) % scans.size()];
    sim::Simulator sim(recordingWorld(sc, sensor, opt), standing, sensor, physics, seed);
    out.push_back(sim.renderScan(i));  // scan i: its own noise
  }
  return out;
}

bool notIdentifiableWithOwnScene(const std::string& key) {
  // Known truth (test_appearance_scene.cpp): a beam of 2.4 deg against 1.8 came back 1.49 with
  // the recording's scene (the wider returns become more scatterers); on Boreas-RT it ran to its
  // 0.3 deg bound. The gain chain moves only the weak clutter against the scene (Oxford: radar
  // constant 112 -> 89.5 dB). Fitted as nuisance parameters, never named.
  return key == "beam_width_deg" || key == "radar_constant_db" || key == "range_gain_db_per_decade";
}

namespace detail {
void markOwnSceneFindings(std::vector<AppearanceFinding>& findings,
                          std::vector<std::string>& notes) {
  for (AppearanceFinding& f : findings)
    if (notIdentifiableWithOwnScene(f.parameter)) {
      f.named = false;
      f.verdict = "not identifiable";
    }
  notes.push_back("Reference scene: the recording's own returns (docs/diagnose_scene.md). The "
                  "scene takes up part of the returns' gain and of the beam's blur: the receiver "
                  "gain, its range slope and the beam width are fitted as nuisance parameters "
                  "(kept as given they left Oxford's worst gap at 26 / 28 % instead of 14 / 10 %) "
                  "and never named.");
}
}  // namespace detail

AppearanceOptions withReferenceScene(const AppearanceOptions& opt,
                                     const std::vector<PolarScan>& recording) {
  AppearanceOptions o = opt;
  if (o.scene == "combined") o.scene = "recording", o.hold_gain_chain = true;  // its 2nd stage
  if (o.scene != "recording") return o;
  // The scene comes from the fit part only, so the held-out figures stay a check.
  std::vector<PolarScan> fit, holdout;
  if (opt.holdout)
    splitHoldout(recording, fit, holdout, parseHoldoutSplit(opt.holdout_split));
  else
    fit = recording;
  o.scene_scans = std::make_shared<const std::vector<PolarScan>>(std::move(fit));
  return o;
}

}  // namespace spinradar::diagnose
