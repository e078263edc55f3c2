// Localizer on synthetic keypoint frames (no simulator): a point world seen by a sensor that
// moves during the sweep (motion distortion) with Doppler-shifted ranges, map and live
// drives in opposite directions. Known truth, hand-made geometry.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "spinradar/core/lie.hpp"
#include "spinradar/localization/localizer.hpp"

namespace spinradar {
namespace {

constexpr double kBeta = 0.049;
constexpr double kPeriod = 0.25;  // s per rotation

std::vector<Eigen::Vector2d> world() {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> X(-100.0, 100.0), Y(-30.0, 30.0);
  std::vector<Eigen::Vector2d> w;
  for (int i = 0; i < 600; ++i) {
    Eigen::Vector2d p(X(rng), Y(rng));
    if (std::abs(p.y()) > 3.0) w.push_back(p);  // keep the road clear
  }
  for (double x = -100.0; x < 100.0; x += 0.6) {  // two facades
    w.emplace_back(x, 22.0 + 2.0 * std::sin(x / 9.0));
    w.emplace_back(x, -25.0 + 1.5 * std::cos(x / 7.0));
  }
  return w;
}

/// Keypoints of `w` seen during one rotation starting at t0 from pose T0 (world), moving with
/// body velocity v; each return at its own time, range shortened by beta * u.
LocFrame observe(const std::vector<Eigen::Vector2d>& w, const Eigen::Matrix3d& T0,
                 const Eigen::Vector3d& v, int64_t t0_ns) {
  LocFrame f;
  f.stamp_ns = t0_ns;
  for (const auto& pw : w) {
    double az = 0.0, dt = 0.0;
    Eigen::Vector2d ps;
    for (int it = 0; it < 4; ++it) {  // azimuth <-> time fixed point
      const Eigen::Matrix3d T = se2::inverse(T0 * se2::exp(dt * v));
      ps = T.topLeftCorner<2, 2>() * pw + T.topRightCorner<2, 1>();
      az = std::atan2(-ps.y(), ps.x());
      if (az < 0) az += 2 * M_PI;
      dt = az / (2 * M_PI) * kPeriod;
    }
    const double r = ps.norm();
    if (r < 3.0 || r > 80.0) continue;
    Keypoint k;
    k.azimuth = az;
    k.range = r - kBeta * (v(0) * std::cos(az) - v(1) * std::sin(az));
    k.x = k.range * std::cos(az);
    k.y = -k.range * std::sin(az);
    k.stamp_ns = t0_ns + static_cast<int64_t>(dt * 1e9);
    f.keypoints.push_back(k);
  }
  f.has_velocity = true;
  f.velocity_mc = f.velocity_doppler = v;
  RsdExtractor().compute(f.keypoints, f.rsd);
  return f;
}

double transError(const LocalizationResult& r, const Eigen::Matrix3d& T_true) {
  return se2::toXyYaw(se2::inverse(T_true) * r.T_map_sensor).head<2>().norm();
}

TEST(Localizer, ParsesCompensationAndValidates) {
  EXPECT_EQ(parseCompensation("none"), Compensation::None);
  EXPECT_EQ(parseCompensation("motion"), Compensation::Motion);
  EXPECT_EQ(parseCompensation("motion_doppler"), Compensation::MotionDoppler);
  EXPECT_THROW(parseCompensation("doppler"), std::invalid_argument);
  EXPECT_STREQ(compensationName(Compensation::MotionDoppler), "motion_doppler");
  LocalizerConfig c;
  c.loc_nndr = 2.0;
  try {
    Localizer loc(c);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("loc_nndr"), std::string::npos);
  }
  c = LocalizerConfig{};
  c.compensation = "full";
  EXPECT_THROW(Localizer{c}, std::invalid_argument);
}

TEST(Localizer, EmptyMapAndNearestFrame) {
  Localizer loc;
  EXPECT_EQ(loc.nearestMapFrame({0, 0}), -1);
  LocFrame live;
  LocalizationResult r = loc.localize(live, Eigen::Matrix3d::Identity(), Compensation::None);
  EXPECT_FALSE(r.ok);
  EXPECT_FALSE(r.reason.empty());
  for (double x : {0.0, 10.0, 20.0}) {
    LocFrame f;
    f.T_map_sensor = se2::fromXyYaw({x, 0.0, 0.0});
    loc.addMapFrame(f);
  }
  EXPECT_EQ(loc.nearestMapFrame({12.0, 3.0}), 1);
  EXPECT_EQ(loc.nearestMapFrame({100.0, 0.0}), 2);
  // Prior far from every map scan: refused with a reason, prior returned.
  const Eigen::Matrix3d far = se2::fromXyYaw({500.0, 0.0, 0.0});
  r = loc.localize(live, far, Compensation::None);
  EXPECT_FALSE(r.ok);
  EXPECT_TRUE(r.T_map_sensor.isApprox(far));
}

TEST(Localizer, CheckAgainstPriorRejectsJumps) {
  Localizer loc;
  LocalizationResult r;
  r.ok = true;
  r.T_map_prior = se2::fromXyYaw({10.0, 0.0, 0.0});
  r.T_map_sensor = se2::fromXyYaw({11.0, 0.5, 0.05});
  EXPECT_TRUE(loc.checkAgainstPrior(r));
  r.T_map_sensor = se2::fromXyYaw({30.0, 0.0, 0.0});
  EXPECT_FALSE(loc.checkAgainstPrior(r));
  EXPECT_FALSE(r.ok);
  EXPECT_TRUE(r.T_map_sensor.isApprox(r.T_map_prior));
  r.ok = true;
  r.T_map_sensor = se2::fromXyYaw({10.0, 0.0, 1.0});
  EXPECT_FALSE(loc.checkAgainstPrior(r));
}

TEST(Localizer, OppositeDirectionCompensationOrder) {
  // Map drive east at 15 m/s along y = -2; live drive west at 15 m/s along y = +2, 1.3 m
  // from the map scan along the road. Velocities are the true ones (set on the frames).
  const auto w = world();
  const Eigen::Vector3d v(15.0, 0.0, 0.0);
  const Eigen::Matrix3d T_map = se2::fromXyYaw({0.0, -2.0, 0.0});
  const Eigen::Matrix3d T_live = se2::fromXyYaw({1.3, 2.0, M_PI});
  Localizer loc;
  LocFrame map = observe(w, T_map, v, 1'000'000'000);
  map.T_map_sensor = T_map;
  loc.addMapFrame(map);
  loc.addMapFrame([&] {  // a second map scan farther along: must not be chosen
    LocFrame f = observe(w, se2::fromXyYaw({30.0, -2.0, 0.0}), v, 3'000'000'000);
    f.T_map_sensor = se2::fromXyYaw({30.0, -2.0, 0.0});
    return f;
  }());
  const LocFrame live = observe(w, T_live, v, 90'000'000'000);

  const LocalizationResult none = loc.localize(live, T_live, Compensation::None);
  const LocalizationResult mot = loc.localize(live, T_live, Compensation::Motion);
  const LocalizationResult dop = loc.localize(live, T_live, Compensation::MotionDoppler);
  ASSERT_TRUE(none.ok) << none.reason;
  ASSERT_TRUE(mot.ok) << mot.reason;
  ASSERT_TRUE(dop.ok) << dop.reason;
  EXPECT_EQ(dop.map_index, 0);
  EXPECT_TRUE(dop.velocity_known);
  const double en = transError(none, T_live), em = transError(mot, T_live), ed = transError(dop, T_live);
  std::printf("synthetic opposite drives: none %.3f m, motion %.3f m, motion+doppler %.3f m\n", en, em, ed);
  // Exact velocities, noise-free points: full compensation is essentially exact.
  EXPECT_LT(ed, 0.05);
  EXPECT_GT(em, 5 * ed);
  EXPECT_GT(en, em);
  // Relative pose agrees with the absolute one.
  EXPECT_TRUE((T_map * dop.T_mapscan_sensor).isApprox(dop.T_map_sensor, 1e-9));

  // A live scan without velocity is used raw (the map scan still compensated): flagged.
  LocFrame blind = live;
  blind.has_velocity = false;
  const LocalizationResult b = loc.localize(blind, T_live, Compensation::MotionDoppler);
  EXPECT_FALSE(b.velocity_known);
  ASSERT_TRUE(b.ok);
  EXPECT_GT(transError(b, T_live), 10 * ed);

  // Global localization without a prior finds the right map scan.
  const LocalizationResult g = loc.globalLocalize(live, Compensation::MotionDoppler);
  ASSERT_TRUE(g.ok);
  EXPECT_EQ(g.map_index, 0);
  EXPECT_LT(transError(g, T_live), 0.05);
}

}  // namespace
}  // namespace spinradar
