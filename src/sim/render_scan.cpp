// One rotation: per-azimuth timing and pose, occlusion depth map, scatterers bucketed by the
// azimuths whose beam can see them, then each row rendered sparsely (point spread of every
// visible scatterer) on top of a table-driven speckle noise floor.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "glint.hpp"
#include "render_geometry.hpp"
#include "height_rule.hpp"
#include "simulator_impl.hpp"

namespace spinradar::sim {

using detail::Scatterer;
using detail::ScanWork;

using detail::bearingCw;
using detail::kTwoPi;
using detail::pointSegmentDistance;
using detail::raySegment;
using detail::wrap2Pi;
using detail::wrapPi;

namespace {

constexpr int kDepthOversample = 8;
constexpr uint32_t kMoverBit = 1u << 31;

ScanWork& work() {
  thread_local ScanWork w;
  return w;
}

}  // namespace

void Simulator::Impl::render(double t0, uint64_t scan_key, PolarScan& out) const {
  const int N = sensor.azimuths, M = sensor.bins;
  const double period = 1.0 / sensor.rotation_hz;
  const double dt = period / N;
  const double az_step = kTwoPi / N;
  const double res = sensor.range_resolution;
  const double r_max = sensor.maxRange() + std::abs(physics.range_offset) + 1.0;
  ScanWork& w = work();
  for (auto* v : {&w.t_render, &w.px, &w.py, &w.cyaw, &w.syaw, &w.vx, &w.vy, &w.psi, &w.dop_sign})
    v->resize(N);
  out.resize(N, M);
  out.range_resolution = res;
  out.range_offset = 0.0;
  out.encoder_size = sensor.encoder_size;
  out.chirp_up.clear();
  if (fx.chirp_alternate) out.chirp_up.assign(N, 0);

  // ---- timing: true acquisition times (rotation jitter stretches the whole rotation) and the
  // stamps the sensor reports (nominal spacing, optional packet bursts, plus the offset).
  detail::Rng scan_rng(seed * 0x9E3779B97F4A7C15ull ^ scan_key);
  double stretch = 1.0 + fx.rotation_jitter * scan_rng.normal();
  const double t_fixed = fx.pose_at_start ? t0 : t0 + 0.5 * period * stretch;
  for (int a = 0; a < N; ++a) {
    double t_true = t0 + a * dt * stretch;
    double tr = physics.motion_distortion ? t_true : t_fixed;
    w.t_render[a] = tr;
    Pose2 p = traj.at(tr);
    w.px[a] = p.x;
    w.py[a] = p.y;
    w.cyaw[a] = std::cos(p.yaw);
    w.syaw[a] = std::sin(p.yaw);
    Eigen::Vector3d vb = traj.bodyVelocity(tr);
    w.vx[a] = w.cyaw[a] * vb.x() - w.syaw[a] * vb.y();
    w.vy[a] = w.syaw[a] * vb.x() + w.cyaw[a] * vb.y();
    int64_t enc = (int64_t(a) * sensor.encoder_size + N / 2) / N % sensor.encoder_size;
    double az_rep = enc * kTwoPi / sensor.encoder_size;
    out.encoder[a] = uint16_t(enc);
    out.azimuth[a] = az_rep;
    w.psi[a] = wrap2Pi(az_rep - physics.azimuth_offset - fx.encoder_wobble * std::sin(az_rep));
    if (fx.azimuth_jitter > 0) w.psi[a] = wrap2Pi(w.psi[a] + detail::azimuthJitter(fx, seed, scan_key, a));
    double stamp = t0 + a * dt;
    if (fx.bursts) {
      int first = a / fx.burst_size * fx.burst_size;
      int last = std::min(first + fx.burst_size - 1, N - 1);
      stamp = t0 + last * dt + fx.burst_delay + (a - first) * fx.burst_spacing;
    }
    out.stamp_ns[a] = std::llround((stamp + physics.timestamp_offset) * 1e9);
    bool up = !fx.chirp_alternate || (a % 2 == 0);
    if (fx.chirp_alternate) out.chirp_up[a] = up ? 1 : 0;
    w.dop_sign[a] = up ? 1.0 : -1.0;
  }
  const int a_mid = N / 2;
  const double mx = w.px[a_mid], my = w.py[a_mid];
  double travel = 0;
  for (int a = 0; a < N; a += 8) travel = std::max(travel, std::hypot(w.px[a] - mx, w.py[a] - my));
  travel = std::max({travel, std::hypot(w.px[0] - mx, w.py[0] - my),
                     std::hypot(w.px[N - 1] - mx, w.py[N - 1] - my)});
  // Glint (glint.hpp): the scattering centres move per scan; off: no draw, output unchanged.
  const detail::Glint glint_fx(fx, seed, scan_key, mx, my);
  auto glint = [&](uint32_t id, double& x, double& y) { glint_fx.apply(id, x, y); };
  const double inv_az_step = 1.0 / az_step;
  auto azOf = [&](double psi) {  // azimuth index whose true beam angle is nearest psi
    int a = int(std::floor((psi + physics.azimuth_offset) * inv_az_step + 0.5));
    a %= N;
    return a < 0 ? a + N : a;
  };

  // ---- occlusion: first wall along each fine angle, from the pose of the azimuth seeing it.
  // With heights (height_rule.hpp) every wall hit is kept, for the skyline of each angle.
  const int J = N * kDepthOversample;
  const double h_s = sensor.mount_height;
  w.depth.assign(J, 1e30);
  w.depth_wall.assign(J, -1);
  w.hits.clear();
  const int probe[5] = {0, N / 4, N / 2, 3 * N / 4, N - 1};
  for (size_t wi = 0; wi < world.walls.size(); ++wi) {
    const Wall& wl = world.walls[wi];
    if (pointSegmentDistance(mx, my, wl) > r_max + travel) continue;
    const double wall_h = wl.height ? *wl.height : std::numeric_limits<double>::infinity();
    double ref = bearingCw(wl.x1, wl.y1, mx, my, w.cyaw[a_mid], w.syaw[a_mid]);
    double lo = 0, hi = 0;
    for (int a : probe)
      for (int e = 0; e < 2; ++e) {
        double b = bearingCw(e ? wl.x2 : wl.x1, e ? wl.y2 : wl.y1, w.px[a], w.py[a], w.cyaw[a],
                             w.syaw[a]);
        double d = wrapPi(b - ref);
        lo = std::min(lo, d);
        hi = std::max(hi, d);
      }
    int j0, j1;
    if (hi - lo > M_PI - 0.05) {
      j0 = 0;
      j1 = J - 1;
    } else {
      j0 = int(std::floor((ref + lo) / kTwoPi * J)) - 2;
      j1 = int(std::ceil((ref + hi) / kTwoPi * J)) + 2;
    }
    for (int jj = j0; jj <= j1; ++jj) {
      int j = ((jj % J) + J) % J;
      double psi = (j + 0.5) * kTwoPi / J;
      int a = azOf(psi);
      // World direction of a clockwise sensor azimuth psi: yaw - psi.
      double c = depth_cos[j], s = depth_sin[j];
      double dxw = w.cyaw[a] * c + w.syaw[a] * s;   // cos(yaw - psi)
      double dyw = w.syaw[a] * c - w.cyaw[a] * s;   // sin(yaw - psi)
      double t = raySegment(w.px[a], w.py[a], dxw, dyw, wl);
      if (heights) {
        if (t > 0) w.hits.push_back({uint32_t(j), int32_t(wi), t, detail::topSlope(wall_h, h_s, t)});
      } else if (t > 0 && t < w.depth[j]) {
        w.depth[j] = t;
        w.depth_wall[j] = int32_t(wi);
      }
    }
  }

  const double tol = sensor.occlusion_tolerance;
  w.wall_seen.assign(world.walls.size(), 0);
  if (heights)  // a wall is rendered where its top shows over the walls in front
    detail::buildSkylines(w, J, w.wall_seen);
  for (int j = 0; j < J; ++j)
    if (w.depth_wall[j] >= 0) w.wall_seen[w.depth_wall[j]] = 1;

  // ---- bucket scatterers by the azimuths whose beam can reach them.
  w.pairs.clear();
  const double noise_mid = model.thresholdLin(std::min(M - 1, M / 2));
  const double r_cull = r_max + travel;
  auto bucket = [&](const Scatterer& sc, uint32_t id, double x, double y) {
    glint(id, x, y);
    double dx = x - mx, dy = y - my;
    double r2 = dx * dx + dy * dy;
    if (r2 > r_cull * r_cull || r2 < 0.0025) return;
    double r = std::sqrt(r2);
    // Textured clutter thinned by its density curve over range (grazing-angle visibility).
    if (sc.clutter_u >= 0 && sc.clutter_u >= sensor.clutterDensityX(r)) return;
    int b = std::clamp(int(r / res), 0, M - 1);
    double p = double(sc.rcs_lin) * model.rangeFactor(std::max(r - travel, 0.3));
    double thr = std::min<double>(model.thresholdLin(b), noise_mid);
    if (p <= thr) return;
    double half = model.beamHalfWidthForRatio(p / thr);
    // Crossing azimuth: fixed point of "beam angle at azimuth a = bearing from pose a".
    int a = azOf(bearingCw(x, y, mx, my, w.cyaw[a_mid], w.syaw[a_mid]));
    for (int it = 0; it < 2; ++it)
      a = azOf(bearingCw(x, y, w.px[a], w.py[a], w.cyaw[a], w.syaw[a]));
    // Skip scatterers hidden behind a wall from the crossing pose (with margin: the pose
    // moves a little across the beam pattern). Elevated ones are seen over the walls.
    if (sc.mirror < 0 && !sc.elevated) {
      double psi = bearingCw(x, y, w.px[a], w.py[a], w.cyaw[a], w.syaw[a]);
      double rr = std::hypot(x - w.px[a], y - w.py[a]);
      int j = std::min(J - 1, int(psi / kTwoPi * J));
      bool hidden = true;
      const double slope = heights ? detail::topSlope(sc.height, h_s, rr) : 0.0;
      for (int dj = -1; dj <= 1 && hidden; ++dj) {
        int jj = (j + dj + J) % J;
        if (heights ? detail::clearsWalls(w, jj, rr, slope, sc.wall, tol + 0.5)
                    : (w.depth_wall[jj] == sc.wall || rr <= w.depth[jj] + tol + 0.5))
          hidden = false;
      }
      if (hidden) return;
    }
    // Slack for the bearing change across the pattern when close and moving.
    double slack = (r > 1 ? travel / r * 0.1 : 0.5) + 4 * fx.azimuth_jitter;
    int K = int(std::ceil((half + slack) / az_step)) + 1;
    K = std::min(K, N / 2);
    for (int k = -K; k <= K; ++k) {
      int aa = ((a + k) % N + N) % N;
      w.pairs.push_back((uint64_t(aa) << 32) | id);
    }
  };
  w.candidates.clear();
  if (gnx > 0) {
    double rad = r_max + travel + cell;
    int cx0 = std::max(0, int((mx - rad - gx0) / cell)), cx1 = std::min(gnx - 1, int((mx + rad - gx0) / cell));
    int cy0 = std::max(0, int((my - rad - gy0) / cell)), cy1 = std::min(gny - 1, int((my + rad - gy0) / cell));
    for (int cy = cy0; cy <= cy1; ++cy)
      for (int cx = cx0; cx <= cx1; ++cx) {
        // Skip cells entirely outside the visible disc.
        double ex = std::max({gx0 + cx * cell - mx, mx - (gx0 + (cx + 1) * cell), 0.0});
        double ey = std::max({gy0 + cy * cell - my, my - (gy0 + (cy + 1) * cell), 0.0});
        if (ex * ex + ey * ey > r_cull * r_cull) continue;
        size_t c = size_t(cy) * gnx + cx;
        for (uint32_t k = cell_start[c]; k < cell_start[c + 1]; ++k) bucket(statics[k], k, statics[k].x, statics[k].y);
      }
  }
  // Wall scatterers: only walls that are the first hit somewhere (others are hidden).
  for (size_t wi = 0; wi < world.walls.size(); ++wi) {
    if (!w.wall_seen[wi]) continue;
    for (uint32_t k = wall_first[wi], e = k + wall_count[wi]; k < e; ++k)
      bucket(statics[k], k, statics[k].x, statics[k].y);
  }
  const double t_mid = w.t_render[a_mid];
  for (size_t i = 0; i < movers.size(); ++i) {
    const Scatterer& sc = movers[i];
    bucket(sc, uint32_t(i) | kMoverBit, sc.x + sc.vx * (t_mid - t_ref), sc.y + sc.vy * (t_mid - t_ref));
  }
  w.bucket_start.assign(N + 1, 0);
  for (uint64_t pr : w.pairs) ++w.bucket_start[(pr >> 32) + 1];
  for (int a = 0; a < N; ++a) w.bucket_start[a + 1] += w.bucket_start[a];
  w.bucket_items.resize(w.pairs.size());
  {
    // Reuse candidates as the fill cursor.
    w.candidates.assign(w.bucket_start.begin(), w.bucket_start.end() - 1);
    for (uint64_t pr : w.pairs) w.bucket_items[w.candidates[pr >> 32]++] = uint32_t(pr);
  }

  // ---- rows
  const int H = model.psfHalf();
  const double beta = physics.doppler;
  const double atten = fx.attenuation_db_per_km;
  const double inc_n = sensor.incidence_exponent;
  w.row.resize(M);
  w.level.resize(M);
  // Per-azimuth noise level: AR(1) across azimuths with the configured stationary std.
  const double row_rho = 0.6;
  const double row_innov = sensor.noise_row_jitter_db * std::sqrt(1 - row_rho * row_rho);
  double row_level = sensor.noise_row_jitter_db * scan_rng.normal();
  std::fill(w.row.begin(), w.row.end(), 0.f);
  const uint8_t* count_table = model.countTable();
  const int16_t* noise_q = model.noiseQData();
  for (int a = 0; a < N; ++a) {
    // Alternating chirps of unequal resolution: odd rows take their own point spread and speckle.
    const detail::RenderModel& rm = (a & 1) && model_odd ? *model_odd : model;
    const int16_t* speckle_q = rm.speckleQData();
    float* row = w.row.data();
    int lo = M, hi = -1;  // touched bins
    const double px = w.px[a], py = w.py[a], c = w.cyaw[a], s = w.syaw[a];
    const double psi_a = w.psi[a];
    const double t_a = w.t_render[a];
    const double bc = std::cos(psi_a), bsn = std::sin(psi_a);
    for (uint32_t k = w.bucket_start[a]; k < w.bucket_start[a + 1]; ++k) {
      uint32_t id = w.bucket_items[k];
      const bool mover = id & kMoverBit;
      const Scatterer& sc = mover ? movers[id & ~kMoverBit] : statics[id];
      double x = sc.x, y = sc.y;
      if (mover) {
        x += sc.vx * (t_a - t_ref);
        y += sc.vy * (t_a - t_ref);
      }
      glint(id, x, y);
      double dx = x - px, dy = y - py;
      double xs = c * dx + s * dy, ys = -s * dx + c * dy;
      // Along and across the beam (across > 0 = clockwise of it).
      double along = xs * bc - ys * bsn, across = -ys * bc - xs * bsn;
      if (along <= 0) continue;
      double tn = across / along;
      double delta = std::abs(tn) < 0.08 ? tn * (1.0 - tn * tn * (1.0 / 3.0)) : std::atan(tn);
      float g = model.beamGain(delta);
      if (g <= 0.f) continue;
      double r = std::sqrt(dx * dx + dy * dy);
      if (r < sensor.min_range || r > r_max) continue;
      double psi = psi_a + delta;
      if (psi < 0) psi += kTwoPi;
      if (psi >= kTwoPi) psi -= kTwoPi;
      int j = std::min(J - 1, int(psi * (J / kTwoPi)));
      if (sc.mirror >= 0) {
        // A ghost shows through its mirror wall only, and only if that hit is not occluded
        // (with heights: the mirror wall's top at the hit clears the walls in front).
        const Wall& mw = world.walls[sc.mirror];
        double th = raySegment(px, py, dx / r, dy / r, mw);
        if (th < 0) continue;
        if (heights) {
          const double mh = mw.height ? *mw.height : std::numeric_limits<double>::infinity();
          if (!detail::clearsWalls(w, j, th, detail::topSlope(mh, h_s, th), sc.mirror, tol)) continue;
        } else if (w.depth_wall[j] != sc.mirror && th > w.depth[j] + tol) {
          continue;
        }
      } else if (!sc.elevated) {
        const bool hidden =
            heights ? !detail::clearsWalls(w, j, r, detail::topSlope(sc.height, h_s, r), sc.wall, tol)
                    : (w.depth_wall[j] != sc.wall && r > w.depth[j] + tol);
        if (hidden) continue;
      }
      double p = double(sc.rcs_lin) * model.rangeFactor(r) * g;
      if (sc.wall >= 0) {
        double ci = std::abs(sc.nx * dx + sc.ny * dy) / r;
        p *= inc_n == 2.0 ? ci * ci : std::pow(ci, inc_n);
      }
      if (atten > 0) p *= std::pow(10.0, -atten * 2.0 * r / 1000.0 / 10.0);
      double ra = r;
      if (beta != 0) {
        double tvx = mover ? sc.vx : 0.0, tvy = mover ? sc.vy : 0.0;
        double u = ((w.vx[a] - tvx) * dx + (w.vy[a] - tvy) * dy) / r;  // closing speed
        ra -= w.dop_sign[a] * beta * u;
      }
      double xb = (ra + physics.range_offset) / res - 0.5;
      if (xb < -H || xb > M + H) continue;
      double fb = std::floor(xb);
      int b0 = int(fb);
      int phase = int((xb - fb) * detail::RenderModel::kPhases + 0.5);
      if (phase == detail::RenderModel::kPhases) {
        phase = 0;
        ++b0;
      }
      int bc = std::clamp(b0, 0, M - 1);
      float pf = float(p);
      float thr = model.thresholdLin(bc);
      if (pf < thr) continue;
      int h = rm.psfHalfFor(pf / thr);
      const float* taps = rm.psf(phase) + H;
      int k0 = std::max(-h, -b0), k1 = std::min(h, M - 1 - b0);
      if (k0 > k1) continue;
      for (int kk = k0; kk <= k1; ++kk) row[b0 + kk] += pf * taps[kk];
      lo = std::min(lo, b0 + k0);
      hi = std::max(hi, b0 + k1);
    }
    // Noise floor (range-correlated speckle, per-azimuth level jitter) everywhere; signal
    // cells add their power before the quantiser.
    detail::Rng rng(seed ^ detail::Rng::splitmix(scan_key * 1315423911ull + uint64_t(a)));
    // Start inside the table so that the row needs no wrap-around.
    const uint32_t start = uint32_t(rng.next() % uint64_t(detail::RenderModel::kSpeckleMask + 1 - M));
    row_level = row_rho * row_level + row_innov * rng.normal();
    const int dq = std::clamp(int(std::lround(row_level * 8.0)),
                              -detail::RenderModel::kMaxRowOffsetQ,
                              detail::RenderModel::kMaxRowOffsetQ);
    const float gain = float(std::pow(10.0, dq / 80.0));
    uint8_t* o = out.row(a);
    const uint8_t* table = count_table + dq;
    const int16_t* sq = speckle_q + start;
    int16_t* lvl = w.level.data();
    for (int b = 0; b < M; ++b) lvl[b] = int16_t(noise_q[b] + sq[b]);  // vectorises
    for (int b = 0; b < M; ++b) o[b] = table[lvl[b]];
    for (int b = std::max(lo, 0); b <= hi; ++b) {
      float sig = row[b];
      if (sig == 0.f) continue;
      uint32_t idx = start + uint32_t(b);
      o[b] = model.countOfLin(gain * model.noiseLin(b) * rm.speckleLin(idx) + sig);
      row[b] = 0.f;  // leave the row clean for the next azimuth
    }
  }
}

}  // namespace spinradar::sim
