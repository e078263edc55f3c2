// The recording's own reference scene by deconvolution (AppearanceOptions::scene_clean,
// appearance_scene_clean.cpp). Known truth: a standing sensor records a diffuse target 0.6 m
// deep (a bush: 31 point scatterers along one ray) and a wall across the beam; re-simulated from
// the CLEAN scene with the recording's own sensor, the returns' range and azimuth widths come
// back within the stated tolerances, where the one-point scene (one scatterer per local maximum
// along the row) renders the bush with the model's point width. A point target stays one
// scatterer, and the held-out rows are never read.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>

#include "diagnose/appearance_fixtures.hpp"
#include "spinradar/diagnose/appearance.hpp"
#include "spinradar/sim/simulator.hpp"

namespace spinradar::diagnose {
namespace {

const sim::Trajectory& standing() {
  static const sim::Trajectory t({{0.0, {}}, {2.0, {}}});
  return t;
}

PolarScan render(const sim::World& w, const sim::SensorConfig& s, uint64_t seed) {
  return sim::Simulator(w, standing(), s, {}, seed).renderScan(0);
}

// Sensor frame: azimuth clockwise from forward.
sim::Target at(double range, double az_deg, double rcs) {
  const double a = az_deg * M_PI / 180.0;
  return {range * std::cos(a), -range * std::sin(a), rcs};
}

// Widths of the return around (range, azimuth): the bins whose strongest cell over the window's
// rows is within 6 dB of the window's peak, and the rows whose strongest cell over its bins is.
struct Widths {
  int bins = 0, rows = 0, peak = 0;
};
Widths widths(const PolarScan& scan, double range, double az_deg, double half_m, int half_rows,
              double per_db) {
  const int b_lo = std::max(0, int(scan.binOfRange(range - half_m)));
  const int b_hi = std::min(scan.bins - 1, int(scan.binOfRange(range + half_m)));
  const int r_c = int(std::lround(az_deg / 360.0 * scan.azimuths)) % scan.azimuths;
  Widths w;
  for (int d = -half_rows; d <= half_rows; ++d)
    for (int b = b_lo; b <= b_hi; ++b)
      w.peak = std::max(w.peak, int(scan.row((r_c + d + scan.azimuths) % scan.azimuths)[b]));
  const double cut = w.peak - 6.0 * per_db;
  for (int b = b_lo; b <= b_hi; ++b) {
    int best = 0;
    for (int d = -half_rows; d <= half_rows; ++d)
      best = std::max(best, int(scan.row((r_c + d + scan.azimuths) % scan.azimuths)[b]));
    w.bins += best >= cut;
  }
  for (int d = -half_rows; d <= half_rows; ++d) {
    const uint8_t* row = scan.row((r_c + d + scan.azimuths) % scan.azimuths);
    w.rows += *std::max_element(row + b_lo, row + b_hi + 1) >= cut;
  }
  return w;
}

struct Case {
  double range, az_deg, half_m;
  int half_rows;
};

TEST(AppearanceClean, ExtendedReturnsKeepTheirWidthWhereOnePointPerReturnDoesNot) {
  const sim::SensorConfig s = testing::hundredMetreSensor();
  sim::World truth;
  // The bush: 0.6 m deep (13.7 bins at 4.38 cm), a scatterer every 2 cm along one ray.
  for (int k = 0; k <= 30; ++k) truth.targets.push_back(at(30.0 + 0.02 * k, 60.0, 0.0));
  // A wall across the beam at 40 m, 8 m long (11.5 deg): wide in azimuth, a point in range.
  const double a0 = 195 * M_PI / 180, a1 = 206.5 * M_PI / 180;
  truth.walls.push_back({40 * std::cos(a0), -40 * std::sin(a0), 40 * std::cos(a1),
                         -40 * std::sin(a1), 5.0});
  const PolarScan rec = render(truth, s, 5);
  const Case bush{30.3, 60.0, 1.2, 6}, wall{40.0, 200.75, 1.0, 14};
  AppearanceOptions clean, peaks;
  clean.scene_clean = true;
  peaks.scene_clean = false;
  const sim::World w_clean = recordingWorld(rec, s, clean), w_peaks = recordingWorld(rec, s, peaks);
  const PolarScan sim_clean = render(w_clean, s, 6), sim_peaks = render(w_peaks, s, 6);
  for (const Case& c : {bush, wall}) {
    const Widths real = widths(rec, c.range, c.az_deg, c.half_m, c.half_rows, s.power_scale);
    const Widths cw = widths(sim_clean, c.range, c.az_deg, c.half_m, c.half_rows, s.power_scale);
    const Widths pw = widths(sim_peaks, c.range, c.az_deg, c.half_m, c.half_rows, s.power_scale);
    if (std::getenv("SPINRADAR_TEST_VERBOSE"))
      std::cerr << "at " << c.range << " m: real " << real.bins << " bins x " << real.rows
                << " rows (peak " << real.peak << "), CLEAN " << cw.bins << " x " << cw.rows
                << " (" << cw.peak << "), one point " << pw.bins << " x " << pw.rows << " ("
                << pw.peak << "); scatterers " << w_clean.targets.size() << " / "
                << w_peaks.targets.size() << "\n";
    // Tolerance: 15 % of the width or one bin / row (the row grid and the quantiser).
    EXPECT_NEAR(cw.bins, real.bins, std::max(1.0, 0.15 * real.bins)) << c.range;
    EXPECT_NEAR(cw.rows, real.rows, std::max(1.0, 0.15 * real.rows)) << c.range;
    EXPECT_NEAR(cw.peak, real.peak, 2.0 * s.power_scale) << c.range;  // 2 dB
    if (&c == &bush) {
      ASSERT_GT(real.bins, 14);  // the bush is wider than the model's point response
      // The contrast: one scatterer per local maximum renders the point width.
      EXPECT_LT(pw.bins, 0.7 * real.bins) << "one-point scene " << pw.bins;
    }
  }
}

TEST(AppearanceClean, PointTargetStaysOneScatterer) {
  const sim::SensorConfig s = testing::hundredMetreSensor();
  // Half a row between rows (22 deg: rows are 0.9 deg) and a quarter row off one.
  for (const double rcs : {0.0, 20.0})
    for (const double az : {22.0, 21.8}) {
    sim::World truth;
    truth.targets.push_back(az == 22.0 ? at(32.0, az, rcs) : sim::Target{30.0, -12.0, rcs});
    const PolarScan rec = render(truth, s, 7);
    AppearanceOptions opt;
    opt.scene_clean = true;
    const sim::World w = recordingWorld(rec, s, opt);
    ASSERT_FALSE(w.targets.empty());
    const auto best = std::max_element(w.targets.begin(), w.targets.end(),
                                       [](const auto& a, const auto& b) { return a.rcs < b.rcs; });
    EXPECT_NEAR(best->x, truth.targets[0].x, 0.3) << rcs;
    EXPECT_NEAR(best->y, truth.targets[0].y, 0.5) << rcs;
    EXPECT_NEAR(best->rcs, rcs, 3.0) << rcs;
    int strong = 0;
    for (const auto& t : w.targets) {
      strong += t.rcs > rcs - 20;
      if (std::getenv("SPINRADAR_TEST_VERBOSE") && t.rcs > rcs - 30)
        std::cerr << "scatterer " << std::hypot(t.x, t.y) << " m "
                  << std::atan2(-t.y, t.x) * 180 / M_PI << " deg " << t.rcs << " dBsm\n";
    }
    EXPECT_EQ(strong, 1) << rcs;
  }
}

TEST(AppearanceClean, HeldOutRowsAreNeverRead) {
  const sim::SensorConfig s = testing::hundredMetreSensor();
  sim::World truth;
  for (int k = 0; k <= 30; ++k) truth.targets.push_back(at(30.0 + 0.02 * k, 60.0, 0.0));
  std::vector<PolarScan> fit, holdout;
  splitHoldout({render(truth, s, 3)}, fit, holdout);
  ASSERT_EQ(fit.size(), 1u);
  PolarScan changed = fit[0];
  for (int r = 0; r < changed.azimuths; ++r)
    if (!changed.valid[r])
      for (int b = 100; b < changed.bins; b += 7) changed.row(r)[b] = 200;
  AppearanceOptions opt;
  opt.scene_clean = true;
  const sim::World a = recordingWorld(fit[0], s, opt), b = recordingWorld(changed, s, opt);
  EXPECT_GT(a.targets.size(), 5u);  // the bush is in the fit quarters, as several scatterers
  EXPECT_EQ(a.toJson(), b.toJson());
}

}  // namespace
}  // namespace spinradar::diagnose
