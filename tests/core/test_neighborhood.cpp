#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

#include "core/test_support.hpp"
#include "vnsba/core/neighborhood.hpp"

namespace vnsba::test {
namespace {

using core::generate_moves;
using core::MoveList;
using core::Neighborhood;

using Offsets = std::set<std::pair<int, int>>;

Offsets offsets_of(const MoveList& moves) {
  Offsets out;
  for (const auto& m : moves) out.insert({m.dx, m.dy});
  return out;
}

const Offsets kEight = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {-1, 1}, {1, -1}, {-1, -1}};

std::vector<std::string> open_rows(int size) {
  return std::vector<std::string>(size, std::string(size, '.'));
}

// The extra cells docs/algorithm.md section 2 lists for a guide direction, written out by hand.
Offsets expected_extras(int sx, int sy) {
  if (sx == 0 && sy == 0) return {};
  if (sy == 0) return {{2 * sx, -1}, {2 * sx, 0}, {2 * sx, 1}};
  if (sx == 0) return {{-1, 2 * sy}, {0, 2 * sy}, {1, 2 * sy}};
  return {{2 * sx, 0}, {2 * sx, sy}, {2 * sx, 2 * sy}, {sx, 2 * sy}, {0, 2 * sy}};
}

TEST(Neighborhood, EightElevenThirteenForAllDirections) {
  auto map = GridMap::from_rows(open_rows(9));
  ASSERT_TRUE(map);
  const Cell centre{4, 4};
  for (int sx = -1; sx <= 1; ++sx) {
    for (int sy = -1; sy <= 1; ++sy) {
      // Guides at several distances in the same direction give the same neighbourhood.
      for (int reach : {1, 3, 4}) {
        const Cell guide{centre.x + sx * reach, centre.y + sy * (reach == 3 ? 2 : reach)};
        const MoveList moves = generate_moves(
            *map, centre, guide, Neighborhood::kEightElevenThirteen, CornerPolicy::kNever);
        Offsets expected = kEight;
        for (auto e : expected_extras(sx, sy)) expected.insert(e);
        EXPECT_EQ(offsets_of(moves), expected) << "direction " << sx << "," << sy;
        const size_t size = (sx == 0 && sy == 0) ? 8 : (sx == 0 || sy == 0) ? 11 : 13;
        EXPECT_EQ(static_cast<size_t>(moves.count), size);
        for (const auto& m : moves) {
          // The Euclidean length, quantized to a multiple of 2^-26 cells (exact sums).
          const double length = std::hypot(m.dx, m.dy);
          EXPECT_NEAR(m.cost, length, 1e-8 * length) << int(m.dx) << "," << int(m.dy);
          const double quanta = m.cost * 67108864.0;
          EXPECT_EQ(quanta, std::round(quanta)) << int(m.dx) << "," << int(m.dy);
        }
      }
    }
  }
}

TEST(Neighborhood, EightOnlyWhenAskedForEight) {
  auto map = GridMap::from_rows(open_rows(7));
  ASSERT_TRUE(map);
  EXPECT_EQ(
      offsets_of(generate_moves(*map, {3, 3}, {6, 5}, Neighborhood::kEight, CornerPolicy::kNever)),
      kEight);
}

TEST(Neighborhood, FallsBackToEightNearObstaclesAndEdges) {
  // A blocked cell among the 8 neighbours: no extras, and the blocked one is missing.
  auto map = GridMap::from_rows(
      {".......", ".......", ".......", "....#..", ".......", ".......", "......."});
  ASSERT_TRUE(map);
  const Cell centre{3, 3};  // (4,3) is blocked: top row is y = 6, so "....#.." is y = 3
  ASSERT_TRUE(map->blocked(4, 3));
  const Offsets got = offsets_of(generate_moves(
      *map, centre, {6, 6}, Neighborhood::kEightElevenThirteen, CornerPolicy::kAlways));
  Offsets expected = kEight;
  expected.erase({1, 0});
  EXPECT_EQ(got, expected);
  // At the map edge some neighbours are outside: no extras either.
  auto open = GridMap::from_rows(open_rows(6));
  ASSERT_TRUE(open);
  const MoveList edge = generate_moves(*open, {0, 2}, {5, 2}, Neighborhood::kEightElevenThirteen,
                                       CornerPolicy::kNever);
  EXPECT_EQ(offsets_of(edge), (Offsets{{1, 0}, {0, 1}, {0, -1}, {1, 1}, {1, -1}}));
  // One step in from the edge all 8 are inside, so extras appear (pointing inward).
  EXPECT_EQ(generate_moves(*open, {1, 2}, {5, 2}, Neighborhood::kEightElevenThirteen,
                           CornerPolicy::kNever)
                .count,
            11);
}

TEST(Neighborhood, ExtraCellsMustBeFreeAndInside) {
  // Guide to the upper right; block the (2,1) extra and put the map edge under (0,2)-type cells.
  auto map = GridMap::from_rows({".....", ".....", "....#", ".....", "....."});
  ASSERT_TRUE(map);
  const Offsets got = offsets_of(generate_moves(
      *map, {2, 1}, {4, 4}, Neighborhood::kEightElevenThirteen, CornerPolicy::kNever));
  // (4,2) is blocked: the (2,1) extra is dropped; (2,2) needs both (2,1) and (1,2) free under
  // `never`, so it is dropped too; the others remain.
  Offsets expected = kEight;
  expected.insert({2, 0});
  expected.insert({1, 2});
  expected.insert({0, 2});
  EXPECT_EQ(got, expected);
  const Offsets touch = offsets_of(generate_moves(
      *map, {2, 1}, {4, 4}, Neighborhood::kEightElevenThirteen, CornerPolicy::kTouch));
  EXPECT_TRUE(touch.count({2, 2}));
}

TEST(Neighborhood, DiagonalsRespectCornerPolicy) {
  auto map = GridMap::from_rows({"...", "..#", "..."});  // (2,1) blocked: east of the centre
  ASSERT_TRUE(map);
  auto diagonals = [&](CornerPolicy p) {
    Offsets d;
    for (auto o : offsets_of(generate_moves(*map, {1, 1}, {1, 1}, Neighborhood::kEight, p)))
      if (o.first != 0 && o.second != 0) d.insert(o);
    return d;
  };
  EXPECT_EQ(diagonals(CornerPolicy::kNever), (Offsets{{-1, 1}, {-1, -1}}));
  EXPECT_EQ(diagonals(CornerPolicy::kTouch), (Offsets{{-1, 1}, {-1, -1}, {1, 1}, {1, -1}}));
}

// Every move generated on random maps, for every direction and policy, is collision-free: by the
// exact line-of-sight definition and by dense sampling, and 11/13 moves only cross cells of the
// 3 x 3 block around the node plus the destination.
TEST(Neighborhood, EveryMoveIsCollisionFree) {
  std::mt19937 rng(13);
  int extra_moves = 0;
  for (int trial = 0; trial < 64; ++trial) {
    auto map = GridMap::from_rows(random_rows(rng, 12, 12, 0.04 * (trial % 8)));
    ASSERT_TRUE(map);
    for (const Cell& from : free_cells(*map)) {
      for (int sx = -1; sx <= 1; ++sx) {
        for (int sy = -1; sy <= 1; ++sy) {
          for (CornerPolicy p :
               {CornerPolicy::kNever, CornerPolicy::kTouch, CornerPolicy::kAlways}) {
            const Cell guide{from.x + 5 * sx, from.y + 5 * sy};
            for (const auto& m :
                 generate_moves(*map, from, guide, Neighborhood::kEightElevenThirteen, p)) {
              const Cell to{from.x + m.dx, from.y + m.dy};
              ASSERT_TRUE(reference_los_centres(*map, from, to, p));
              ASSERT_TRUE(segment_clear_sampled(*map, core::cell_centre(from),
                                                core::cell_centre(to), p, 16));
              if (std::max(std::abs(m.dx), std::abs(m.dy)) == 2) {
                ++extra_moves;
                for (int k = 0; k <= 256; ++k) {
                  const Point2 q = core::cell_centre(from) +
                                   (core::cell_centre(to) - core::cell_centre(from)) * (k / 256.0);
                  // A sample exactly on a lattice corner belongs to no single cell; the corner's
                  // side cells are covered by the policy check above.
                  if (q.x() == std::floor(q.x()) && q.y() == std::floor(q.y())) continue;
                  const Cell c{static_cast<int>(std::floor(q.x())),
                               static_cast<int>(std::floor(q.y()))};
                  const bool in_block = std::abs(c.x - from.x) <= 1 && std::abs(c.y - from.y) <= 1;
                  ASSERT_TRUE(in_block || c == to);
                }
              }
            }
          }
        }
      }
    }
  }
  EXPECT_GT(extra_moves, 5000);
}

// The tolerance's reachability floods use the 8-neighbourhood alone (reachability.hpp): the
// 8-11-13 moves must reach no cell outside the 8-connected component of the cell they leave, for
// every guide direction and corner policy. Components by the tests' own breadth-first search.
TEST(Neighborhood, EightElevenThirteenReachesNothingEightConnectedMovesDoNot) {
  std::mt19937 rng(4242);
  int64_t long_moves = 0;
  for (int trial = 0; trial < 60; ++trial) {
    auto map = random_shared_map(rng, 24, 20, 0.05 + 0.4 * (trial % 5) / 4.0);
    ASSERT_TRUE(map);
    for (CornerPolicy policy : kAllCornerPolicies) {
      const auto labels = component_labels(*map, policy);
      auto label = [&](int32_t x, int32_t y) {
        return labels[static_cast<size_t>(y) * map->width() + x];
      };
      for (const Cell& from : free_cells(*map)) {
        for (int gx = -1; gx <= 1; ++gx) {
          for (int gy = -1; gy <= 1; ++gy) {
            const Cell guide{from.x + 5 * gx, from.y + 5 * gy};
            for (const auto& m :
                 generate_moves(*map, from, guide, Neighborhood::kEightElevenThirteen, policy)) {
              long_moves += std::max(std::abs(m.dx), std::abs(m.dy)) == 2;
              ASSERT_EQ(label(from.x + m.dx, from.y + m.dy), label(from.x, from.y))
                  << "(" << from.x << ", " << from.y << ") + (" << int{m.dx} << ", " << int{m.dy}
                  << ") leaves its 8-connected component under " << core::to_string(policy);
            }
          }
        }
      }
    }
  }
  EXPECT_GT(long_moves, 10000);
}

TEST(Neighborhood, NamesRoundTrip) {
  EXPECT_EQ(core::neighborhood_from_string("8"), Neighborhood::kEight);
  EXPECT_EQ(core::neighborhood_from_string("8-11-13"), Neighborhood::kEightElevenThirteen);
  EXPECT_FALSE(core::neighborhood_from_string("13"));
}

}  // namespace
}  // namespace vnsba::test
