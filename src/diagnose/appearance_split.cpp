// Fit / held-out splits of the appearance stage and the real halves' own difference under each
// (issue 20, docs/diagnose_holdout.md "tenth round"). See appearance_split.hpp.
#include "spinradar/diagnose/appearance_split.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <sstream>
#include <stdexcept>

#include "spinradar/features/detector.hpp"
#include "spinradar/sim/realism.hpp"

namespace spinradar::diagnose {

std::string HoldoutSplit::name() const {
  if (kind == kContiguous) return "contiguous";
  if (kind == kScans) return "scans";
  if (kind == kAuto) return "auto";
  return "blocks:" + std::to_string(block_rows);
}

HoldoutSplit parseHoldoutSplit(const std::string& text) {
  HoldoutSplit s;
  if (text == "contiguous") return s.kind = HoldoutSplit::kContiguous, s;
  if (text == "scans") return s.kind = HoldoutSplit::kScans, s;
  if (text == "auto") return s.kind = HoldoutSplit::kAuto, s;
  if (text.rfind("blocks:", 0) == 0) {
    const std::string n = text.substr(7);
    size_t used = 0;
    int v = 0;
    try {
      v = std::stoi(n, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (n.empty() || used != n.size() || v < 2 || v > 100000 || v % 2)
      throw std::invalid_argument("holdout split '" + text + "': N of blocks:N must be an even "
                                  "whole number of rows >= 2 (even: as many even as odd rows)");
    s.kind = HoldoutSplit::kBlocks;
    s.block_rows = v;
    return s;
  }
  throw std::invalid_argument("holdout split '" + text +
                              "': expected auto, contiguous, scans or blocks:N (N even rows)");
}

namespace {

// 0 = fit part, 1 = held out, for row `r` of scan `i` of `n` scans of `az` rows.
int partOf(const HoldoutSplit& sp, int i, int n, int r, int az) {
  if (sp.kind == HoldoutSplit::kScans) return i % 2;
  if (sp.kind == HoldoutSplit::kContiguous) {
    if (n >= 2) return i < (n + 1) / 2 ? 0 : 1;
    return std::min(r / std::max(az / 4, 1), 3) % 2;
  }
  return (r / sp.block_rows) % 2;
}

void checkFits(const HoldoutSplit& sp, const std::vector<PolarScan>& scans) {
  if (sp.kind == HoldoutSplit::kScans && scans.size() < 2)
    throw std::invalid_argument("holdout split 'scans' needs at least 2 scans (the recording has " +
                                std::to_string(scans.size()) + "); use blocks:N");
  if (sp.kind == HoldoutSplit::kBlocks)
    for (const PolarScan& s : scans)
      if (2 * sp.block_rows > s.azimuths)
        throw std::invalid_argument("holdout split '" + sp.name() + "': blocks larger than half of a " +
                                    std::to_string(s.azimuths) + "-row scan");
}

// A copy of `s` holding only the rows of `part` (others masked and zeroed).
PolarScan keepRows(const PolarScan& s, const HoldoutSplit& sp, int i, int n, int part) {
  PolarScan c = s;
  if (c.valid.size() != size_t(c.azimuths)) c.valid.assign(size_t(c.azimuths), 1);
  for (int r = 0; r < c.azimuths; ++r)
    if (partOf(sp, i, n, r, c.azimuths) != part) {
      c.valid[size_t(r)] = 0;
      std::fill(c.power.begin() + long(r) * c.bins, c.power.begin() + long(r + 1) * c.bins, 0);
    }
  return c;
}

constexpr int kFigBands = 3;  // the fitted bands: 10-25, 25-50, 50-100 m (band 1..3)

// Counts of one 2-row group of one scan: per fitted band the histogram of counts, plain CA-CFAR
// cells and Cen2018 keypoints, and its valid rows.
struct Group {
  int scan = 0, row0 = 0, rows = 0, even = 0;
  std::array<std::array<uint32_t, 256>, kFigBands> hist{};
  std::array<double, kFigBands> cfar{}, cen{};
};

std::vector<Group> groupCounts(const std::vector<PolarScan>& scans) {
  const sim::RealismOptions ro;
  DetectorConfig dc = ro.detector;
  dc.min_range = ro.min_range;
  dc.max_range = ro.max_range;
  dc.detector = "cen2018";
  dc.azimuth_peaks = false;  // as sim::computeRealism: keypoints per row
  Detector det(dc);
  std::vector<Keypoint> kps;
  std::vector<Group> out;
  for (size_t i = 0; i < scans.size(); ++i) {
    PolarScan s = scans[i];
    const std::vector<uint8_t> orig =
        s.valid.size() == size_t(s.azimuths) ? s.valid : std::vector<uint8_t>(size_t(s.azimuths), 1);
    const int b0 = std::max(0, int(std::ceil(s.binOfRange(ro.min_range))));
    const int b1 = std::min(s.bins - 1, int(std::floor(s.binOfRange(ro.max_range))));
    for (int g0 = 0; g0 < s.azimuths; g0 += 2) {
      Group g;
      g.scan = int(i), g.row0 = g0;
      s.valid.assign(size_t(s.azimuths), 0);
      for (int r = g0; r < std::min(g0 + 2, s.azimuths); ++r)
        if (orig[size_t(r)]) {
          s.valid[size_t(r)] = 1, ++g.rows, g.even += r % 2 == 0;
          const uint8_t* row = s.row(r);
          for (int b = b0; b <= b1; ++b) {
            const double range = s.rangeOfBin(b);
            for (int k = 1; k < 4; ++k)
              if (range >= sim::kBandEdges[k] && range < sim::kBandEdges[k + 1]) ++g.hist[size_t(k - 1)][row[b]];
          }
        }
      if (g.rows) {
        double cf[4] = {0, 0, 0, 0};
        sim::countPlainCaCfar(s, ro.min_range, ro.max_range, cf);
        det.detect(s, kps);
        for (int k = 1; k < 4; ++k) {
          g.cfar[size_t(k - 1)] = cf[k];
          for (const Keypoint& kp : kps)
            if (kp.range >= sim::kBandEdges[k] && kp.range < sim::kBandEdges[k + 1]) g.cen[size_t(k - 1)] += 1;
        }
      }
      out.push_back(g);
    }
  }
  return out;
}

// The 12 figures of the groups with in[g] set, as sim::computeRealism of the part's scans.
std::array<double, 12> partFigures(const std::vector<Group>& gs, const std::vector<char>& in,
                                   const std::vector<PolarScan>& scans) {
  std::array<std::array<double, 256>, kFigBands> h{};
  std::vector<int> rows(scans.size(), 0);
  std::vector<std::array<double, 2 * kFigBands>> per_scan(scans.size(), std::array<double, 6>{});
  for (size_t j = 0; j < gs.size(); ++j) {
    if (!in[j] || !gs[j].rows) continue;
    const Group& g = gs[j];
    rows[size_t(g.scan)] += g.rows;
    for (int k = 0; k < kFigBands; ++k) {
      for (int v = 0; v < 256; ++v) h[size_t(k)][size_t(v)] += g.hist[size_t(k)][size_t(v)];
      per_scan[size_t(g.scan)][size_t(k)] += g.cfar[size_t(k)];
      per_scan[size_t(g.scan)][size_t(k + 3)] += g.cen[size_t(k)];
    }
  }
  std::array<double, 12> f{};
  int ns = 0;
  for (size_t i = 0; i < scans.size(); ++i)
    if (rows[i] > 0) {
      ++ns;
      const double per_rotation = double(scans[i].azimuths) / rows[i];
      for (int k = 0; k < kFigBands; ++k) {
        f[size_t(4 * k + 2)] += per_scan[i][size_t(k)] * per_rotation;
        f[size_t(4 * k + 3)] += per_scan[i][size_t(k + 3)] * per_rotation;
      }
    }
  for (int k = 0; k < kFigBands; ++k) {
    double n = 0, s = 0, c = 0;
    for (int v = 0; v < 256; ++v) n += h[size_t(k)][size_t(v)], s += v * h[size_t(k)][size_t(v)];
    f[size_t(4 * k)] = n > 0 ? s / n : 0;
    for (int v = 0; v < 256 && n > 0; ++v) {
      c += h[size_t(k)][size_t(v)];
      if (c >= 0.9 * n) {
        f[size_t(4 * k + 1)] = v;
        break;
      }
    }
    f[size_t(4 * k + 2)] /= std::max(ns, 1);
    f[size_t(4 * k + 3)] /= std::max(ns, 1);
  }
  return f;
}

double rel(double held, double fit) { return fit > 0 ? std::abs(held - fit) / fit : (held > 0 ? 1.0 : 0.0); }

std::array<double, 12> halvesOf(const std::vector<Group>& gs, const std::vector<char>& part,
                                const std::vector<PolarScan>& scans) {
  std::vector<char> a(part.size()), b(part.size());
  for (size_t j = 0; j < part.size(); ++j) a[j] = part[j] == 0, b[j] = part[j] == 1;
  const auto fa = partFigures(gs, a, scans), fb = partFigures(gs, b, scans);
  std::array<double, 12> d{};
  for (int i = 0; i < 12; ++i) d[size_t(i)] = rel(fb[size_t(i)], fa[size_t(i)]);
  return d;
}

}  // namespace

void splitHoldout(const std::vector<PolarScan>& scans, std::vector<PolarScan>& fit,
                  std::vector<PolarScan>& holdout, const HoldoutSplit& split) {
  if (split.kind == HoldoutSplit::kAuto) return splitHoldout(scans, fit, holdout, chooseHoldoutSplit(scans));
  fit.clear();
  holdout.clear();
  checkFits(split, scans);
  const int n = int(scans.size());
  for (int i = 0; i < n; ++i) {
    const PolarScan& s = scans[size_t(i)];
    const bool whole = split.kind == HoldoutSplit::kScans || (split.kind == HoldoutSplit::kContiguous && n >= 2);
    if (whole) {
      (partOf(split, i, n, 0, s.azimuths) == 0 ? fit : holdout).push_back(s);
      continue;
    }
    fit.push_back(keepRows(s, split, i, n, 0));
    holdout.push_back(keepRows(s, split, i, n, 1));
  }
}

void splitHoldout(const std::vector<PolarScan>& scans, std::vector<PolarScan>& fit,
                  std::vector<PolarScan>& holdout) {
  HoldoutSplit c;
  c.kind = HoldoutSplit::kContiguous;
  splitHoldout(scans, fit, holdout, c);
}

bool admittedSplit(const HoldoutSplit& sp, const std::vector<PolarScan>& scans, std::string* why) {
  auto no = [&](const std::string& w) {
    if (why) *why = w;
    return false;
  };
  if (sp.kind == HoldoutSplit::kAuto) return no("auto is the rule itself");
  try {
    checkFits(sp, scans);
  } catch (const std::invalid_argument& e) {
    return no(e.what());
  }
  const int n = int(scans.size());
  if (sp.kind == HoldoutSplit::kScans || (sp.kind == HoldoutSplit::kContiguous && n >= 2)) return true;
  for (const PolarScan& s : scans) {
    const int az = s.azimuths, q = std::max(az / 4, 1);
    if (sp.kind == HoldoutSplit::kBlocks && sp.block_rows < kMinBlockRows * az / 400)
      return no("blocks under " + std::to_string(kMinBlockRows) + " rows (per 400)");
    for (int r = 0; r < az; ++r) {
      const int p = partOf(sp, 0, 1, r, az);
      if (partOf(sp, 0, 1, (r + q) % az, az) == p && partOf(sp, 0, 1, (r + az - q) % az, az) == p)
        return no("row " + std::to_string(r) + " has no row of the other part a quarter turn away "
                  "(the own scene would have no returns there)");
    }
  }
  return true;
}

HoldoutSplit chooseHoldoutSplit(const std::vector<PolarScan>& scans, double* halves) {
  std::vector<HoldoutSplit> c;
  for (const char* name : kAutoCandidates) {
    const HoldoutSplit sp = parseHoldoutSplit(name);
    if (admittedSplit(sp, scans)) c.push_back(sp);
  }
  if (c.empty()) throw std::invalid_argument("holdout split auto: no candidate fits the recording");
  const auto sv = surveySplits(scans, c, 0);
  size_t best = 0;
  for (size_t i = 1; i < sv.size(); ++i)
    if (sv[i].largest < sv[best].largest) best = i;
  if (halves) *halves = sv[best].largest;
  return parseHoldoutSplit(sv[best].split);
}

std::vector<SplitHalves> surveySplits(const std::vector<PolarScan>& scans,
                                      const std::vector<HoldoutSplit>& splits, int permutations,
                                      uint64_t seed) {
  static const char* const names[12] = {
      "10-25 m mean", "10-25 m q90", "10-25 m cacfar", "10-25 m cen2018",
      "25-50 m mean", "25-50 m q90", "25-50 m cacfar", "25-50 m cen2018",
      "50-100 m mean", "50-100 m q90", "50-100 m cacfar", "50-100 m cen2018"};
  const std::vector<Group> gs = groupCounts(scans);
  const int n = int(scans.size());
  std::vector<SplitHalves> out;
  for (const HoldoutSplit& sp_in : splits) {
    const HoldoutSplit sp = sp_in.kind == HoldoutSplit::kAuto ? chooseHoldoutSplit(scans) : sp_in;
    SplitHalves sh;
    sh.split = sp_in.kind == HoldoutSplit::kAuto ? "auto = " + sp.name() : sp.name();
    try {
      checkFits(sp, scans);
    } catch (const std::invalid_argument&) {
      continue;  // not applicable to this recording (e.g. "scans" on one scan)
    }
    // The split's units: whole scans, quarters of one scan, or blocks of every scan.
    std::vector<int> unit(gs.size());
    const bool by_scan = sp.kind == HoldoutSplit::kScans || (sp.kind == HoldoutSplit::kContiguous && n >= 2);
    std::vector<char> part(gs.size());
    std::vector<std::array<int, 2>> even_odd(size_t(2 * n), {0, 0});
    for (size_t j = 0; j < gs.size(); ++j) {
      const Group& g = gs[j];
      const int az = scans[size_t(g.scan)].azimuths;
      part[j] = char(partOf(sp, g.scan, n, g.row0, az));
      const int per_scan_units = sp.kind == HoldoutSplit::kBlocks ? (az + sp.block_rows - 1) / sp.block_rows : 4;
      unit[j] = by_scan ? g.scan
                        : g.scan * per_scan_units +
                              (sp.kind == HoldoutSplit::kBlocks ? g.row0 / sp.block_rows
                                                               : std::min(g.row0 / std::max(az / 4, 1), 3));
      auto& eo = even_odd[size_t(2 * g.scan + part[j])];
      eo[0] += g.even, eo[1] += g.rows - g.even;
    }
    for (const auto& eo : even_odd) sh.even_odd_balanced = sh.even_odd_balanced && eo[0] == eo[1];
    const auto d = halvesOf(gs, part, scans);
    for (int i = 0; i < 12; ++i) {
      sh.figures.emplace_back(names[i], d[size_t(i)]);
      if (d[size_t(i)] > sh.largest) sh.largest = d[size_t(i)], sh.largest_figure = names[i];
    }
    // Floor: the same units assigned at random, half each (per scan for blocks and quarters).
    const int units = *std::max_element(unit.begin(), unit.end()) + 1;
    std::vector<int> unit_scan(size_t(units), 0);
    for (size_t j = 0; j < gs.size(); ++j) unit_scan[size_t(unit[j])] = by_scan ? 0 : gs[j].scan;
    sh.blocks_per_part = by_scan ? (n + 1) / 2 : units / (2 * n);
    std::mt19937_64 rng(seed);
    std::vector<double> largest;
    std::vector<int> assign(static_cast<size_t>(units), 0);
    for (int p = 0; p < permutations; ++p) {
      for (int sc = 0; sc < (by_scan ? 1 : n); ++sc) {
        std::vector<int> mine;
        for (int u = 0; u < units; ++u)
          if (unit_scan[size_t(u)] == sc) mine.push_back(u);
        std::shuffle(mine.begin(), mine.end(), rng);
        const size_t half = (mine.size() + (p % 2)) / 2;  // odd counts: alternate the larger part
        for (size_t q = 0; q < mine.size(); ++q) assign[size_t(mine[q])] = q < half ? 0 : 1;
      }
      for (size_t j = 0; j < gs.size(); ++j) part[j] = char(assign[size_t(unit[j])]);
      const auto r = halvesOf(gs, part, scans);
      largest.push_back(*std::max_element(r.begin(), r.end()));
    }
    auto quantiles = [](std::vector<double> v, double& med, double& p90) {
      if (v.empty()) return;
      std::sort(v.begin(), v.end());
      med = v[v.size() / 2];
      p90 = v[std::min(v.size() - 1, size_t(0.9 * double(v.size())))];
    };
    quantiles(largest, sh.floor_median, sh.floor_p90);
    // The split's own spread: the same alternating pattern with its grid turned by every even
    // number of rows over one period (offset 0 is the split as used).
    if (!by_scan && permutations > 0) {
      std::vector<double> shifted;
      for (int o = 0; o < 2 * std::max(sp.kind == HoldoutSplit::kBlocks ? sp.block_rows : scans[0].azimuths / 4, 1); o += 2) {
        for (size_t j = 0; j < gs.size(); ++j) {
          const int az = scans[size_t(gs[j].scan)].azimuths;
          const int b = sp.kind == HoldoutSplit::kBlocks ? sp.block_rows : std::max(az / 4, 1);
          part[j] = char(((gs[j].row0 + o) % az / b) % 2);
        }
        const auto r = halvesOf(gs, part, scans);
        shifted.push_back(*std::max_element(r.begin(), r.end()));
      }
      quantiles(shifted, sh.offset_median, sh.offset_p90);
    }
    out.push_back(std::move(sh));
  }
  return out;
}

std::string splitSurveyMarkdown(const std::vector<SplitHalves>& rows) {
  std::ostringstream os;
  os << "| split | units per part (per scan for blocks) | real halves' largest difference "
        "(figure) | grid turned by 0..period rows: median / 90 % | same units assigned at "
        "random: median / 90 % | even = odd rows in every part |\n|---|---|---|---|---|---|\n";
  os.precision(3);
  for (const SplitHalves& s : rows) {
    os << "| " << s.split << " | " << s.blocks_per_part << " | " << 100 * s.largest << " % ("
       << s.largest_figure << ") | ";
    if (std::isnan(s.offset_median))
      os << "- | ";
    else
      os << 100 * s.offset_median << " / " << 100 * s.offset_p90 << " % | ";
    os << 100 * s.floor_median << " / " << 100 * s.floor_p90 << " % | "
       << (s.even_odd_balanced ? "yes" : "no") << " |\n";
  }
  os << "\nPer figure (|held out - fit| / fit, %):\n\n| split |";
  if (!rows.empty())
    for (const auto& f : rows.front().figures) os << " " << f.first << " |";
  os << "\n|---|";
  if (!rows.empty())
    for (size_t i = 0; i < rows.front().figures.size(); ++i) os << "---|";
  os << "\n";
  for (const SplitHalves& s : rows) {
    os << "| " << s.split << " |";
    for (const auto& f : s.figures) os << " " << 100 * f.second << " |";
    os << "\n";
  }
  return os.str();
}

}  // namespace spinradar::diagnose
