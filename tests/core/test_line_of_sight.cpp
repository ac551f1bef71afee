#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <random>
#include <string>
#include <vector>

#include "core/scalar_line_of_sight.hpp"
#include "core/test_support.hpp"
#include "vnsba/core/line_of_sight.hpp"

namespace vnsba::test {
namespace {

using core::line_of_sight;
using core::detail::centre_segment_clear;
using test_oracle::line_of_sight_centres_scalar;
using test_oracle::line_of_sight_scalar;
using test_oracle::max_cost_along_scalar;

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

// --- The bit-grid walk between cell centres (centre_segment_clear) against the scalar
// supercover traversal it replaced, which stays the definition (core/scalar_line_of_sight.hpp). ---

// A segment through an exact corner, row 0 -> row 1 across a word boundary: (0,0) -> (199,1)
// crosses the row boundary at x = 0.5 + 199/2 = 100 exactly, so the open spans are row 0
// cells 0..99 and row 1 cells 100..199, and the corner's side cells are (100,0) and (99,1).
TEST(LineOfSight, LongSegmentThroughACornerAcrossWords) {
  auto expect = [](const std::vector<Cell>& blocked, bool never, bool touch, bool always) {
    for (bool steep : {false, true}) {
      std::vector<std::string> rows = steep ? std::vector<std::string>(200, "..")
                                            : std::vector<std::string>(2, std::string(200, '.'));
      auto put = [&](Cell c) { return steep ? Cell{c.y, c.x} : c; };  // transposed map
      for (Cell c : blocked) {
        const Cell t = put(c);
        rows[rows.size() - 1 - t.y][t.x] = '#';
      }
      auto map = GridMap::from_rows(rows);
      ASSERT_TRUE(map);
      const Cell a = put({0, 0}), b = put({199, 1});
      const bool want[3] = {never, touch, always};
      for (int i = 0; i < 3; ++i) {
        for (auto [from, to] : {std::pair{a, b}, std::pair{b, a}}) {
          EXPECT_EQ(line_of_sight(*map, from, to, kPolicies[i]), want[i])
              << "steep " << steep << " policy " << core::to_string(kPolicies[i]);
          EXPECT_EQ(line_of_sight_centres_scalar(*map, from, to, kPolicies[i]), want[i]);
        }
      }
    }
  };
  expect({}, true, true, true);
  expect({{100, 0}}, false, true, true);            // one side of the corner
  expect({{99, 1}}, false, true, true);             // the other side
  expect({{100, 0}, {99, 1}}, false, false, true);  // both sides
  for (int x : {1, 62, 63, 64, 65, 99}) expect({{x, 0}}, false, false, false);    // row 0's span
  for (int x : {100, 127, 128, 129, 198}) expect({{x, 1}}, false, false, false);  // row 1's
  expect({{101, 0}, {98, 1}, {150, 0}, {50, 1}}, true, true, true);  // beside the spans
}

// Spans around the widest one 8-byte load covers (57 cells from any start within a byte) and
// just past it, where the word loop takes over: a single blocked cell at every position of a
// 200 x 4 map, against segments whose middle lines have 54..60 cells each, starting at every
// offset within a byte, upwards and downwards.
TEST(LineOfSight, SpansAroundOneLoadWideSeeEveryCell) {
  int64_t compared = 0, blocked = 0;
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 200; ++x) {
      std::vector<std::string> rows(4, std::string(200, '.'));
      rows[3 - y][x] = '#';
      auto map = GridMap::from_rows(rows);
      ASSERT_TRUE(map);
      for (int n : {2, 3}) {
        for (int du = 54 * n; du <= 60 * n; ++du) {
          for (int u0 = 0; u0 < 8; ++u0) {
            for (bool up : {true, false}) {
              const Cell a{u0, up ? 0 : n}, b{u0 + du, up ? n : 0};
              for (CornerPolicy p : kPolicies) {
                const bool expected = line_of_sight_centres_scalar(*map, a, b, p);
                ASSERT_EQ(centre_segment_clear(*map, a, b, p), expected)
                    << "blocked " << x << "," << y << " a=" << a.x << "," << a.y << " b=" << b.x
                    << "," << b.y << " policy " << core::to_string(p);
                ++compared;
                blocked += !expected;
              }
            }
          }
        }
      }
    }
  }
  EXPECT_GT(blocked, compared / 20);
}

