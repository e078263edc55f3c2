// Spread of returns matched between consecutive scans (matched_spread.hpp).
#include "spinradar/diagnose/matched_spread.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>

namespace spinradar::diagnose {

namespace {

constexpr double kEdges[5] = {2.5, 10, 25, 50, 100};
constexpr double kHalf = 110.0;  // m, half size of the alignment grids

int bandOf(double r) {
  for (int k = 0; k < 4; ++k)
    if (r >= kEdges[k] && r < kEdges[k + 1]) return k;
  return -1;
}

Eigen::Matrix3d se2(double x, double y, double yaw) {
  Eigen::Matrix3d T = Eigen::Matrix3d::Identity();
  T(0, 0) = std::cos(yaw), T(0, 1) = -std::sin(yaw);
  T(1, 0) = std::sin(yaw), T(1, 1) = std::cos(yaw);
  T(0, 2) = x, T(1, 2) = y;
  return T;
}

Eigen::Vector2d apply(const Eigen::Matrix3d& T, const Eigen::Vector2d& p) {
  return T.topLeftCorner<2, 2>() * p + T.topRightCorner<2, 1>();
}

// Nearest-neighbour lookup over a fixed square grid of cell `cell` metres.
class PointGrid {
 public:
  PointGrid(const std::vector<Eigen::Vector2d>& pts, double cell) : pts_(pts), cell_(cell) {
    n_ = int(std::ceil(2 * kHalf / cell_));
    start_.assign(size_t(n_) * n_ + 1, 0);
    std::vector<int> c(pts.size());
    for (size_t i = 0; i < pts.size(); ++i) {
      c[i] = cellOf(pts[i]);
      if (c[i] >= 0) ++start_[c[i] + 1];
    }
    for (size_t k = 1; k < start_.size(); ++k) start_[k] += start_[k - 1];
    items_.resize(start_.back());
    std::vector<int> fill(start_.begin(), start_.end() - 1);
    for (size_t i = 0; i < pts.size(); ++i)
      if (c[i] >= 0) items_[fill[c[i]]++] = int(i);
  }
  /// Index of the nearest point within `gate`, or -1.
  int nearest(const Eigen::Vector2d& q, double gate) const {
    const int ix = int(std::floor((q.x() + kHalf) / cell_)), iy = int(std::floor((q.y() + kHalf) / cell_));
    const int reach = int(std::ceil(gate / cell_));
    int best = -1;
    double bd = gate * gate;
    for (int y = std::max(0, iy - reach); y <= std::min(n_ - 1, iy + reach); ++y)
      for (int x = std::max(0, ix - reach); x <= std::min(n_ - 1, ix + reach); ++x) {
        const size_t c = size_t(y) * n_ + x;
        for (int k = start_[c]; k < start_[c + 1]; ++k) {
          const double d = (pts_[items_[k]] - q).squaredNorm();
          if (d < bd) bd = d, best = items_[k];
        }
      }
    return best;
  }

