// NearestPointGrid (the keyframe map's proximity search): against a scan over every point,
// on random maps shaped like a scan (points to 150 m, clustered along walls, duplicated
// points for exact ties), at every gate the keyframe tracker uses; and the buffers are reused.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "support/brute_nearest.hpp"
#include "spinradar/estimation/nearest_point_grid.hpp"

using namespace spinradar;
using spinradar::testing::bruteNearest;

namespace {

std::vector<Eigen::Vector2d> scanLikeMap(std::mt19937& rng, int n) {
  std::uniform_real_distribution<double> u(-150.0, 150.0), wall(-1.0, 1.0);
  std::vector<Eigen::Vector2d> pts;
  for (int i = 0; i < n; ++i) {
    if (i % 3 == 0)
      pts.emplace_back(u(rng), 12.0 + 0.3 * wall(rng));  // a wall along x
    else
      pts.emplace_back(u(rng), u(rng));
    if (i % 50 == 0) pts.push_back(pts.back());  // an exact duplicate: a tie
  }
  return pts;
}

// Half the queries close to a map point (the tracker's case), half anywhere.
Eigen::Vector2d query(std::mt19937& rng, const std::vector<Eigen::Vector2d>& pts, int k) {
  std::uniform_real_distribution<double> u(-160.0, 160.0), near(-2.0, 2.0);
  return k % 2 ? pts[static_cast<size_t>(k) % pts.size()] + Eigen::Vector2d(near(rng), near(rng))
               : Eigen::Vector2d(u(rng), u(rng));
}

}  // namespace

TEST(NearestPointGrid, SameAnswerAsAScanOverEveryPoint) {
  std::mt19937 rng(7);
  NearestPointGrid grid;
  int found = 0, queries = 0;
  for (int map = 0; map < 5; ++map) {
    const std::vector<Eigen::Vector2d> pts = scanLikeMap(rng, 3000);
    grid.build(pts);
    for (int k = 0; k < 4000; ++k) {
      const Eigen::Vector2d q = query(rng, pts, k);
      for (const double gate : {0.3, 0.5, 0.6, 1.5, 2.0}) {
        const int want = bruteNearest(pts, q, gate);
        ASSERT_EQ(grid.nearest(q, gate), want) << "map " << map << " query " << k << " gate " << gate;
        found += want >= 0;
        ++queries;
      }
    }
    // A query on a duplicated point: distance 0 to both copies, the smaller index wins.
    ASSERT_EQ(grid.nearest(pts[1], 0.3), bruteNearest(pts, pts[1], 0.3));
  }
  EXPECT_GT(found, queries / 5);  // the comparison covered hits (23 %), not only misses
}

TEST(NearestPointGrid, EmptyNonFiniteAndWideMaps) {
  NearestPointGrid grid;
  grid.build({});
  EXPECT_TRUE(grid.empty());
  EXPECT_EQ(grid.nearest({0.0, 0.0}, 1.0), -1);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // Non-finite points are never returned; a y spread of 1e9 m widens the bands, still exact.
  const std::vector<Eigen::Vector2d> pts = {{nan, 1.0}, {0.0, 0.0}, {1.0, 1e9}, {0.2, 0.1}};
  grid.build(pts);
  EXPECT_EQ(grid.nearest({0.15, 0.1}, 0.3), 3);
  EXPECT_EQ(grid.nearest({1.0, 1e9 + 0.1}, 0.3), 2);
  EXPECT_EQ(grid.nearest({nan, 0.0}, 0.3), -1);
  EXPECT_EQ(grid.nearest({0.0, 0.0}, nan), -1);
  EXPECT_EQ(grid.nearest({0.0, -0.5}, 0.5), -1);  // at exactly the gate: not within it
}