// Slopes -1/3, -3, -3/5 and -5/3 (down-right and up-left), each passing lattice corners: the
// answers are those of the exact definition.
TEST(LineOfSight, SmallSlopesThroughCornersMatchTheDefinition) {
  std::mt19937 rng(17);
  const std::array<Cell, 4> steps = {Cell{3, -1}, Cell{-5, 3}, Cell{1, -3}, Cell{-3, 5}};
  for (int trial = 0; trial < 400; ++trial) {
    auto map = GridMap::from_rows(random_rows(rng, 16, 16, 0.15));
    ASSERT_TRUE(map);
    const Cell step = steps[trial % 4];
    const Cell a{step.x < 0 ? 15 : 0, step.y < 0 ? 15 : 0};
    for (int m = 1; m <= 3; ++m) {
      const Cell b{a.x + m * step.x, a.y + m * step.y};
      for (CornerPolicy p : kPolicies)
        ASSERT_EQ(line_of_sight(*map, a, b, p), reference_los_centres(*map, a, b, p));
    }
  }
}

// A random map for the comparisons below: independent cells blocked with probability
// `density`, or, for `rooms`, free space cut by random blocked rectangles (long clear segments
// next to obstacles, where long walks end late).
GridMap random_test_map(std::mt19937& rng, int width, int height, double density, bool rooms) {
  std::vector<std::string> rows;
  if (!rooms) {
    rows = random_rows(rng, width, height, density);
  } else {
    rows.assign(height, std::string(width, '.'));
    std::uniform_int_distribution<int> rx(0, width - 1), ry(0, height - 1), size(0, 6);
    const int rectangles = static_cast<int>(density * width * height / 12.0);
    for (int i = 0; i < rectangles; ++i) {
      const int x0 = rx(rng), y0 = ry(rng), x1 = std::min(width - 1, x0 + size(rng)),
                y1 = std::min(height - 1, y0 + size(rng));
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) rows[y][x] = '#';
    }
  }
  return std::move(GridMap::from_rows(rows)).value();
}

// Segments of four kinds: uniform end cells; short ones; ones through exact lattice corners
// (steps (p, q) with p, q odd and coprime, e.g. slopes 1, 1/3, 3/5, repeated m times: the
// segment then passes a corner at every odd multiple of half the step); and axis-aligned ones.
Cell random_segment_end(std::mt19937& rng, const GridMap& map, const Cell& a) {
  static constexpr std::array<Cell, 8> kOddSteps = {Cell{1, 1}, Cell{1, 3}, Cell{3, 1}, Cell{3, 5},
                                                    Cell{5, 3}, Cell{1, 5}, Cell{7, 3}, Cell{5, 7}};
  const int w = map.width(), h = map.height();
  std::uniform_int_distribution<int> kind(0, 9), rx(0, w - 1), ry(0, h - 1), near(-4, 4);
  const int k = kind(rng);
  if (k < 4) return {rx(rng), ry(rng)};
  if (k < 6) return {std::clamp(a.x + near(rng), 0, w - 1), std::clamp(a.y + near(rng), 0, h - 1)};
  if (k < 9) {
    Cell step = kOddSteps[std::uniform_int_distribution<size_t>(0, kOddSteps.size() - 1)(rng)];
    if (rng() & 1) step.x = -step.x;
    if (rng() & 1) step.y = -step.y;
    const int room_x = step.x > 0 ? w - 1 - a.x : a.x, room_y = step.y > 0 ? h - 1 - a.y : a.y;
    const int most = std::min(room_x / std::abs(step.x), room_y / std::abs(step.y));
    if (most < 1) return {rx(rng), ry(rng)};
    const int m = std::uniform_int_distribution<int>(1, most)(rng);
    return {a.x + m * step.x, a.y + m * step.y};
  }
  return (rng() & 1) ? Cell{rx(rng), a.y} : Cell{a.x, ry(rng)};
}

// Per policy: how many segments were compared and what the answers were, so that the test
// shows both answers (and long blocked segments) were exercised.
struct AnswerCounts {
  int64_t segments = 0, clear = 0, blocked_long = 0;
};

// The same cells with a cost gradient (inflation_radius 3 cells, no radius), or without one.
GridMap with_cost_gradient(const GridMap& cells, bool gradient) {
  core::OccupancyGrid grid;
  grid.width = cells.width();
  grid.height = cells.height();
  grid.resolution = 1.0;
  grid.data.assign(static_cast<size_t>(grid.width) * grid.height, core::kOccupancyFree);
  for (int32_t y = 0; y < grid.height; ++y)
    for (int32_t x = 0; x < grid.width; ++x)
      if (cells.blocked(x, y))
        grid.data[static_cast<size_t>(y) * grid.width + x] = core::kOccupancyOccupied;
  core::GridBuildOptions options;
  if (gradient) {
    options.inflation_radius = 3.0;
    options.cost_scaling_factor = 0.7;
  }
  return std::move(GridMap::build(grid, options)).value();
}

