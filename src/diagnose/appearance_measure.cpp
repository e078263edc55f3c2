// Appearance figures of polar scans (appearance.hpp). Every figure is computed per replicate (a
// quarter of a scan: 100 rows of a 400-row scan) so that even a single real scan gives a
// standard error from the scatter between its quarters.
#include <algorithm>
#include <cmath>

#include "spinradar/diagnose/appearance.hpp"

namespace spinradar::diagnose {

namespace {

struct Replicate {
  std::array<double, kBands> floor{}, mean{}, bright{}, cfar{};
  double beam = NAN, psf = NAN, behind = NAN, near = NAN;
  int peaks = 0;
  bool masked = false;  ///< all its rows invalid (held out): not a replicate
};

double lin(uint8_t c) { return std::pow(10.0, c / 10.0); }

// Share of the brightest cells whose mean is the "bright" figure (signal level per band).
constexpr double kBrightShare = 0.05;

// Mean of the lower half, mean, mean of the top 1 % from a histogram of counts.
void histFigures(const std::vector<double>& h, double& low, double& mean, double& top) {
  double n = 0, s = 0;
  for (int v = 0; v < 256; ++v) n += h[v], s += v * h[v];
  low = mean = top = 0;
  if (n <= 0) return;
  mean = s / n;
  double need = 0.5 * n, acc = 0, sum = 0;
  for (int v = 0; v < 256 && need > 0; ++v) {
    double take = std::min(h[v], need);
    sum += take * v, acc += take, need -= take;
  }
  low = sum / std::max(acc, 1.0);
  need = kBrightShare * n, acc = 0, sum = 0;
  for (int v = 255; v >= 0 && need > 0; --v) {
    double take = std::min(h[v], need);
    sum += take * v, acc += take, need -= take;
  }
  top = sum / std::max(acc, 1.0);
}

int bandOf(double r) {
  for (int k = 0; k < kBands; ++k)
    if (r >= sim::kBandEdges[k] && r < sim::kBandEdges[k + 1]) return k;
  return -1;
}

struct PeakSums {
  double beam = 0, psf = 0, az_side = 0, rng_side = 0;
  int n = 0, n_side = 0;
};

// Isolated, unsaturated peaks well above the floor: their azimuth and range equivalent widths
// (linear power above the floor, normalised by the peak cell), and the sidelobe levels.
void measurePeaks(const PolarScan& s, const std::array<double, kBands>& floor, int top,
                  PeakSums& ps) {
  const int N = s.azimuths, M = s.bins;
  const int R = 6, B = 40;  // isolation window (rows, bins)
  // A peak's window must lie in valid rows: a held-out row (masked and zeroed) would cut it.
  std::vector<int> bad_before(size_t(N) + 1, 0);
  for (int a = 0; a < N; ++a)
    bad_before[size_t(a) + 1] = bad_before[size_t(a)] + (!s.valid.empty() && !s.valid[size_t(a)]);
  for (int a = R; a < N - R; ++a) {
    if (bad_before[size_t(a + R) + 1] != bad_before[size_t(a - R)]) continue;
    const uint8_t* row = s.row(a);
    for (int b = B; b < M - B; ++b) {
      const int k = bandOf(s.rangeOfBin(b));
      if (k < 0) continue;
      const int c = row[b];
      if (c < floor[k] + 25 || c >= top - 2) continue;
      // Local maximum over +-2 rows, +-4 bins.
      bool is_max = true;
      for (int da = -2; da <= 2 && is_max; ++da) {
        const uint8_t* r2 = s.row(a + da);
        for (int db = -4; db <= 4; ++db)
          if ((da || db) && (r2[b + db] > c || (r2[b + db] == c && (da < 0 || (da == 0 && db < 0))))) {
            is_max = false;
            break;
          }
      }
      if (!is_max) continue;
      // Isolated: nothing within c - 12 in the window outside the core +-2 rows x +-10 bins.
      bool isolated = true;
      for (int da = -R; da <= R && isolated; ++da) {
        const uint8_t* r2 = s.row(a + da);
        for (int db = -B; db <= B; ++db) {
          if (std::abs(da) <= 2 && std::abs(db) <= 10) continue;
          if (r2[b + db] > c - 12) {
            isolated = false;
            break;
          }
        }
      }
      if (!isolated) continue;
      const double nl = std::pow(10.0, floor[k] / 10.0), p0 = lin(uint8_t(c)) - nl;
      if (p0 <= 0) continue;
      double az = 0, rg = 0;
      for (int da = -4; da <= 4; ++da) {
        const uint8_t* r2 = s.row(a + da);
        uint8_t m = 0;
        for (int db = -2; db <= 2; ++db) m = std::max(m, r2[b + db]);
        az += std::max(0.0, lin(m) - nl);
      }
      for (int db = -15; db <= 15; ++db) rg += std::max(0.0, lin(row[b + db]) - nl);
      ps.beam += az / p0;
      ps.psf += rg / p0;
      ++ps.n;
      if (c >= floor[k] + 40) {
        double sa = 0, sr = 0;
        for (int da = 3; da <= 6; ++da) sa += lin(s.row(a + da)[b]) + lin(s.row(a - da)[b]);
        for (int db = 10; db <= 20; ++db) sr += lin(row[b + db]) + lin(row[b - db]);
        ps.az_side += 10 * std::log10(sa / 8 / lin(uint8_t(c)));
        ps.rng_side += 10 * std::log10(sr / 22 / lin(uint8_t(c)));
        ++ps.n_side;
      }
    }
  }
}

// Share of bright cells (floor + 15) 2-30 m behind the first strong hit (floor + 30) of a row:
// multipath ghosts and returns through or around the first reflector.
double behindShare(const PolarScan& s, const std::array<double, kBands>& floor) {
  double bright = 0, cells = 0;
  const int gap = int(std::ceil(2.0 / s.range_resolution));
  const int span = int(30.0 / s.range_resolution);
  for (int a = 0; a < s.azimuths; ++a) {
    if (!s.valid.empty() && !s.valid[size_t(a)]) continue;
    const uint8_t* row = s.row(a);
    int hit = -1;
    for (int b = 0; b < s.bins; ++b) {
      int k = bandOf(s.rangeOfBin(b));
      if (k >= 0 && row[b] >= floor[k] + 30) {
        hit = b;
        break;
      }
    }
    if (hit < 0) continue;
    for (int b = hit + gap; b < std::min(s.bins, hit + gap + span); ++b) {
      int k = bandOf(s.rangeOfBin(b));
      if (k < 0) continue;
      cells += 1;
      if (row[b] >= floor[k] + 15) bright += 1;
    }
  }
  return cells > 0 ? bright / cells : NAN;
}

void meanSe(const std::vector<double>& v, double& mean, double& se) {
  std::vector<double> x;
  for (double d : v)
    if (std::isfinite(d)) x.push_back(d);
  mean = se = 0;
  if (x.empty()) {
    mean = se = NAN;
    return;
  }
  for (double d : x) mean += d;
  mean /= x.size();
  double ss = 0;
  for (double d : x) ss += (d - mean) * (d - mean);
  se = x.size() > 1 ? std::sqrt(ss / (x.size() - 1) / x.size()) : std::abs(mean) * 0.2;
}

}  // namespace

AppearanceFigures measureAppearance(const std::vector<PolarScan>& scans) {
  AppearanceFigures f;
  f.scans = int(scans.size());
  std::vector<Replicate> reps;
  std::vector<double> hist_all(256, 0.0);
  double az_side = 0, rng_side = 0, near = 0, near_n = 0, floor0 = 0;
  int n_side = 0;
  std::vector<double> row_means;
  for (const PolarScan& full : scans) {
    const bool has_valid = full.valid.size() == size_t(full.azimuths);
    for (int a = 0; a < full.azimuths; ++a)
      if (!has_valid || full.valid[a])
        for (int b = 0; b < full.bins; ++b) hist_all[full.row(a)[b]] += 1;
    const int Q = 4, rows = full.azimuths / Q;
    for (int q = 0; q < Q; ++q) {
      // A quarter whose rows are all masked out (held out for the check) is no replicate.
      bool any = !has_valid;
      for (int a = q * rows; a < (q + 1) * rows && !any; ++a) any = full.valid[a] != 0;
      if (!any) {
        Replicate r;
        r.masked = true;
        reps.push_back(r);
        continue;
      }
      // Only the quarter's valid rows (an interleaved split masks every other block of it).
      std::vector<int> keep;
      for (int a = q * rows; a < (q + 1) * rows; ++a)
        if (!has_valid || full.valid[a]) keep.push_back(a);
      PolarScan s;
      s.resize(int(keep.size()), full.bins);
      s.range_resolution = full.range_resolution;
      s.range_offset = full.range_offset;
      for (size_t i = 0; i < keep.size(); ++i)
        std::copy(full.row(keep[i]), full.row(keep[i]) + full.bins, s.power.begin() + long(i) * full.bins);
      const double per_rotation = double(full.azimuths) / double(keep.size());
      Replicate r;
      std::vector<std::vector<double>> h(kBands, std::vector<double>(256, 0.0));
      double rnear = 0, rnear_n = 0;
      for (int a = 0; a < s.azimuths; ++a) {
        const uint8_t* row = s.row(a);
        double rs = 0, rn = 0;
        for (int b = 0; b < s.bins; ++b) {
          const double range = s.rangeOfBin(b);
          if (range < 2.0 && range > 0) near += row[b], near_n += 1, rnear += row[b], rnear_n += 1;
          int k = bandOf(range);
          if (k >= 0) h[k][row[b]] += 1;
          if (k == 3) rs += row[b], rn += 1;
        }
        if (rn > 0) row_means.push_back(rs / rn);
      }
      for (int k = 0; k < kBands; ++k) histFigures(h[k], r.floor[k], r.mean[k], r.bright[k]);
      floor0 += r.floor[0];
      if (rnear_n > 0) r.near = rnear / rnear_n - r.floor[0];
      double cf[4] = {0, 0, 0, 0};
      sim::countPlainCaCfar(s, sim::kBandEdges[0], sim::kBandEdges[kBands], cf);
      for (int k = 0; k < kBands; ++k) r.cfar[k] = std::log10(1.0 + per_rotation * cf[k]);
      reps.push_back(r);
    }
  }
  // Peaks and the behind-the-first-hit share need whole rows of context: per scan, split into
  // the same quarters by the peak's row.
  {
    size_t ri = 0;
    for (const PolarScan& s : scans) {
      int top = 255;
      for (int v = 255; v >= 0; --v)
        if (hist_all[v] > 0) {
          top = v;
          break;
        }
      std::array<double, kBands> fl{};
      int used = 0;
      for (int q = 0; q < 4; ++q)
        if (!reps[ri + q].masked) {
          ++used;
          for (int k = 0; k < kBands; ++k) fl[k] += reps[ri + q].floor[k];
        }
      for (int k = 0; k < kBands; ++k) fl[k] /= std::max(used, 1);
      const int rows = s.azimuths / 4;
      for (int q = 0; q < 4; ++q) {
        if (reps[ri + q].masked) continue;
        PolarScan sub;
        const int a0 = std::max(0, q * rows - 6), a1 = std::min(s.azimuths, (q + 1) * rows + 6);
        sub.resize(a1 - a0, s.bins);
        sub.range_resolution = s.range_resolution;
        sub.range_offset = s.range_offset;
        std::copy(s.row(a0), s.row(a0) + size_t(a1 - a0) * s.bins, sub.power.begin());
        if (s.valid.size() == size_t(s.azimuths))  // masked (held-out) rows: no peak window there
          std::copy(s.valid.begin() + a0, s.valid.begin() + a1, sub.valid.begin());
        PeakSums ps;
        measurePeaks(sub, fl, top, ps);
        Replicate& r = reps[ri + q];
        if (ps.n >= 3) {
          r.beam = ps.beam / ps.n;
          r.psf = ps.psf / ps.n;
        }
        r.peaks = ps.n;
        az_side += ps.az_side, rng_side += ps.rng_side, n_side += ps.n_side;
        r.behind = behindShare(sub, fl);
      }
      ri += 4;
    }
  }
  reps.erase(std::remove_if(reps.begin(), reps.end(), [](const Replicate& r) { return r.masked; }),
             reps.end());
  auto collect = [&](auto get, double& m, double& se) {
    std::vector<double> v;
    for (const auto& r : reps) v.push_back(get(r));
    meanSe(v, m, se);
  };
  for (int k = 0; k < kBands; ++k) {
    collect([k](const Replicate& r) { return r.floor[k]; }, f.floor[k], f.floor_se[k]);
    collect([k](const Replicate& r) { return r.mean[k]; }, f.mean[k], f.mean_se[k]);
    collect([k](const Replicate& r) { return r.bright[k]; }, f.bright[k], f.bright_se[k]);
    collect([k](const Replicate& r) { return r.cfar[k]; }, f.cfar[k], f.cfar_se[k]);
  }
  collect([](const Replicate& r) { return r.beam; }, f.beam_rows, f.beam_rows_se);
  collect([](const Replicate& r) { return r.psf; }, f.psf_bins, f.psf_bins_se);
  collect([](const Replicate& r) { return r.behind; }, f.behind, f.behind_se);
  {
    double m = 0;
    collect([](const Replicate& r) { return r.near; }, m, f.near_excess_se);
  }
  for (const auto& r : reps) {
    f.peaks += r.peaks;
    std::vector<double> v;
    for (const auto* a : {&r.floor, &r.mean, &r.bright, &r.cfar}) v.insert(v.end(), a->begin(), a->end());
    v.push_back(r.beam);
    v.push_back(r.psf);
    f.replicates.push_back(std::move(v));
  }
  f.az_sidelobe_db = n_side ? az_side / n_side : NAN;
  f.rng_sidelobe_db = n_side ? rng_side / n_side : NAN;
  f.near_excess = near_n > 0 && !reps.empty() ? near / near_n - floor0 / reps.size() : NAN;
  for (int v = 255; v >= 0; --v)
    if (hist_all[v] > 0) {
      f.top_count = v;
      double below = 0;
      for (int d = 1; d <= 3 && v - d >= 0; ++d) below += hist_all[v - d];
      f.pileup = hist_all[v] / std::max(below / 3, 1.0);
      break;
    }
  for (int v = 1; v <= 30; ++v)
    if (hist_all[v] > 0) ++f.distinct_low_codes;
  if (row_means.size() > 1) {
    double m = 0, ss = 0;
    for (double x : row_means) m += x;
    m /= row_means.size();
    for (double x : row_means) ss += (x - m) * (x - m);
    f.row_sd = std::sqrt(ss / (row_means.size() - 1));
  }
  return f;
}

}  // namespace spinradar::diagnose