// The x-cell directory (kCell): points on cell edges (integer x from the map's smallest),
// queries just either side of an edge and outside the map in x, and a map wide in x and in y
// at once, whose cells widen to keep the directory small: always the scan over every point.
TEST(NearestPointGrid, CellEdgesAndWideMapsInX) {
  NearestPointGrid grid;
  std::vector<Eigen::Vector2d> pts;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 5; ++j) pts.emplace_back(-20.0 + i * NearestPointGrid::kCell, 0.25 * j);
  grid.build(pts);
  int found = 0, queries = 0;
  for (int i = -2; i < 44; ++i)
    for (const double dx : {-1e-12, 0.0, 1e-12, 0.29, 0.5})
      for (const double gate : {0.3, 0.6, 1.5}) {
        const Eigen::Vector2d q(-20.0 + i * NearestPointGrid::kCell + dx, 0.4);
        const int want = bruteNearest(pts, q, gate);
        ASSERT_EQ(grid.nearest(q, gate), want) << "x " << q.x() << " gate " << gate;
        found += want >= 0;
        ++queries;
      }
  EXPECT_GT(found, queries / 2);
  // 2e5 m by 2e5 m with a dense cluster: bands x cells would be 4e10 at 1 m, so cells widen.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> wide(-1e5, 1e5), local(-5.0, 5.0);
  std::vector<Eigen::Vector2d> spread;
  for (int i = 0; i < 2000; ++i)
    spread.emplace_back(i % 2 ? wide(rng) : local(rng), i % 2 ? wide(rng) : local(rng));
  grid.build(spread);
  for (int k = 0; k < 2000; ++k) {
    const Eigen::Vector2d q(local(rng), local(rng));
    for (const double gate : {0.3, 1.5})
      ASSERT_EQ(grid.nearest(q, gate), bruteNearest(spread, q, gate)) << "query " << k;
  }
}

// nearest(q, gate, radius, wide, second2): the gate's answer as nearest(q, gate), and from the
// same pass the nearest within the radius and the second-nearest's squared distance (radius^2
// when there is none), all against a scan over every point (ties included).
TEST(NearestPointGrid, WiderRadiusGivesTheGatesAnswerAndABound) {
  std::mt19937 rng(11);
  NearestPointGrid grid;
  int bounded = 0, queries = 0;
  for (int map = 0; map < 4; ++map) {
    const std::vector<Eigen::Vector2d> pts = scanLikeMap(rng, 3000);
    grid.build(pts);
    for (int k = 0; k < 3000; ++k) {
      const Eigen::Vector2d q = query(rng, pts, k);
      for (const double gate : {0.3, 0.6, 1.5})
        for (const double radius : {gate, 1.0, 2.5}) {
          if (radius < gate) continue;
          int wide = -7;
          double second2 = -7.0;
          ASSERT_EQ(grid.nearest(q, gate, radius, wide, second2), bruteNearest(pts, q, gate))
              << "map " << map << " query " << k << " gate " << gate << " radius " << radius;
          ASSERT_EQ(wide, bruteNearest(pts, q, radius));
          double want2 = radius * radius;  // the second smallest squared distance under it
          for (size_t i = 0; i < pts.size(); ++i) {
            const double dx = pts[i].x() - q.x(), dy = pts[i].y() - q.y();
            if (static_cast<int>(i) != wide) want2 = std::min(want2, dx * dx + dy * dy);
          }
          ASSERT_EQ(second2, want2) << "map " << map << " query " << k << " radius " << radius;
          bounded += second2 < radius * radius;
          ++queries;
        }
    }
    // An exact duplicate: the second-nearest is the copy, at the same distance.
    int wide = -1;
    double second2 = -1.0;
    grid.nearest(pts[1], 0.3, 1.0, wide, second2);
    EXPECT_EQ(second2, 0.0);
  }
  EXPECT_GT(bounded, queries / 10);  // second-nearest points were found, not only the radius
  // Nothing searched (a non-finite query, an empty gate): no bound.
  int wide = 0;
  double second2 = 0.0;
  EXPECT_EQ(grid.nearest({std::numeric_limits<double>::quiet_NaN(), 0.0}, 0.3, 1.0, wide, second2), -1);
  EXPECT_EQ(wide, -1);
  EXPECT_LT(second2, 0.0);
}