// Between any points, the line walk over the bit grids takes the cell-by-cell traversal's every
// decision: the same answer and, with costs, the same highest cost, on random real points,
// points on cell boundaries and through exact corners (dyadic coordinates), short and long
// segments, every policy.
TEST(LineOfSight, ContinuousWalkEqualsScalarTraversal) {
  std::mt19937 rng(77);
  int64_t compared = 0, clear = 0, corners = 0;
  int64_t long_spans = 0;  // clear segments whose line spans pass a whole word (the word loop)
  for (int trial = 0; trial < 300; ++trial) {
    // Every tenth map is long and low (up to 300 x 8), for spans over several words.
    const int w = trial % 10 == 9 ? 130 + trial % 171 : 1 + trial % 90;
    const int h = trial % 10 == 9 ? 1 + trial % 8 : 1 + (trial * 7) % 70;
    const bool long_low = trial % 10 == 9;  // a few rectangles only: long clear rows
    const GridMap map =
        with_cost_gradient(random_test_map(rng, w, h, long_low ? 0.03 : 0.05 + 0.1 * (trial % 5),
                                           long_low || trial % 2 == 0),
                           trial % 4 != 0);
    std::uniform_real_distribution<double> ux(0.0, w), uy(0.0, h);
    // Half-cell points up to the map's far edges (x == w or y == h lies outside: refused).
    std::uniform_int_distribution<int> half_x(0, 2 * w), half_y(0, 2 * h);
    std::uniform_int_distribution<int> whole_x(0, w), whole_y(0, h);
    for (int q = 0; q < 500; ++q) {
      Point2 a, b;
      if (q % 5 == 0 ||
          q % 5 == 2) {  // half-cell grid: boundaries, centres and exact corner crossings
        a = Point2(half_x(rng) / 2.0, half_y(rng) / 2.0);
        b = Point2(half_x(rng) / 2.0, half_y(rng) / 2.0);
      } else if (q % 5 == 3) {  // a tiny step across a cell boundary or corner, either way
        const int t = q / 5;    // 1e-12 or 1e-300; across a side or a corner; either way
        const double eps = t % 2 == 0 ? 1e-12 : 1e-300;
        const bool corner = t % 4 >= 2;
        a = Point2(whole_x(rng) - eps, whole_y(rng) + (corner ? eps : 0.5));
        b = a + Point2(2 * eps, corner ? -2 * eps : 0.0);
        if (t % 8 >= 4) std::swap(a, b);
      } else if (q % 5 == 1) {  // short, as the smoothers' segments
        a = Point2(ux(rng), uy(rng));
        b = a + Point2(std::uniform_real_distribution<double>(-3, 3)(rng),
                       std::uniform_real_distribution<double>(-3, 3)(rng));
      } else {
        a = Point2(ux(rng), uy(rng));
        b = Point2(ux(rng), uy(rng));
      }
      for (CornerPolicy p : kPolicies) {
        const bool expected = line_of_sight_scalar(map, a, b, p);
        ASSERT_EQ(line_of_sight(map, a, b, p), expected)
            << "map " << trial << " a=" << a.transpose() << " b=" << b.transpose() << " "
            << core::to_string(p);
        const auto cost = core::max_cost_along(map, a, b, p);
        const auto expected_cost = max_cost_along_scalar(map, a, b, p);
        ASSERT_EQ(cost.has_value(), expected_cost.has_value());
        if (cost) {
          ASSERT_EQ(*cost, *expected_cost);
        }
        ++compared;
        clear += expected;
        long_spans += expected && std::abs(b.x() - a.x()) > 64 * (std::abs(b.y() - a.y()) + 1e-9);
      }
      // Exact corner crossings between the half-cell points: both coordinates' crossings
      // coincide somewhere along the segment.
      corners +=
          (q % 5 == 0 || q % 5 == 2) && line_of_sight_scalar(map, a, b, CornerPolicy::kNever) !=
                                            line_of_sight_scalar(map, a, b, CornerPolicy::kAlways);
    }
  }
  EXPECT_GT(clear, compared / 10);
  EXPECT_GT(compared - clear, compared / 10);
  EXPECT_GT(corners, 100);     // corner crossings decided some answers
  EXPECT_GT(long_spans, 100);  // and spans read over several words
  // Non-finite and outside ends are refused by both functions.
  const GridMap open = std::move(GridMap::from_rows({"....", "...."})).value();
  for (const auto& [a, b] : {std::pair{Point2(0.5, 0.5), Point2(NAN, 0.5)},
                             std::pair{Point2(0.5, 0.5), Point2(4.0, 0.5)},
                             std::pair{Point2(0.5, 2.0), Point2(0.5, 0.5)},
                             std::pair{Point2(-1e-300, 0.5), Point2(0.5, 0.5)}}) {
    EXPECT_FALSE(line_of_sight(open, a, b, CornerPolicy::kAlways));
    EXPECT_FALSE(core::max_cost_along(open, a, b, CornerPolicy::kAlways).has_value());
  }
}

