#include "spinradar/diagnose/feature_repeatability.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <stdexcept>
#include <unordered_map>

#include "spinradar/core/feature_frame.hpp"
#include "spinradar/core/stage_times.hpp"
#include "spinradar/features/feature_extractor.hpp"
#include "spinradar/features/matcher.hpp"

namespace spinradar::diagnose {

void RepeatabilityOptions::validate() const {
  if (max_gap < 1 || max_gap > 50) throw std::invalid_argument("max_gap must be 1..50, got " + std::to_string(max_gap));
  if (!(truth_radius > 0.0) || truth_radius > 10.0)
    throw std::invalid_argument("truth_radius must be in (0, 10] m, got " + std::to_string(truth_radius));
  if (weak_inliers < 0) throw std::invalid_argument("weak_inliers must be >= 0");
  for (size_t i = 0; i < band_edges.size(); ++i)
    if (!(band_edges[i] > (i ? band_edges[i - 1] : 0.0)))
      throw std::invalid_argument("band_edges must be positive and increasing");
}

namespace {

struct Frame {
  FeatureFrame f;
  std::vector<double> wx, wy;  ///< keypoints in the world, by the truth at their own times
  std::unordered_map<int64_t, std::vector<int>> grid;  ///< cells of truth_radius
};

int64_t cellKey(long cx, long cy) { return (static_cast<int64_t>(cx) << 32) ^ (cy & 0xffffffffLL); }

}  // namespace

struct RepeatabilityMeter::Impl {
  Impl(const PipelineConfig& c, sim::Trajectory t, RepeatabilityOptions o)
      : config(c), truth(std::move(t)), opt(std::move(o)), extractor(c.detector, c.features) {
    opt.validate();
    const size_t nb = opt.band_edges.size() + 1;
    sum.band_keypoints.assign(nb, 0.0);
    sum.gaps.resize(static_cast<size_t>(opt.max_gap));
    for (auto& g : sum.gaps) g.band_repeatable.assign(nb, 0.0), g.band_true.assign(nb, 0.0);
  }
  size_t band(double r) const {
    size_t b = 0;
    while (b < opt.band_edges.size() && r >= opt.band_edges[b]) ++b;
    return b;
  }
  long cell(double v) const { return static_cast<long>(std::floor(v / opt.truth_radius)); }
  /// Index of a keypoint of `k` within truth_radius of (x, y), or -1.
  int near(const Frame& k, double x, double y) const {
    const long cx = cell(x), cy = cell(y);
    for (long i = cx - 1; i <= cx + 1; ++i)
      for (long j = cy - 1; j <= cy + 1; ++j) {
        auto it = k.grid.find(cellKey(i, j));
        if (it == k.grid.end()) continue;
        for (int q : it->second)
          if (std::hypot(k.wx[q] - x, k.wy[q] - y) < opt.truth_radius) return q;
      }
    return -1;
  }
  PipelineConfig config;
  sim::Trajectory truth;
  RepeatabilityOptions opt;
  FeatureExtractor extractor;
  std::deque<Frame> history;
  std::vector<Match> matches;
  Repeatability sum;
  int weak[64] = {};
};

RepeatabilityMeter::RepeatabilityMeter(const PipelineConfig& config, sim::Trajectory truth,
                                       RepeatabilityOptions options)
    : impl_(new Impl(config, std::move(truth), std::move(options))) {}

RepeatabilityMeter::~RepeatabilityMeter() { delete impl_; }

void RepeatabilityMeter::add(const PolarScan& scan) {
  Impl& m = *impl_;
  Frame cur;
  StageTimes times;
  m.extractor.extract(scan, cur.f, &times);
  m.sum.feature_ms += times.detect_ms + times.cartesian_ms + times.describe_ms;
  m.sum.keypoints += static_cast<double>(cur.f.keypoints.size());
  ++m.sum.scans;
  for (const Keypoint& k : cur.f.keypoints) {
    const sim::Pose2 p = m.truth.at(1e-9 * static_cast<double>(k.stamp_ns));
    const double c = std::cos(p.yaw), s = std::sin(p.yaw);
    cur.wx.push_back(p.x + c * k.x - s * k.y);
    cur.wy.push_back(p.y + s * k.x + c * k.y);
    cur.grid[cellKey(m.cell(cur.wx.back()), m.cell(cur.wy.back()))].push_back(static_cast<int>(cur.wx.size()) - 1);
    m.sum.band_keypoints[m.band(k.range)] += 1.0;
  }
  for (int g = 1; g <= m.opt.max_gap && g <= static_cast<int>(m.history.size()); ++g) {
    const Frame& key = m.history[m.history.size() - static_cast<size_t>(g)];
    GapFigures& out = m.sum.gaps[static_cast<size_t>(g - 1)];
    // As the keyframe tracker matches: the older scan's descriptors against the newer's.
    matchDescriptors(key.f.descriptors, cur.f.descriptors, m.config.features.nndr, m.matches);
    out.matches += static_cast<double>(m.matches.size());
    int confirmed = 0;
    for (const Match& x : m.matches)
      if (std::hypot(cur.wx[x.i2] - key.wx[x.i1], cur.wy[x.i2] - key.wy[x.i1]) < m.opt.truth_radius) {
        ++confirmed;
        out.band_true[m.band(cur.f.keypoints[x.i2].range)] += 1.0;
      }
    out.true_matches += confirmed;
    for (size_t i = 0; i < cur.f.keypoints.size(); ++i)
      if (m.near(key, cur.wx[i], cur.wy[i]) >= 0) {
        out.repeatable += 1.0;
        out.band_repeatable[m.band(cur.f.keypoints[i].range)] += 1.0;
      }
    if (confirmed < m.opt.weak_inliers) ++m.weak[g - 1];
    ++out.pairs;
  }
  m.history.push_back(std::move(cur));
  if (static_cast<int>(m.history.size()) > m.opt.max_gap) m.history.pop_front();
}

Repeatability RepeatabilityMeter::result() const {
  const Impl& m = *impl_;
  Repeatability r = m.sum;
  const double n = std::max(1, r.scans);
  r.keypoints /= n;
  r.feature_ms /= n;
  for (double& v : r.band_keypoints) v /= n;
  for (size_t g = 0; g < r.gaps.size(); ++g) {
    GapFigures& x = r.gaps[g];
    const double p = std::max(1, x.pairs);
    x.repeatable /= p, x.matches /= p, x.true_matches /= p;
    x.weak_share = x.pairs ? m.weak[g] / p : 0.0;
    for (double& v : x.band_repeatable) v /= p;
    for (double& v : x.band_true) v /= p;
  }
  return r;
}

double trueShareBeyond(const GapFigures& g, size_t edge) {
  if (edge + 1 >= g.band_true.size())
    throw std::out_of_range("trueShareBeyond: edge " + std::to_string(edge) + " of " +
                            std::to_string(g.band_true.size()) + " bands");
  double all = 0, far = 0;
  for (size_t b = 0; b < g.band_true.size(); ++b) (b > edge ? far : all) += g.band_true[b];
  all += far;
  return all > 0 ? far / all : 0.0;
}

std::string repeatabilityTable(const Repeatability& r, const RepeatabilityOptions& o) {
  std::string s;
  char buf[256];
  std::snprintf(buf, sizeof buf, "%d scans, %.0f keypoints per scan, feature stage %.2f ms per scan\n\n", r.scans,
                r.keypoints, r.feature_ms);
  s += buf;
  s += "| gap | repeatable | matches | true | weak (< " + std::to_string(o.weak_inliers) +
       " true) | true by band | true beyond each edge (%) |\n|---|---|---|---|---|---|---|\n";
  for (size_t g = 0; g < r.gaps.size(); ++g) {
    const GapFigures& x = r.gaps[g];
    std::snprintf(buf, sizeof buf, "| %zu | %.0f | %.0f | %.0f | %.0f %% |", g + 1, x.repeatable, x.matches,
                  x.true_matches, 100.0 * x.weak_share);
    s += buf;
    for (double v : x.band_true) std::snprintf(buf, sizeof buf, " %.1f", v), s += buf;
    s += " |";
    for (size_t e = 0; e + 1 < x.band_true.size(); ++e)
      std::snprintf(buf, sizeof buf, " %.0f", 100.0 * trueShareBeyond(x, e)), s += buf;
    s += " |\n";
  }
  s += "\nrange bands (m):";
  for (size_t b = 0; b <= o.band_edges.size(); ++b) {
    std::snprintf(buf, sizeof buf, b == 0 ? " < %g" : b < o.band_edges.size() ? ", %g-%g" : ", > %g",
                  b == 0 ? o.band_edges[0] : o.band_edges[b - 1], b < o.band_edges.size() ? o.band_edges[b] : 0.0);
    s += buf;
  }
  s += "; keypoints per scan:";
  for (double v : r.band_keypoints) std::snprintf(buf, sizeof buf, " %.0f", v), s += buf;
  if (!r.gaps.empty()) {
    s += "; repeatable at gap " + std::to_string(r.gaps.size()) + ":";
    for (double v : r.gaps.back().band_repeatable) std::snprintf(buf, sizeof buf, " %.0f", v), s += buf;
  }
  s += "\n";
  return s;
}

}  // namespace spinradar::diagnose