 private:
  int cellOf(const Eigen::Vector2d& p) const {
    const int ix = int(std::floor((p.x() + kHalf) / cell_)), iy = int(std::floor((p.y() + kHalf) / cell_));
    if (ix < 0 || iy < 0 || ix >= n_ || iy >= n_) return -1;
    return iy * n_ + ix;
  }
  const std::vector<Eigen::Vector2d>& pts_;
  double cell_;
  int n_ = 0;
  std::vector<int> start_, items_;
};

double robustStd(std::vector<double> v) {
  if (v.size() < 2) return NAN;
  auto mid = v.begin() + v.size() / 2;
  std::nth_element(v.begin(), mid, v.end());
  const double med = *mid;
  for (double& x : v) x = std::abs(x - med);
  std::nth_element(v.begin(), mid, v.end());
  return 1.4826 * *mid;
}

// Standard error of the MAD-based std of n normal samples (asymptotic efficiency 0.37).
double madSe(double s, size_t n) { return n > 1 ? 1.167 * s / std::sqrt(double(n)) : NAN; }

// Scan b follows scan a directly (stride 1): later, and by at most 1.6 rotations when the row
// stamps give the rotation time (scans spread over a route, or masked copies of one scan, are no
// pair); with stride k > 1, by k - 0.6 to k + 0.6 rotations.
bool consecutive(const PolarScan& a, const PolarScan& b, int stride) {
  const int64_t gap = b.firstStamp() - a.firstStamp();
  if (gap <= 0) return false;
  const int64_t span = a.lastStamp() - a.firstStamp();
  if (span <= 0 || a.azimuths < 2) return true;
  const double rot = double(span) * a.azimuths / (a.azimuths - 1), k = std::max(stride, 1);
  return double(gap) <= (k + 0.6) * rot && (k == 1 || double(gap) >= (k - 0.6) * rot);
}

}  // namespace

std::vector<Eigen::Vector2d> spreadReturns(const PolarScan& scan, const SpreadOptions& opt) {
  std::vector<Eigen::Vector2d> out;
  const int N = scan.azimuths, M = scan.bins;
  if (N < 3 || M < 3) return out;
  auto validRow = [&](int a) { return scan.valid.empty() || scan.valid[a]; };
  // Threshold per band: the strongest keep_fraction of its cells.
  int thr[4];
  for (int k = 0; k < 4; ++k) {
    const int b0 = std::clamp(int(std::ceil(scan.binOfRange(std::max(kEdges[k], opt.min_range)))), 0, M);
    const int b1 = std::clamp(int(std::floor(scan.binOfRange(kEdges[k + 1]))), 0, M);
    long hist[256] = {0};
    long total = 0;
    for (int a = 0; a < N; ++a) {
      if (!validRow(a)) continue;
      const uint8_t* row = scan.row(a);
      for (int b = b0; b < b1; ++b) ++hist[row[b]], ++total;
    }
    long above = 0;
    int t = 255;
    while (t > 0 && above + hist[t] <= opt.keep_fraction * total) above += hist[t--];
    thr[k] = std::max(t + 1, 1);
  }
  const double az_step = 2 * M_PI / N;
  for (int a = 0; a < N; ++a) {
    if (!validRow(a)) continue;
    const int ap = (a + N - 1) % N, an = (a + 1) % N;
    const uint8_t* row = scan.row(a);
    const uint8_t* rp = validRow(ap) ? scan.row(ap) : nullptr;
    const uint8_t* rn = validRow(an) ? scan.row(an) : nullptr;
    for (int b = 2; b < M - 2; ++b) {
      const double r0 = scan.rangeOfBin(b);
      const int k = bandOf(r0);
      if (k < 0 || r0 < opt.min_range || row[b] < thr[k]) continue;
      const int v = row[b];
      // Local maximum over +-1 row and +-2 bins (ties: the first in scan order wins).
      bool peak = true;
      for (int db = -2; db <= 2 && peak; ++db) {
        if (db < 0 && row[b + db] >= v) peak = false;
        if (db > 0 && row[b + db] > v) peak = false;
        if (rp && rp[b + db] >= v) peak = false;
        if (rn && rn[b + db] > v) peak = false;
      }
      if (!peak) continue;
      // Sub-cell position: parabola through the log counts (a Gaussian peak is one).
      auto vertex = [](double l, double c, double r) {
        const double den = l - 2 * c + r;
        return den < 0 ? std::clamp(0.5 * (l - r) / den, -0.5, 0.5) : 0.0;
      };
      const double ob = vertex(row[b - 1], v, row[b + 1]);
      const double oa = rp && rn ? vertex(rp[b], v, rn[b]) : 0.0;
      const double r = scan.rangeOfBin(b + ob);
      const double phi = (scan.azimuth.size() == size_t(N) ? scan.azimuth[a] : a * az_step) + oa * az_step;
      out.emplace_back(r * std::cos(phi), -r * std::sin(phi));
    }
  }
  return out;
}

Eigen::Matrix3d alignReturns(const std::vector<Eigen::Vector2d>& a,
                             const std::vector<Eigen::Vector2d>& b, const Eigen::Matrix3d& init,
                             const SpreadOptions& opt) {
  if (a.size() < 3 || b.size() < 3) return init;
  // Coarse: occupancy of a (0.5 m cells, dilated by one cell), translations and yaws around
  // `init` scored by the share of b falling on it.
  const double cell = 0.5;
  const int n = int(std::ceil(2 * kHalf / cell));
  std::vector<uint8_t> occ(size_t(n) * n, 0);
  auto idx = [&](const Eigen::Vector2d& p) {
    const int ix = int(std::floor((p.x() + kHalf) / cell)), iy = int(std::floor((p.y() + kHalf) / cell));
    return (ix < 0 || iy < 0 || ix >= n || iy >= n) ? -1 : iy * n + ix;
  };
  for (const auto& p : a) {
    const int c = idx(p);
    if (c < 0) continue;
    const int cx = c % n, cy = c / n;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        if (cx + dx >= 0 && cx + dx < n && cy + dy >= 0 && cy + dy < n)
          occ[size_t(cy + dy) * n + cx + dx] = 1;
  }
  const double yaw0 = std::atan2(init(1, 0), init(0, 0)), x0 = init(0, 2), y0 = init(1, 2);
  const int ns = int(std::round(opt.search / cell));
  const int ny = int(std::round(opt.search_yaw_deg / 0.5));
  int best = -1;
  Eigen::Matrix3d T = init;
  for (int iy = -ny; iy <= ny; ++iy) {
    const double yaw = yaw0 + iy * 0.5 * M_PI / 180;
    const Eigen::Matrix2d R = se2(0, 0, yaw).topLeftCorner<2, 2>();
    std::vector<Eigen::Vector2d> rb(b.size());
    for (size_t i = 0; i < b.size(); ++i) rb[i] = R * b[i];
    for (int tx = -ns; tx <= ns; ++tx)
      for (int ty = -ns; ty <= ns; ++ty) {
        const Eigen::Vector2d t(x0 + tx * cell, y0 + ty * cell);
        int score = 0;
        for (const auto& q : rb) {
          const int c = idx(q + t);
          score += c >= 0 && occ[c];
        }
        if (score > best) best = score, T = se2(t.x(), t.y(), yaw);
      }
  }
  // Fine: point-to-point ICP with a gate shrinking to opt.gate.
  const PointGrid grid(a, 1.0);
  for (int it = 0; it < opt.icp_iterations; ++it) {
    const double gate = std::max(opt.gate, 1.5 - it * 0.1);
    Eigen::Vector2d ma = Eigen::Vector2d::Zero(), mb = Eigen::Vector2d::Zero();
    std::vector<std::pair<int, int>> m;
    for (size_t i = 0; i < b.size(); ++i) {
      const int j = grid.nearest(apply(T, b[i]), gate);
      if (j >= 0) m.emplace_back(j, int(i)), ma += a[j], mb += b[i];
    }
    if (m.size() < 3) break;
    ma /= double(m.size()), mb /= double(m.size());
    Eigen::Matrix2d H = Eigen::Matrix2d::Zero();
    for (auto [j, i] : m) H += (b[i] - mb) * (a[j] - ma).transpose();
    const double yaw = std::atan2(H(0, 1) - H(1, 0), H(0, 0) + H(1, 1));
    const Eigen::Matrix2d R = se2(0, 0, yaw).topLeftCorner<2, 2>();
    const Eigen::Vector2d t = ma - R * mb;
    const Eigen::Matrix3d Tn = se2(t.x(), t.y(), yaw);
    const double change = (Tn - T).cwiseAbs().maxCoeff();
    T = Tn;
    if (change < 1e-6 && gate <= opt.gate) break;
  }
  return T;
}

MatchedSpread measureMatchedSpread(const std::vector<PolarScan>& scans,
                                   const std::vector<Eigen::Matrix3d>* motions,
                                   const SpreadOptions& opt) {
  if (motions && motions->size() + 1 != scans.size() && !scans.empty())
    throw std::invalid_argument("matched spread: " + std::to_string(motions->size()) +
                                " motions for " + std::to_string(scans.size()) + " scans");
  MatchedSpread out;
  std::vector<std::vector<Eigen::Vector2d>> ret(scans.size());
  long total = 0;
  for (size_t i = 0; i < scans.size(); ++i) total += (ret[i] = spreadReturns(scans[i], opt)).size();
  out.returns = scans.empty() ? 0 : int(total / long(scans.size()));
  std::array<std::vector<double>, 4> et, er;
  std::array<double, 4> rsum{};
  double rall = 0;
  std::vector<double> all_t, all_r;
  Eigen::Matrix3d prev = Eigen::Matrix3d::Identity();
  for (size_t i = 0; i + 1 < scans.size(); ++i) {
    if (!consecutive(scans[i], scans[i + 1], opt.stride)) continue;
    const auto &a = ret[i], &b = ret[i + 1];
    const Eigen::Matrix3d T = motions ? (*motions)[i] : alignReturns(a, b, prev, opt);
    prev = T;
    out.motions.push_back(T);
    std::vector<Eigen::Vector2d> tb(b.size());
    for (size_t k = 0; k < b.size(); ++k) tb[k] = apply(T, b[k]);
    const PointGrid ga(a, 1.0), gb(tb, 1.0);
    std::vector<double> pair_t;
    for (size_t j = 0; j < a.size(); ++j) {
      const int k = gb.nearest(a[j], opt.gate);
      if (k < 0 || ga.nearest(tb[k], opt.gate) != int(j)) continue;  // mutual only
      const double r = a[j].norm();
      const int band = bandOf(r);
      if (band < 0) continue;
      const Eigen::Vector2d u = a[j] / r, e = tb[k] - a[j];
      const double rad = e.dot(u), tan = e.x() * -u.y() + e.y() * u.x();
      et[band].push_back(tan), er[band].push_back(rad);
      rsum[band] += r, rall += r;
      all_t.push_back(tan), all_r.push_back(rad), pair_t.push_back(tan);
    }
    out.pair_tangential.push_back(robustStd(pair_t));
    ++out.pairs;
  }
  auto fill = [](SpreadBand& s, const std::vector<double>& t, const std::vector<double>& r) {
    s.matches = int(t.size());
    s.tangential = robustStd(t), s.radial = robustStd(r);
    s.tangential_se = madSe(s.tangential, t.size()), s.radial_se = madSe(s.radial, r.size());
  };
  for (int k = 0; k < 4; ++k) {
    fill(out.band[k], et[k], er[k]);
    out.band[k].range = et[k].empty() ? 0 : rsum[k] / double(et[k].size());
  }
  fill(out.all, all_t, all_r);
  out.all.range = all_t.empty() ? 0 : rall / double(all_t.size());
  // Matches of one scene are not independent: the pairs' own scatter when there are enough.
  std::vector<double> pt;
  for (double x : out.pair_tangential)
    if (std::isfinite(x)) pt.push_back(x);
  if (pt.size() >= 3) {
    double m = 0, ss = 0;
    for (double x : pt) m += x;
    m /= pt.size();
    for (double x : pt) ss += (x - m) * (x - m);
    out.all.tangential_se = std::max(out.all.tangential_se, std::sqrt(ss / (pt.size() - 1) / pt.size()));
  }
  return out;
}

void writeSpreadTableHeader(std::ostream& os) {
  os << "| spread across / along the beam, m | 2.5-10 m | 10-25 m | 25-50 m | 50-100 m | all |\n"
        "|---|---|---|---|---|---|\n";
}

void writeSpreadTableRow(std::ostream& os, const std::string& name, const MatchedSpread& m) {
  os << "| " << name << " (" << m.pairs << " pairs) |";
  for (const auto& b : m.band) os << " " << b.tangential << " / " << b.radial << " |";
  os << " " << m.all.tangential << " +- " << m.all.tangential_se << " / " << m.all.radial << " |\n";
}

}  // namespace spinradar::diagnose