// The bit-grid walk, and the public API with its summed-area shortcuts, equal the scalar
// traversal on > 10^6 segments per policy: maps from 1 to 300 cells wide (not only multiples of
// 64), densities 0 to 60 %, long segments over many words, and segments through exact corners.
TEST(LineOfSight, BitGridWalkEqualsScalarTraversalOnMillionsOfSegments) {
  constexpr int kMaps = 1000, kSegmentsPerMap = 1050;
  const int widths[] = {1, 2, 3, 5, 17, 63, 64, 65, 100, 127, 128, 129, 190, 255, 257, 300};
  const double densities[] = {0.0, 0.01, 0.03, 0.05, 0.1, 0.2, 0.3, 0.45, 0.6};
  std::mt19937 rng(2024);
  std::array<AnswerCounts, 3> seen{};
  int64_t policy_dependent = 0;
  for (int trial = 0; trial < kMaps; ++trial) {
    const int w = widths[trial % 16], h = widths[(trial / 16 + trial * 7) % 16];
    const double density = densities[trial % 9];
    const GridMap map = random_test_map(rng, w, h, density, trial % 3 == 0);
    std::uniform_int_distribution<int> rx(0, w - 1), ry(0, h - 1);
    for (int q = 0; q < kSegmentsPerMap; ++q) {
      const Cell a{rx(rng), ry(rng)};
      const Cell b = random_segment_end(rng, map, a);
      bool answers[3];
      for (int i = 0; i < 3; ++i) {
        const CornerPolicy p = kPolicies[i];
        const bool expected = line_of_sight_centres_scalar(map, a, b, p);
        const bool walked = centre_segment_clear(map, a, b, p);
        if (walked != expected || line_of_sight(map, a, b, p) != expected) {
          FAIL() << "map " << trial << " (" << w << " x " << h << ", density " << density
                 << ") a=" << a.x << "," << a.y << " b=" << b.x << "," << b.y << " policy "
                 << core::to_string(p) << ": scalar " << expected << ", walk " << walked;
        }
        answers[i] = expected;
        AnswerCounts& s = seen[i];
        ++s.segments;
        s.clear += expected;
        // Blocked segments longer than a word between free end cells: the blocking cell may lie
        // anywhere along many words of spans.
        s.blocked_long += !expected && map.blocked_in_rect(a, b) > 0 &&
                          std::max(std::abs(a.x - b.x), std::abs(a.y - b.y)) > 64 && map.free(a) &&
                          map.free(b);
      }
      policy_dependent += answers[0] != answers[2];
    }
  }
  for (int i = 0; i < 3; ++i) {
    const AnswerCounts& s = seen[i];
    EXPECT_GE(s.segments, 1'000'000) << core::to_string(kPolicies[i]);
    EXPECT_GT(s.clear, s.segments / 5) << core::to_string(kPolicies[i]);
    EXPECT_GT(s.segments - s.clear, s.segments / 5) << core::to_string(kPolicies[i]);
    EXPECT_GT(s.blocked_long, 10'000) << core::to_string(kPolicies[i]);
  }
  EXPECT_GT(policy_dependent, 10'000);  // never and always differed: corners were decisive
}

// On small maps the walk also equals the independent definition in test_support.hpp.
TEST(LineOfSight, BitGridWalkEqualsExactDefinition) {
  std::mt19937 rng(99);
  int64_t compared = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int w = 1 + trial % 70, h = 1 + (trial * 13) % 41;
    const GridMap map = random_test_map(rng, w, h, 0.02 + 0.5 * (trial % 6) / 6.0, trial % 2);
    std::uniform_int_distribution<int> rx(0, w - 1), ry(0, h - 1);
    for (int q = 0; q < 300; ++q) {
      const Cell a{rx(rng), ry(rng)};
      const Cell b = random_segment_end(rng, map, a);
      for (CornerPolicy p : kPolicies) {
        ASSERT_EQ(centre_segment_clear(map, a, b, p), reference_los_centres(map, a, b, p))
            << "trial " << trial << " a=" << a.x << "," << a.y << " b=" << b.x << "," << b.y
            << " policy " << core::to_string(p);
        ++compared;
      }
    }
  }
  EXPECT_EQ(compared, 200 * 300 * 3);
}

TEST(CornerPolicy, NamesRoundTrip) {
  for (CornerPolicy p : kPolicies)
    EXPECT_EQ(core::corner_policy_from_string(core::to_string(p)), p);
  EXPECT_FALSE(core::corner_policy_from_string("sometimes"));
}

}  // namespace
}  // namespace vnsba::test
