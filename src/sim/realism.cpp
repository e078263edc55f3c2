// Realism figures of polar scans (see realism.hpp).
#include "spinradar/sim/realism.hpp"
#include "spinradar/sim/realism_seeds.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "spinradar/features/detector.hpp"
#include "spinradar/io/scan_io.hpp"

namespace spinradar::sim {

namespace {

// Pearson correlation accumulator.
struct Corr {
  double n = 0, sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
  void add(double x, double y) {
    n += 1, sx += x, sy += y, sxx += x * x, syy += y * y, sxy += x * y;
  }
  double value() const {
    double vx = sxx - sx * sx / n, vy = syy - sy * sy / n;
    return vx > 0 && vy > 0 ? (sxy - sx * sy / n) / std::sqrt(vx * vy) : 0.0;
  }
};

}  // namespace

void countPlainCaCfar(const PolarScan& s, double min_range, double max_range, double per_band[4]) {
  constexpr int kTrain = 16, kGuard = 4;
  const double alpha = std::pow(10.0, 1.2);
  static const std::vector<double> lut = [] {
    std::vector<double> t(256);
    for (int c = 0; c < 256; ++c) t[c] = std::pow(10.0, c / 10.0);
    return t;
  }();
  std::vector<double> lin(size_t(s.bins)), cum(size_t(s.bins) + 1);
  const int b0 = std::max(kTrain + kGuard, int(std::ceil(s.binOfRange(min_range))));
  const int b1 = std::min(s.bins - 1 - kTrain - kGuard, int(std::floor(s.binOfRange(max_range))));
  for (int a = 0; a < s.azimuths; ++a) {
    if (!s.valid.empty() && !s.valid[a]) continue;
    const uint8_t* row = s.row(a);
    cum[0] = 0;
    for (int b = 0; b < s.bins; ++b) {
      lin[b] = lut[row[b]];
      cum[b + 1] = cum[b] + lin[b];
    }
    for (int b = b0; b <= b1; ++b) {
      double train = cum[b - kGuard] - cum[b - kGuard - kTrain] + cum[b + kGuard + kTrain + 1] -
                     cum[b + kGuard + 1];
      if (lin[b] <= alpha * train / (2 * kTrain)) continue;
      double r = s.rangeOfBin(b);
      for (int k = 0; k < 4; ++k)
        if (r >= kBandEdges[k] && r < kBandEdges[k + 1]) per_band[k] += 1;
    }
  }
}

std::vector<double> bandGaps(const RealismStats& sim, const RealismStats& real) {
  std::vector<double> g;
  auto rel = [&](double s, double r) {
    g.push_back(r > 0 ? std::abs(s - r) / r : (s > 0 ? 1.0 : 0.0));
  };
  for (int k = 0; k < 4; ++k) {
    rel(sim.band_mean[k], real.band_mean[k]);
    rel(sim.band_q90[k], real.band_q90[k]);
    rel(sim.band_cacfar[k], real.band_cacfar[k]);
    if (sim.band_cen[k] >= 0 && real.band_cen[k] >= 0) rel(sim.band_cen[k], real.band_cen[k]);
  }
  return g;
}

RealismStats computeRealism(const std::vector<PolarScan>& scans, const std::string& name,
                            const RealismOptions& o) {
  RealismStats st;
  st.name = name;
  st.scans = int(scans.size());
  std::vector<double> hist(256, 0.0);
  std::vector<std::vector<double>> band_hist(4, std::vector<double>(256, 0.0));
  double cacfar[4] = {0, 0, 0, 0}, cen_band[4] = {0, 0, 0, 0};
  double band_sum[4] = {0, 0, 0, 0}, band_n[4] = {0, 0, 0, 0};
  std::vector<double> beyond_hist(256, 0.0);
  const double* band_edge = kBandEdges;
  Corr az, rs, rl;
  double det_cen = 0, det_cfar = 0;
  std::vector<Keypoint> kps;
  for (const PolarScan& s : scans) {
    // Counts per scan are per full rotation: a scan with rows masked out (held-out halves of a
    // single real scan) is scaled up by its share of valid rows.
    int valid_rows = s.azimuths;
    if (!s.valid.empty()) valid_rows = int(std::count_if(s.valid.begin(), s.valid.end(), [](uint8_t v) { return v != 0; }));
    const double per_rotation = valid_rows > 0 ? double(s.azimuths) / valid_rows : 0.0;
    int b0 = std::max(0, int(std::ceil(s.binOfRange(o.min_range))));
    int b1 = std::min(s.bins - 1, int(std::floor(s.binOfRange(o.max_range))));
    int lag_s = std::max(1, int(std::lround(0.25 / s.range_resolution)));
    int lag_l = std::max(1, int(std::lround(1.0 / s.range_resolution)));
    for (int a = 0; a < s.azimuths; ++a) {
      if (!s.valid.empty() && !s.valid[a]) continue;
      const uint8_t* row = s.row(a);
      const uint8_t* next = s.row((a + 1) % s.azimuths);
      for (int b = b1 + 1; b < s.bins; ++b) beyond_hist[row[b]] += 1;
      for (int b = b0; b <= b1; ++b) {
        hist[row[b]] += 1;
        double r = s.rangeOfBin(b);
        for (int k = 0; k < 4; ++k)
          if (r >= band_edge[k] && r < band_edge[k + 1]) {
            band_sum[k] += row[b], band_n[k] += 1;
            band_hist[k][row[b]] += 1;
          }
        // Subsample the texture statistics (every 3rd cell) to keep this fast.
        if (b % 3 == 0) {
          az.add(row[b], next[b]);
          if (b + lag_s <= b1) rs.add(row[b], row[b + lag_s]);
          if (b + lag_l <= b1) rl.add(row[b], row[b + lag_l]);
        }
      }
    }
    if (o.detect) {
      DetectorConfig dc = o.detector;
      dc.min_range = o.min_range;
      dc.max_range = o.max_range;
      dc.detector = "cen2018";
      dc.azimuth_peaks = false;  // the figures are the paper's detectors: keypoints per row
      Detector d(dc);
      d.detect(s, kps);
      det_cen += kps.size() * per_rotation;
      for (const Keypoint& kp : kps)
        for (int k = 0; k < 4; ++k)
          if (kp.range >= band_edge[k] && kp.range < band_edge[k + 1]) cen_band[k] += per_rotation;
      dc.detector = "cfar";
      d.setConfig(dc);
      d.detect(s, kps);
      det_cfar += kps.size() * per_rotation;
    }
    double cf[4] = {0, 0, 0, 0};
    countPlainCaCfar(s, o.min_range, o.max_range, cf);
    for (int k = 0; k < 4; ++k) cacfar[k] += cf[k] * per_rotation;
  }
  const double ns = std::max<size_t>(scans.size(), 1);
  for (int k = 0; k < 4; ++k) {
    double n = 0, c = 0;
    for (double h : band_hist[k]) n += h;
    for (int v = 0; v < 256 && n > 0; ++v) {
      c += band_hist[k][v];
      if (c >= 0.9 * n) {
        st.band_q90[k] = v;
        break;
      }
    }
    // Lower half of the counts, the last code partly: same definition as the appearance floor.
    double lo = 0, taken = 0;
    for (int v = 0; v < 256 && n > 0 && taken < 0.5 * n; ++v) {
      const double t = std::min(band_hist[k][v], 0.5 * n - taken);
      lo += t * v;
      taken += t;
    }
    if (taken > 0) st.band_floor[k] = lo / taken;
    if (n > 0) st.band_zero[k] = std::clamp(band_hist[k][0] / n, 0.0, 1.0);
    st.band_cacfar[k] = cacfar[k] / ns;
    st.cacfar += cacfar[k] / ns;
    if (o.detect) st.band_cen[k] = cen_band[k] / ns;
  }
  double total = 0, sum = 0;
  for (int v = 0; v < 256; ++v) total += hist[v], sum += v * hist[v];
  if (total == 0) return st;
  st.zero_fraction = hist[0] / total;
  st.mean = sum / total;
  auto quantile = [&](double q) {
    double c = 0;
    for (int v = 0; v < 256; ++v) {
      c += hist[v];
      if (c >= q * total) return double(v);
    }
    return 255.0;
  };
  st.q50 = quantile(0.5);
  st.q90 = quantile(0.9);
  st.q99 = quantile(0.99);
  st.q999 = quantile(0.999);
  for (int v = 255; v >= 0; --v)
    if (hist[v] > 0) {
      st.max = v;
      break;
    }
  double bright = 0;
  for (int v = 40; v < 256; ++v) bright += hist[v];
  st.bright_fraction = bright / total;
  for (int k = 0; k < 4; ++k) st.band_mean[k] = band_n[k] > 0 ? band_sum[k] / band_n[k] : 0;
  double beyond_n = 0, beyond_sum = 0;
  for (int v = 0; v < 256; ++v) beyond_n += beyond_hist[v], beyond_sum += v * beyond_hist[v];
  double beyond_c = 0;
  for (int v = 0; v < 256 && beyond_n > 0; ++v)
    if ((beyond_c += beyond_hist[v]) >= 0.9 * beyond_n) {
      st.beyond_mean = beyond_sum / beyond_n;
      st.beyond_q90 = v;
      break;
    }
  st.azimuth_corr = az.value();
  st.range_corr_short = rs.value();
  st.range_corr_long = rl.value();
  if (o.detect && !scans.empty()) {
    st.detections_cen = det_cen / scans.size();
    st.detections_cfar = det_cfar / scans.size();
  }
  return st;
}

std::vector<std::pair<std::string, std::vector<PolarScan>>> loadRealSamples(
    const std::string& dir) {
  namespace fs = std::filesystem;
  std::vector<std::pair<std::string, std::vector<PolarScan>>> out;
  auto sorted = [](const fs::path& p, const std::string& ext) {
    std::vector<std::string> files;
    if (fs::is_directory(p))
      for (const auto& e : fs::directory_iterator(p))
        if (e.path().extension() == ext) files.push_back(e.path().string());
    std::sort(files.begin(), files.end());
    return files;
  };
  fs::path root(dir);
  {
    std::vector<PolarScan> v;
    for (const auto& f : sorted(root / "oxford_2019-01-10-14-36-48" / "radar", ".png"))
      v.push_back(loadOxfordPng(f));
    if (!v.empty()) out.emplace_back("oxford (real)", std::move(v));
  }
  {
    std::vector<PolarScan> v;
    for (const auto& f : sorted(root / "mulran", ".csv")) v.push_back(loadMulranCsv(f));
    if (!v.empty()) out.emplace_back("mulran (real)", std::move(v));
  }
  {
    std::vector<PolarScan> v;
    fs::path f = root / "boreas_rt" / "test_frame.png";
    if (fs::exists(f)) v.push_back(loadBoreasPng(f.string()));
    if (!v.empty()) out.emplace_back("boreas-rt (real)", std::move(v));
  }
  {
    std::vector<PolarScan> v;
    int64_t t = 0;
    for (const auto& f : sorted(root / "radiate_fog_6_0" / "Navtech_Polar", ".png")) {
      v.push_back(loadRadiatePng(f, t));
      t += 250000000;
    }
    if (!v.empty()) out.emplace_back("radiate* (real)", std::move(v));
  }
  return out;
}

std::string formatRealismTable(const std::vector<RealismStats>& cols) {
  return formatRealismTable(cols, std::vector<const RealismOverSeeds*>(cols.size(), nullptr));
}

std::string formatRealismTable(const std::vector<RealismStats>& cols,
                               const std::vector<const RealismOverSeeds*>& spreads) {
  if (spreads.size() != cols.size())
    throw std::invalid_argument("formatRealismTable: one seed spread (or null) per column");
  std::ostringstream os;
  os << std::fixed;
  os << "| figure |";
  for (const auto& c : cols) os << ' ' << c.name << " |";
  os << "\n|---|";
  for (size_t i = 0; i < cols.size(); ++i) os << "---|";
  os << "\n";
  auto row = [&](const char* label, auto get, int prec) {
    os << "| " << label << " |";
    for (size_t i = 0; i < cols.size(); ++i) {
      const double v = get(cols[i]);
      if (v < 0) {
        os << " - |";
        continue;
      }
      os << ' ' << std::setprecision(prec) << v;
      // A mean over noise seeds carries its range; one render (or equal seeds) prints as before.
      if (const RealismOverSeeds* sp = spreads[i]; sp && get(sp->lo) != get(sp->hi))
        os << " [" << get(sp->lo) << "-" << get(sp->hi) << "]";
      os << " |";
    }
    os << "\n";
  };
  row("scans", [](const RealismStats& c) { return double(c.scans); }, 0);
  row("zero fraction", [](const RealismStats& c) { return c.zero_fraction; }, 3);
  row("mean count", [](const RealismStats& c) { return c.mean; }, 1);
  row("median", [](const RealismStats& c) { return c.q50; }, 0);
  row("q90", [](const RealismStats& c) { return c.q90; }, 0);
  row("q99", [](const RealismStats& c) { return c.q99; }, 0);
  row("q99.9", [](const RealismStats& c) { return c.q999; }, 0);
  row("max", [](const RealismStats& c) { return c.max; }, 0);
  row("share >= 40", [](const RealismStats& c) { return c.bright_fraction; }, 4);
  row("mean 2.5-10 m", [](const RealismStats& c) { return c.band_mean[0]; }, 1);
  row("mean 10-25 m", [](const RealismStats& c) { return c.band_mean[1]; }, 1);
  row("mean 25-50 m", [](const RealismStats& c) { return c.band_mean[2]; }, 1);
  row("mean 50-100 m", [](const RealismStats& c) { return c.band_mean[3]; }, 1);
  const char* bands[4] = {"2.5-10 m", "10-25 m", "25-50 m", "50-100 m"};
  for (int k = 0; k < 4; ++k)
    row(("q90 " + std::string(bands[k])).c_str(), [k](const RealismStats& c) { return c.band_q90[k]; }, 0);
  row("azimuth corr (lag 1)", [](const RealismStats& c) { return c.azimuth_corr; }, 3);
  row("range corr (0.25 m)", [](const RealismStats& c) { return c.range_corr_short; }, 3);
  row("range corr (1 m)", [](const RealismStats& c) { return c.range_corr_long; }, 3);
  row("Cen2018 keypoints/scan", [](const RealismStats& c) { return c.detections_cen; }, 0);
  row("CFAR keypoints/scan", [](const RealismStats& c) { return c.detections_cfar; }, 0);
  for (int k = 0; k < 4; ++k)
    row(("Cen2018/scan " + std::string(bands[k])).c_str(), [k](const RealismStats& c) { return c.band_cen[k]; }, 0);
  row("plain CA-CFAR cells/scan", [](const RealismStats& c) { return c.cacfar; }, 0);
  for (int k = 0; k < 4; ++k)
    row(("CA-CFAR/scan " + std::string(bands[k])).c_str(), [k](const RealismStats& c) { return c.band_cacfar[k]; }, 0);
  return os.str();
}

}  // namespace spinradar::sim
