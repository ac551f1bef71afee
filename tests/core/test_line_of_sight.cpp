#include <gtest/gtest.h>

#include <random>

#include "core/test_support.hpp"
#include "vnsba/core/line_of_sight.hpp"

namespace vnsba::test {
namespace {

using core::line_of_sight;

const CornerPolicy kPolicies[] = {CornerPolicy::kNever, CornerPolicy::kTouch,
                                  CornerPolicy::kAlways};

TEST(LineOfSight, DiagonalCornerFollowsPolicy) {
  // (0,0) -> (1,1) passes the corner shared with the two blocked/free side cells.
  auto one_side = GridMap::from_rows({"#.", ".."});  // (0,1) blocked
  auto both = GridMap::from_rows({"#.", ".#"});      // (0,1) and (1,0) blocked
  ASSERT_TRUE(one_side && both);
  EXPECT_FALSE(line_of_sight(*one_side, Cell{0, 0}, Cell{1, 1}, CornerPolicy::kNever));
  EXPECT_TRUE(line_of_sight(*one_side, Cell{0, 0}, Cell{1, 1}, CornerPolicy::kTouch));
  EXPECT_TRUE(line_of_sight(*one_side, Cell{0, 0}, Cell{1, 1}, CornerPolicy::kAlways));
  EXPECT_FALSE(line_of_sight(*both, Cell{0, 0}, Cell{1, 1}, CornerPolicy::kTouch));
  EXPECT_TRUE(line_of_sight(*both, Cell{0, 0}, Cell{1, 1}, CornerPolicy::kAlways));
}

TEST(LineOfSight, BlockedEndpointsAndOutsideFail) {
  auto map = GridMap::from_rows({"...", ".#.", "..."});
  ASSERT_TRUE(map);
  EXPECT_FALSE(line_of_sight(*map, Cell{1, 1}, Cell{0, 0}, CornerPolicy::kAlways));
  EXPECT_FALSE(line_of_sight(*map, Cell{0, 0}, Cell{1, 1}, CornerPolicy::kAlways));
  EXPECT_FALSE(line_of_sight(*map, Cell{0, 0}, Cell{3, 0}, CornerPolicy::kAlways));
  EXPECT_FALSE(line_of_sight(*map, Point2(-0.5, 0.5), Point2(0.5, 0.5), CornerPolicy::kAlways));
  EXPECT_FALSE(line_of_sight(*map, Point2(0.5, 0.5), Point2(NAN, 0.5), CornerPolicy::kAlways));
  EXPECT_TRUE(line_of_sight(*map, Cell{0, 0}, Cell{2, 0}, CornerPolicy::kNever));
  EXPECT_FALSE(line_of_sight(*map, Cell{0, 1}, Cell{2, 1}, CornerPolicy::kAlways));
  EXPECT_TRUE(line_of_sight(*map, Cell{2, 2}, Cell{2, 2}, CornerPolicy::kNever));
}

// Thin slopes clip cells only slightly; a supercover must still see those cells.
TEST(LineOfSight, SeesCellsClippedNearTheirCorner) {
  // Segment (0,0)->(9,1) crosses row boundary y=1 at x=4.5+0.5... compare with the reference.
  auto map = GridMap::from_rows({"....#.....", ".........."});
  ASSERT_TRUE(map);
  for (CornerPolicy p : kPolicies)
    EXPECT_EQ(line_of_sight(*map, Cell{0, 0}, Cell{9, 1}, p),
              reference_los_centres(*map, Cell{0, 0}, Cell{9, 1}, p));
}

// Cell-centre line of sight equals the exact definition on random maps, for every policy, in
// both directions (symmetry), and the summed-area shortcuts change nothing.
TEST(LineOfSight, CentresMatchExactDefinitionOnRandomMaps) {
  std::mt19937 rng(3);
  int agreed_true = 0, agreed_false = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const int w = 2 + trial % 29, h = 2 + (trial * 5) % 23;
    auto map = GridMap::from_rows(random_rows(rng, w, h, 0.05 + 0.4 * (trial % 7) / 7.0));
    ASSERT_TRUE(map);
    std::uniform_int_distribution<int> rx(0, w - 1), ry(0, h - 1);
    for (int q = 0; q < 60; ++q) {
      const Cell a{rx(rng), ry(rng)}, b{rx(rng), ry(rng)};
      for (CornerPolicy p : kPolicies) {
        const bool expected = reference_los_centres(*map, a, b, p);
        ASSERT_EQ(line_of_sight(*map, a, b, p), expected)
            << "trial " << trial << " a=" << a.x << "," << a.y << " b=" << b.x << "," << b.y
            << " policy " << core::to_string(p);
        ASSERT_EQ(line_of_sight(*map, core::cell_centre(a), core::cell_centre(b), p), expected);
        ASSERT_EQ(line_of_sight(*map, b, a, p), expected);
        (expected ? agreed_true : agreed_false)++;
      }
    }
  }
  // Both outcomes must have been exercised for the comparison to mean anything.
  EXPECT_GT(agreed_true, 1000);
  EXPECT_GT(agreed_false, 1000);
}

// For arbitrary real end points: whenever line of sight holds, dense sampling finds no blocked
// cell (soundness; sampling may miss tiny clips, so only this direction is exact).
TEST(LineOfSight, ContinuousSegmentsAreSound) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 200; ++trial) {
    const int w = 3 + trial % 20, h = 3 + (trial * 3) % 17;
    auto map = GridMap::from_rows(random_rows(rng, w, h, 0.25));
    ASSERT_TRUE(map);
    std::uniform_real_distribution<double> ux(0.0, w), uy(0.0, h);
    for (int q = 0; q < 50; ++q) {
      const Point2 a(ux(rng), uy(rng)), b(ux(rng), uy(rng));
      for (CornerPolicy p : kPolicies) {
        if (line_of_sight(*map, a, b, p)) {
          ASSERT_TRUE(segment_clear_sampled(*map, a, b, CornerPolicy::kAlways, 256))
              << a.transpose() << " -> " << b.transpose();
        }
      }
    }
  }
}

TEST(CornerPolicy, NamesRoundTrip) {
  for (CornerPolicy p : kPolicies)
    EXPECT_EQ(core::corner_policy_from_string(core::to_string(p)), p);
  EXPECT_FALSE(core::corner_policy_from_string("sometimes"));
}

}  // namespace
}  // namespace vnsba::test
