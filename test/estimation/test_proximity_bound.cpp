// The proximity anchors (src/estimation/proximity_bound.hpp): an anchor laid by a wide search
// decides a later query only with the grid's own answer. Random keyframe-like maps, anchors
// at random points, queries moved by random rigid motions of 0.1 mm to 16 cm (the ICP moves
// millimetres between its solves), at the tracker's gates; every
// decided query is checked against the grid and against a scan over every point.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "../../src/estimation/proximity_bound.hpp"
#include "support/brute_nearest.hpp"
#include "spinradar/estimation/nearest_point_grid.hpp"

using namespace spinradar;
using spinradar::testing::bruteNearest;

TEST(ProximityBound, HoldsOverRandomMotions) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-120.0, 120.0), unit(-1.0, 1.0);
  NearestPointGrid grid;
  int decided = 0, decided_hit = 0, decided_miss = 0, queries = 0;
  for (int map = 0; map < 4; ++map) {
    // Walls (dense along x) and clutter, with exact duplicates every 40 points.
    std::vector<Eigen::Vector2d> pts;
    for (int i = 0; i < 2500; ++i) {
      if (i % 2 == 0)
        pts.emplace_back(u(rng), 8.0 * (i % 7) + 0.2 * unit(rng));
      else
        pts.emplace_back(u(rng), u(rng));
      if (i % 40 == 0) pts.push_back(pts.back());
    }
    grid.build(pts);
    for (int k = 0; k < 3000; ++k) {
      const Eigen::Vector2d a0 = pts[static_cast<size_t>(k) % pts.size()] +
                                 Eigen::Vector2d(0.8 * unit(rng), 0.8 * unit(rng));
      const double radius = k % 3 == 0 ? 1.5 : 1.0;
      int wide = -1;
      double second2 = 0.0;
      grid.nearest(a0, std::min(radius, 0.6), radius, wide, second2);
      ASSERT_GE(second2, 0.0);
      const ProximityAnchor anchor{a0.x(), a0.y(), std::sqrt(second2), wide};
      // A rigid motion of the query about the map's origin, as a pose update moves it.
      const double scale = std::pow(10.0, -4.0 + 3.2 * (0.5 + 0.5 * unit(rng)));  // 1e-4..0.16
      const double th = 1e-3 * scale * unit(rng);
      const Eigen::Vector2d t(scale * unit(rng), scale * unit(rng));
      const Eigen::Vector2d q(std::cos(th) * a0.x() - std::sin(th) * a0.y() + t.x(),
                              std::sin(th) * a0.x() + std::cos(th) * a0.y() + t.y());
      for (const double gate : {0.3, 0.6, 1.5}) {
        const int got = boundedNearest(anchor, q, gate, pts);
        ++queries;
        if (got == kUndecided) continue;
        ASSERT_EQ(got, grid.nearest(q, gate)) << "map " << map << " query " << k << " gate " << gate;
        ASSERT_EQ(got, bruteNearest(pts, q, gate));
        ++decided;
        decided_hit += got >= 0;
        decided_miss += got < 0;
      }
    }
  }
  // The bound decides most queries, hits and misses both (else it would save nothing).
  EXPECT_GT(decided, queries / 2);
  EXPECT_GT(decided_hit, queries / 20);
  EXPECT_GT(decided_miss, queries / 20);
}

TEST(ProximityBound, NoAnchorAndNonFiniteQueriesAreUndecided) {
  const std::vector<Eigen::Vector2d> pts = {{0.0, 0.0}, {1.0, 0.0}};
  EXPECT_EQ(boundedNearest(ProximityAnchor{}, {0.0, 0.0}, 0.3, pts), kUndecided);
  const ProximityAnchor a{0.1, 0.0, 0.9, 0};
  EXPECT_EQ(boundedNearest(a, {0.1, 0.0}, 0.3, pts), 0);
  EXPECT_EQ(boundedNearest(a, {std::nan(""), 0.0}, 0.3, pts), kUndecided);
  // Halfway between the two points: the anchor cannot tell them apart.
  EXPECT_EQ(boundedNearest(a, {0.5, 0.0}, 0.6, pts), kUndecided);
}

// A query known only to within a slack (keyframe_proximity.cpp computes it with the series
// exponential first): decided, it is the grid's answer for the true query. A slack far above
// the tracker's (1e-13 m scale) so that its margins are what the test exercises; queries
// placed on the gate and half-way between points too.
TEST(ProximityBound, SlackQueriesGetTheTrueQuerysAnswer) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-60.0, 60.0), unit(-1.0, 1.0);
  NearestPointGrid grid;
  std::vector<Eigen::Vector2d> pts;
  for (int i = 0; i < 2000; ++i) pts.emplace_back(u(rng), i % 2 ? u(rng) : 4.0 * (i % 9) + 0.1 * unit(rng));
  grid.build(pts);
  int decided = 0, queries = 0, slack_only_undecided = 0;
  for (int k = 0; k < 20000; ++k) {
    const Eigen::Vector2d a0 = pts[static_cast<size_t>(k) % pts.size()] +
                               Eigen::Vector2d(0.7 * unit(rng), 0.7 * unit(rng));
    int wide = -1;
    double second2 = 0.0;
    grid.nearest(a0, 0.6, 1.0, wide, second2);
    const ProximityAnchor anchor{a0.x(), a0.y(), std::sqrt(second2), wide};
    const double gate = k % 2 ? 0.3 : 0.6;
    Eigen::Vector2d q = a0 + Eigen::Vector2d(0.05 * unit(rng), 0.05 * unit(rng));
    if (k % 5 == 0 && wide >= 0) {  // on the gate around the anchor's point
      const Eigen::Vector2d dir = (q - pts[static_cast<size_t>(wide)]).normalized();
      q = pts[static_cast<size_t>(wide)] + gate * dir;
    }
    const double slack = k % 3 == 0 ? 1e-3 : 1e-6;
    // The computed query: anywhere within the slack of the true one.
    const double ang = M_PI * unit(rng), len = slack * (0.5 + 0.5 * unit(rng));
    const Eigen::Vector2d qs = q + len * Eigen::Vector2d(std::cos(ang), std::sin(ang));
    const int got = boundedNearest(anchor, qs, gate, pts, slack);
    ++queries;
    if (got == kUndecided) {
      slack_only_undecided += boundedNearest(anchor, q, gate, pts) != kUndecided;
      continue;
    }
    ASSERT_EQ(got, grid.nearest(q, gate)) << "query " << k << " slack " << slack;
    ASSERT_EQ(got, bruteNearest(pts, q, gate));
    ++decided;
  }
  EXPECT_GT(decided, queries / 2);
  EXPECT_GT(slack_only_undecided, 0);  // the wider margins do leave some to the search
}
