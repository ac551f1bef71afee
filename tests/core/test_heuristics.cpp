#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include "core/test_support.hpp"
#include "vnsba/core/heuristics.hpp"

namespace vnsba::test {
namespace {

using core::density_weighted_heuristic;
using core::switching_distance;

TEST(Heuristics, OctileDistance) {
  // Within the step costs' quantization (relative 1e-8) of the Euclidean octile distance.
  EXPECT_NEAR(core::octile({0, 0}, {3, 1}), 2 + std::sqrt(2.0), 3e-8);
  EXPECT_EQ(core::octile({5, 5}, {5, 0}), 5.0);
  EXPECT_NEAR(core::octile({2, 2}, {0, 0}), 2 * std::sqrt(2.0), 3e-8);
}

TEST(Heuristics, EqualCostPathsGiveBitIdenticalCosts) {
  // Three straight and three diagonal steps in every order (20 orders): with the searches' step
  // costs one value, bit for bit, equal to the octile distance of the same displacement (so A*'s
  // f ties exactly between such nodes); with the raw sqrt(2), two different values.
  auto sums = [](double straight, double diagonal) {
    std::vector<double> steps = {straight, straight, straight, diagonal, diagonal, diagonal};
    std::sort(steps.begin(), steps.end());
    std::set<double> values;
    int orders = 0;
    do {
      double g = 0.0;
      for (double step : steps) g += step;
      values.insert(g);
      ++orders;
    } while (std::next_permutation(steps.begin(), steps.end()));
    EXPECT_EQ(orders, 20);
    return values;
  };
  const std::set<double> quantized =
      sums(core::detail::kStepCostStraight, core::detail::kStepCostDiagonal);
  ASSERT_EQ(quantized.size(), 1u);
  EXPECT_EQ(*quantized.begin(), core::octile({0, 0}, {6, 3}));
  EXPECT_GT(sums(1.0, std::sqrt(2.0)).size(), 1u);
}

TEST(Heuristics, EuclidWhenVisibleManhattanWhenNot) {
  // 5 x 5, a wall cell at (2,2) in the middle.
  auto map = GridMap::from_rows({".....", ".....", "..#..", ".....", "....."});
  ASSERT_TRUE(map);
  // (0,0) -> (4,4): the diagonal passes through the blocked centre: Manhattan.
  EXPECT_DOUBLE_EQ(switching_distance(*map, {0, 0}, {4, 4}, CornerPolicy::kNever), 8.0);
  // (0,0) -> (4,1): visible, although the rectangle holds no obstacle anyway.
  EXPECT_DOUBLE_EQ(switching_distance(*map, {0, 0}, {4, 1}, CornerPolicy::kNever), std::sqrt(17.0));
  // (1,4) -> (4,1): the segment passes exactly through the lattice corner (3,3), whose side
  // cells are (2,2) blocked and (3,3) free: no sight under `never`, sight under `touch`.
  EXPECT_DOUBLE_EQ(switching_distance(*map, {1, 4}, {4, 1}, CornerPolicy::kNever), 6.0);
  EXPECT_DOUBLE_EQ(switching_distance(*map, {1, 4}, {4, 1}, CornerPolicy::kTouch), std::sqrt(18.0));
  EXPECT_DOUBLE_EQ(switching_distance(*map, {1, 4}, {4, 1}, CornerPolicy::kAlways),
                   std::sqrt(18.0));
  // Axis-aligned pairs: both distances coincide, blocked or not.
  EXPECT_DOUBLE_EQ(switching_distance(*map, {0, 2}, {4, 2}, CornerPolicy::kNever), 4.0);
}

// A hand-computed example of h and f for VNS-BA* (docs/algorithm.md section 3).
TEST(Heuristics, VnsHeuristicHandComputed) {
  // 6 x 4 map (rows top first): blocked (2,1) and (3,1).
  auto map = GridMap::from_rows({"......", "......", "..##..", "......"});
  ASSERT_TRUE(map);
  const Cell n{1, 0}, opposite_current{4, 2}, opposite_start{5, 3};
  // Rectangle (1..4) x (0..2): 12 cells, 2 blocked -> rho = 1/6.
  EXPECT_DOUBLE_EQ(map->density(n, opposite_current), 2.0 / 12.0);
  // dist(n, oc): segment (1.5,0.5)->(4.5,2.5) crosses (2,1) -> Manhattan 3 + 2 = 5.
  // dist(n, os): segment (1.5,0.5)->(5.5,3.5): at x=2..3 y is 1.25..2 -> crosses (2,1): blocked,
  // Manhattan 4 + 3 = 7.
  const double p = 0.5 * 5.0 + 0.5 * 7.0;
  const double h = std::exp(1.0 / 6.0) * p;
  EXPECT_NEAR(density_weighted_heuristic(*map, n, opposite_current, opposite_start, 0.5, 0.5,
                                         CornerPolicy::kNever),
              h, 1e-12);
  // f = g + h for n reached from (0,0) by one orthogonal step (g = 1).
  EXPECT_NEAR(1.0 + density_weighted_heuristic(*map, n, opposite_current, opposite_start, 0.5, 0.5,
                                               CornerPolicy::kNever),
              1.0 + 6.0 * std::exp(1.0 / 6.0), 1e-12);
  // Weights: omega only, eta only.
  EXPECT_NEAR(density_weighted_heuristic(*map, n, opposite_current, opposite_start, 1.0, 0.0,
                                         CornerPolicy::kNever),
              std::exp(1.0 / 6.0) * 5.0, 1e-12);
  EXPECT_NEAR(density_weighted_heuristic(*map, n, opposite_current, opposite_start, 0.0, 1.0,
                                         CornerPolicy::kNever),
              std::exp(1.0 / 6.0) * 7.0, 1e-12);
  // An obstacle-free rectangle: rho = 0, Euclidean distances, no weight.
  const Cell m{0, 3}, oc2{3, 3};
  EXPECT_NEAR(
      density_weighted_heuristic(*map, m, oc2, opposite_start, 0.5, 0.5, CornerPolicy::kNever),
      0.5 * 3.0 + 0.5 * 5.0, 1e-12);
}

// The shortcuts inside switching_distance give the definition's value on random maps.
TEST(Heuristics, SwitchingDistanceMatchesDefinition) {
  std::mt19937 rng(21);
  for (int trial = 0; trial < 200; ++trial) {
    auto map = GridMap::from_rows(random_rows(rng, 17, 13, 0.3));
    ASSERT_TRUE(map);
    std::uniform_int_distribution<int> rx(0, 16), ry(0, 12);
    for (int q = 0; q < 30; ++q) {
      const Cell a{rx(rng), ry(rng)}, b{rx(rng), ry(rng)};
      if (map->blocked(a) || map->blocked(b)) continue;
      const double dx = std::abs(a.x - b.x), dy = std::abs(a.y - b.y);
      const double expected =
          reference_los_centres(*map, a, b, CornerPolicy::kNever) ? std::hypot(dx, dy) : dx + dy;
      ASSERT_DOUBLE_EQ(switching_distance(*map, a, b, CornerPolicy::kNever), expected);
    }
  }
}

}  // namespace
}  // namespace vnsba::test
