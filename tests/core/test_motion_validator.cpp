// MotionValidator (motion_validator.hpp) against oracles written here from the spec
// (docs/algorithm.md sections 1, 2 and 8), reading nothing of the map but its blocked flags, cell
// costs and layers: the moves by brute force over the neighbourhood with the corner rules spelt
// out, segments by a supersampled walk, costs by hand sums, clearance by a search along the
// segment. Pruning, smoothing and relax through the validator are held to their old results by
// test_postprocess.cpp and test_costs.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "core/test_support.hpp"
#include "vnsba/core/motion_validator.hpp"

namespace vnsba::test {
namespace {

using core::GridBuildOptions;
using core::MotionValidator;
using core::Neighborhood;
using core::OccupancyGrid;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr Neighborhood kBothNeighborhoods[] = {Neighborhood::kEight,
                                               Neighborhood::kEightElevenThirteen};

int sign_of(int v) {
  return v > 0 ? 1 : (v < 0 ? -1 : 0);
}

using Offset = std::pair<int, int>;

// The moves of docs/algorithm.md section 2 from `from` toward `guide`, by brute force: every
// 8-neighbour in the map and free (a diagonal one by the corner rule on its two side cells), and
// with 8-11-13, when all 8 are free, the extra cells the guide's direction names, each free, the
// (2, 2)-type one also passing the corner between its (2, 1)- and (1, 2)-type cells by the rule.
std::vector<Offset> spec_moves(const GridMap& map, const Cell& from, const Cell& guide,
                               Neighborhood neighborhood, CornerPolicy policy) {
  auto free = [&](int dx, int dy) { return cell_free(map, from.x + dx, from.y + dy); };
  std::vector<Offset> out;
  bool all_eight_free = true;
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      if (dx == 0 && dy == 0) continue;
      if (!free(dx, dy)) {
        all_eight_free = false;
        continue;
      }
      if (dx != 0 && dy != 0 && !corner_allowed(free(dx, 0), free(0, dy), policy)) continue;
      out.push_back({dx, dy});
    }
  }
  if (neighborhood == Neighborhood::kEight || !all_eight_free) return out;
  const int sx = sign_of(guide.x - from.x), sy = sign_of(guide.y - from.y);
  std::vector<Offset> extra;
  if (sx != 0 && sy == 0) extra = {{2 * sx, -1}, {2 * sx, 0}, {2 * sx, 1}};
  if (sx == 0 && sy != 0) extra = {{-1, 2 * sy}, {0, 2 * sy}, {1, 2 * sy}};
  if (sx != 0 && sy != 0)
    extra = {{2 * sx, 0}, {2 * sx, sy}, {2 * sx, 2 * sy}, {sx, 2 * sy}, {0, 2 * sy}};
  for (const auto& [dx, dy] : extra) {
    if (!free(dx, dy)) continue;
    if (std::abs(dx) == 2 && std::abs(dy) == 2 &&
        !corner_allowed(free(2 * sx, sy), free(sx, 2 * sy), policy))
      continue;
    out.push_back({dx, dy});
  }
  return out;
}

struct ValidatorMove {
  int dx, dy;
  double length;
};

std::vector<ValidatorMove> validator_moves(const MotionValidator& motion, const Cell& from,
                                           const Cell& guide, Neighborhood neighborhood) {
  std::vector<ValidatorMove> out;
  motion.for_each_move(from, guide, neighborhood, [&](int dx, int dy, double length) {
    out.push_back({dx, dy, length});
  });
  return out;
}

TEST(MotionValidatorMoves, AreTheSpecsMovesOnRandomMapsForEveryPolicyAndGuide) {
  std::mt19937 rng(4601);
  int64_t compared = 0, long_moves = 0;
  for (int trial = 0; trial < 24; ++trial) {
    const int width = 5 + static_cast<int>(rng() % 8), height = 5 + static_cast<int>(rng() % 8);
    const double density = std::array<double, 3>{0.08, 0.2, 0.35}[trial % 3];
    const auto map = GridMap::from_rows(random_rows(rng, width, height, density));
    ASSERT_TRUE(map);
    for (const CornerPolicy policy : kAllCornerPolicies) {
      const MotionValidator motion(*map, policy);
      for (const Cell& from : free_cells(*map)) {
        // Guides at every direction and distance up to 3, the cell itself included.
        for (int gy = -3; gy <= 3; ++gy) {
          for (int gx = -3; gx <= 3; ++gx) {
            const Cell guide{from.x + gx, from.y + gy};
            for (const Neighborhood n : kBothNeighborhoods) {
              std::vector<Offset> want = spec_moves(*map, from, guide, n, policy);
              std::vector<Offset> got;
              for (const ValidatorMove& m : validator_moves(motion, from, guide, n)) {
                got.push_back({m.dx, m.dy});
                // The step cost is the move's Euclidean length to within 1e-8 (neighborhood.hpp).
                const double euclid = std::hypot(m.dx, m.dy);
                ASSERT_NEAR(m.length, euclid, 1e-8 * euclid);
                long_moves += std::abs(m.dx) == 2 || std::abs(m.dy) == 2;
              }
              std::sort(want.begin(), want.end());
              std::sort(got.begin(), got.end());
              ASSERT_EQ(got, want) << "from (" << from.x << ", " << from.y << ") guide (" << guide.x
                                   << ", " << guide.y << ") policy " << core::to_string(policy)
                                   << " neighbourhood " << core::to_string(n);
              ++compared;
            }
          }
        }
      }
    }
  }
  EXPECT_GT(compared, 100000);
  EXPECT_GT(long_moves, 10000);  // the 8-11-13 moves were exercised, not only the 8
}

// --- Costs ------------------------------------------------------------------------------------

// A map of graded values (top row first): value v is a free cell of cost v / 100 (as a float,
// section 8), values at or above 65 are blocked.
GridMap graded_map(const std::vector<std::vector<int>>& values_top_first) {
  OccupancyGrid grid;
  grid.height = static_cast<int32_t>(values_top_first.size());
  grid.width = static_cast<int32_t>(values_top_first.front().size());
  for (int32_t y = 0; y < grid.height; ++y)
    for (const int v : values_top_first[grid.height - 1 - y])
      grid.data.push_back(static_cast<int8_t>(v));
  auto built = GridMap::build(grid);
  EXPECT_TRUE(built) << built.error().message;
  return std::move(built).value();
}

double cost_of(int value) {
  return static_cast<double>(static_cast<float>(value / 100.0));
}

TEST(MotionValidatorCosts, MovesAndSegmentsAreTheHandSumsOnASmallMap) {
  // Rows top first: y = 4 at the top. The cells a move's segment crosses, worked out by hand.
  const GridMap map = graded_map({{0, 0, 0, 0, 0},  //
                                  {0, 0, 0, 30, 5},
                                  {0, 0, 10, 20, 0},
                                  {0, 0, 0, 40, 0},
                                  {0, 0, 0, 0, 0}});
  const double w = 2.0;
  const MotionValidator motion(map, CornerPolicy::kNever, w);
  ASSERT_TRUE(motion.weighs_costs());
  const Cell from{2, 2};  // cost 0.10
  auto move = [&](int dx, int dy) {
    const uint32_t at = map.padded_index(from);
    const uint32_t to = map.padded_index(Cell{from.x + dx, from.y + dy});
    return motion.move_cost(at, to, dx, dy, std::hypot(dx, dy));
  };
  // (1, 0): cells (2, 2) 0.10 and (3, 2) 0.20.
  EXPECT_DOUBLE_EQ(move(1, 0), 1.0 * (1.0 + w * cost_of(20)));
  // (2, 0): (2, 2), (3, 2) 0.20, (4, 2) 0: the middle cell is the dearest.
  EXPECT_DOUBLE_EQ(move(2, 0), 2.0 * (1.0 + w * cost_of(20)));
  // (2, 1): (2, 2), (3, 2) 0.20, (3, 3) 0.30, (4, 3) 0.05.
  EXPECT_DOUBLE_EQ(move(2, 1), std::sqrt(5.0) * (1.0 + w * cost_of(30)));
  // (2, -1): (2, 2), (3, 2) 0.20, (3, 1) 0.40, (4, 1) 0.
  EXPECT_DOUBLE_EQ(move(2, -1), std::sqrt(5.0) * (1.0 + w * cost_of(40)));
  // (-2, -2): (2, 2) 0.10, (1, 1) 0, (0, 0) 0: the start cell counts.
  EXPECT_DOUBLE_EQ(move(-2, -2), std::sqrt(8.0) * (1.0 + w * cost_of(10)));
  // (1, 2): (2, 2), (2, 3) 0, (3, 3) 0.30, (3, 4) 0.
  EXPECT_DOUBLE_EQ(move(1, 2), std::sqrt(5.0) * (1.0 + w * cost_of(30)));
  // A segment along row 2 from x = 0.5 to 4.5 crosses costs 0, 0, 0.10, 0.20, 0.
  const Point2 a(0.5, 2.5), b(4.5, 2.5), c(4.5, 0.5);
  EXPECT_DOUBLE_EQ(motion.segment_cost(a, b), 4.0 * (1.0 + w * cost_of(20)));
  // Down column 4 from y = 2.5 to 0.5: costs 0 all the way.
  EXPECT_DOUBLE_EQ(motion.segment_cost(b, c), 2.0);
  EXPECT_DOUBLE_EQ(motion.path_cost({a, b, c}), 4.0 * (1.0 + w * cost_of(20)) + 2.0);
  // Without a weight a segment costs its length, whatever the cells.
  EXPECT_DOUBLE_EQ(MotionValidator(map, CornerPolicy::kNever).segment_cost(a, b), 4.0);
  EXPECT_FALSE(MotionValidator(map, CornerPolicy::kNever).weighs_costs());
}

TEST(MotionValidatorCosts, ABlockedSegmentCostsInfinity) {
  const GridMap map = graded_map({{0, 0, 0},  //
                                  {0, 100, 0},
                                  {0, 0, 0}});
  for (const double w : {0.0, 1.5}) {
    const MotionValidator motion(map, CornerPolicy::kAlways, w);
    EXPECT_EQ(motion.segment_cost(Point2(0.5, 1.5), Point2(2.5, 1.5)), kInf);
    EXPECT_EQ(motion.path_cost({Point2(0.5, 0.5), Point2(0.5, 2.5), Point2(2.5, 0.5)}), kInf);
    EXPECT_DOUBLE_EQ(motion.segment_cost(Point2(0.5, 0.5), Point2(0.5, 2.5)), 2.0);
  }
}

// The cells whose open inside the segment between two cell centres crosses (Liang-Barsky on the
// centres' half-integers, exact in doubles): what a move passes (touching a corner is not
// crossing).
std::vector<Cell> cells_crossed(const Cell& from, const Cell& to) {
  const double ax = from.x + 0.5, ay = from.y + 0.5;
  const double dx = to.x - from.x, dy = to.y - from.y;
  std::vector<Cell> out;
  for (int32_t y = std::min(from.y, to.y); y <= std::max(from.y, to.y); ++y) {
    for (int32_t x = std::min(from.x, to.x); x <= std::max(from.x, to.x); ++x) {
      double lo = 0.0, hi = 1.0;
      bool inside = true;
      const double starts[2] = {ax, ay}, deltas[2] = {dx, dy}, lows[2] = {double(x), double(y)};
      for (int axis = 0; axis < 2; ++axis) {
        if (deltas[axis] == 0.0) {
          inside = inside && starts[axis] > lows[axis] && starts[axis] < lows[axis] + 1.0;
          continue;
        }
        const double t1 = (lows[axis] - starts[axis]) / deltas[axis];
        const double t2 = (lows[axis] + 1.0 - starts[axis]) / deltas[axis];
        lo = std::max(lo, std::min(t1, t2));
        hi = std::min(hi, std::max(t1, t2));
      }
      if (inside && lo < hi) out.push_back({x, y});
    }
  }
  return out;
}

// A random map with graded values, occupied and unknown cells and, on some, a robot radius and a
// cost gradient (section 8).
GridMap random_costed_map(std::mt19937& rng) {
  OccupancyGrid grid;
  grid.width = 6 + static_cast<int32_t>(rng() % 15);
  grid.height = 6 + static_cast<int32_t>(rng() % 15);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double occupied = 0.15 * unit(rng), unknown = 0.05 * unit(rng), graded = unit(rng);
  for (int64_t i = 0; i < int64_t{grid.width} * grid.height; ++i) {
    const double u = unit(rng);
    grid.data.push_back(u < occupied             ? int8_t{100}
                        : u < occupied + unknown ? core::kOccupancyUnknown
                        : unit(rng) < graded     ? static_cast<int8_t>(1 + rng() % 64)
                                                 : int8_t{0});
  }
  GridBuildOptions options;
  options.allow_unknown = rng() % 3 == 0;
  options.inflate_unknown = rng() % 2 == 0;
  options.robot_radius = rng() % 2 == 0 ? 0.0 : 0.3 + 1.5 * unit(rng);
  if (rng() % 2 == 0) options.inflation_radius = options.robot_radius + 4.0 * unit(rng);
  options.cost_scaling_factor = 0.2 + unit(rng);
  auto built = GridMap::build(grid, options);
  EXPECT_TRUE(built) << built.error().message;
  return std::move(built).value();
}

TEST(MotionValidatorCosts, EveryMoveCostsItsLengthWeighedByTheDearestCellItCrosses) {
  std::mt19937 rng(4602);
  int64_t compared = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const GridMap map = random_costed_map(rng);
    if (!map.has_costs()) continue;
    const double w = 0.25 + 4.0 * std::uniform_real_distribution<double>(0.0, 1.0)(rng);
    const MotionValidator motion(map, kAllCornerPolicies[trial % 3], w);
    for (const Cell& from : free_cells(map)) {
      for (const Cell guide : {Cell{from.x + 3, from.y}, Cell{from.x, from.y - 3},
                               Cell{from.x + 2, from.y + 1}, Cell{from.x - 1, from.y - 2}}) {
        for (const ValidatorMove& m :
             validator_moves(motion, from, guide, Neighborhood::kEightElevenThirteen)) {
          const Cell to{from.x + m.dx, from.y + m.dy};
          double dearest = 0.0;
          for (const Cell& c : cells_crossed(from, to)) dearest = std::max(dearest, map.cost(c));
          const double got =
              motion.move_cost(map.padded_index(from), map.padded_index(to), m.dx, m.dy, m.length);
          ASSERT_EQ(got, m.length * (1.0 + w * dearest))
              << "move (" << m.dx << ", " << m.dy << ") from (" << from.x << ", " << from.y << ")";
          // The segment between the same centres is priced alike, up to the step's quantizing.
          const double segment =
              motion.segment_cost(core::cell_centre(from), core::cell_centre(to));
          ASSERT_NEAR(got, segment, 1e-8 * segment);
          ++compared;
        }
      }
    }
  }
  EXPECT_GT(compared, 5000);
}

// --- Segments ---------------------------------------------------------------------------------

// The least distance from the segment a -> b to any lattice point (a cell corner) near it.
double distance_to_nearest_corner(const Point2& a, const Point2& b) {
  double best = kInf;
  for (double y = std::floor(std::min(a.y(), b.y())); y <= std::ceil(std::max(a.y(), b.y())); ++y)
    for (double x = std::floor(std::min(a.x(), b.x())); x <= std::ceil(std::max(a.x(), b.x()));
         ++x) {
      const Point2 ab = b - a, p(x, y);
      const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
      best = std::min(best, (a + t * ab - p).norm());
    }
  return best;
}

// Sampled every 1/1024 cell, a segment that stays 1e-3 cells from every cell corner is seen in
// every cell it crosses (the shortest piece of a cell it can cross is 2e-3 cells, near a corner).
constexpr int kSamplesPerCell = 1024;
constexpr double kCornerMarginCells = 1e-3;

Point2 random_point(std::mt19937& rng, const GridMap& map, double outside) {
  std::uniform_real_distribution<double> x(-outside, map.width() + outside);
  std::uniform_real_distribution<double> y(-outside, map.height() + outside);
  return {x(rng), y(rng)};
}

TEST(MotionValidatorSegments, ValidityIsTheSupersampledWalkForEveryPolicy) {
  std::mt19937 rng(4603);
  int64_t valid = 0, invalid = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const auto map = GridMap::from_rows(
        random_rows(rng, 6 + static_cast<int>(rng() % 10), 6 + static_cast<int>(rng() % 10), 0.2));
    ASSERT_TRUE(map);
    const std::vector<Cell> cells = free_cells(*map);
    for (const CornerPolicy policy : kAllCornerPolicies) {
      const MotionValidator motion(*map, policy);
      for (int k = 0; k < 150; ++k) {
        const Point2 a = random_point(rng, *map, 0.5), b = random_point(rng, *map, 0.5);
        if (distance_to_nearest_corner(a, b) < kCornerMarginCells) continue;
        const bool want = segment_clear_sampled(*map, a, b, policy, kSamplesPerCell);
        ASSERT_EQ(motion.segment_valid(a, b), want) << a.transpose() << " -> " << b.transpose();
        (want ? valid : invalid) += 1;
      }
      // Between cell centres the walk is exact: corners passed exactly are decided by the rule.
      for (int k = 0; k < 150 && !cells.empty(); ++k) {
        const Cell a = cells[rng() % cells.size()], b = cells[rng() % cells.size()];
        const bool want = reference_los_centres(*map, a, b, policy);
        ASSERT_EQ(motion.segment_valid(a, b), want);
        ASSERT_EQ(motion.segment_valid(core::cell_centre(a), core::cell_centre(b)), want);
        // (Between centres a cell is crossed for at least 1/22 cell or only touched at a corner.)
        ASSERT_EQ(segment_clear_sampled(*map, core::cell_centre(a), core::cell_centre(b), policy),
                  want);
      }
    }
  }
  EXPECT_GT(valid, 1000);
  EXPECT_GT(invalid, 1000);
}

// The highest cost of the cells the segment enters, sampled every 1/kSamplesPerCell cell.
double sampled_dearest(const GridMap& map, const Point2& a, const Point2& b) {
  const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() * kSamplesPerCell)));
  double dearest = 0.0;
  for (int i = 0; i <= n; ++i) {
    const Point2 p = a + (b - a) * (static_cast<double>(i) / n);
    dearest = std::max(dearest, map.cost(Cell{static_cast<int32_t>(std::floor(p.x())),
                                              static_cast<int32_t>(std::floor(p.y()))}));
  }
  return dearest;
}

TEST(MotionValidatorSegments, CostIsTheLengthWeighedByTheDearestCellSampled) {
  std::mt19937 rng(4604);
  int64_t priced = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const GridMap map = random_costed_map(rng);
    const CornerPolicy policy = kAllCornerPolicies[trial % 3];
    for (const double w : {0.0, 0.5, 3.0}) {
      const MotionValidator motion(map, policy, w);
      // Each segment starts where the last clear one ended: a polyline, summed by hand, from a
      // point of a free cell.
      const std::vector<Cell> cells = free_cells(map);
      if (cells.empty()) continue;
      const Cell first = cells[rng() % cells.size()];
      std::uniform_real_distribution<double> within(0.01, 0.99);
      std::vector<Point2> polyline = {Point2(first.x + within(rng), first.y + within(rng))};
      double hand_sum = 0.0;
      for (int k = 0; k < 60; ++k) {
        const Point2 a = polyline.back(), b = random_point(rng, map, 0.0);
        if (distance_to_nearest_corner(a, b) < kCornerMarginCells) continue;
        const double length = (b - a).norm();
        const double want = !segment_clear_sampled(map, a, b, policy, kSamplesPerCell) ? kInf
                            : w == 0.0                                                 ? length
                                       : length * (1.0 + w * sampled_dearest(map, a, b));
        ASSERT_EQ(motion.segment_cost(a, b), want) << a.transpose() << " -> " << b.transpose();
        if (want == kInf) continue;
        ++priced;
        polyline.push_back(b);
        hand_sum += want;
      }
      EXPECT_EQ(motion.path_cost(polyline), hand_sum);
    }
  }
  EXPECT_GT(priced, 500);
}

// --- Clearance --------------------------------------------------------------------------------

// The distance from the segment a -> b to the square of cell c: the distance from a point to the
// square is convex along the segment, so a ternary search over the segment finds its least.
double segment_square_distance_oracle(const Point2& a, const Point2& b, const Cell& c) {
  auto to_square = [&](double t) {
    const Point2 p = a + t * (b - a);
    const double dx = std::max({c.x - p.x(), 0.0, p.x() - (c.x + 1.0)});
    const double dy = std::max({c.y - p.y(), 0.0, p.y() - (c.y + 1.0)});
    return std::hypot(dx, dy);
  };
  double lo = 0.0, hi = 1.0;
  for (int i = 0; i < 100; ++i) {
    const double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3;
    if (to_square(m1) < to_square(m2)) {
      hi = m2;
    } else {
      lo = m1;
    }
  }
  return std::min({to_square(0.0), to_square(1.0), to_square((lo + hi) / 2)});
}

// The least distance from the segment to an obstacle square (occupied, or unknown when the map
// inflates it); +inf without obstacles.
double clearance_oracle(const GridMap& map, const Point2& a, const Point2& b) {
  double best = kInf;
  for (int32_t y = 0; y < map.height(); ++y)
    for (int32_t x = 0; x < map.width(); ++x)
      if (map.is_obstacle(map.layer({x, y})))
        best = std::min(best, segment_square_distance_oracle(a, b, {x, y}));
  return best;
}

TEST(MotionValidatorClearance, KeepsClearanceIsLineOfSightAndTheExactDistanceAboveTheFloor) {
  std::mt19937 rng(4605);
  int64_t kept = 0, refused = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const GridMap map = random_costed_map(rng);
    const CornerPolicy policy = kAllCornerPolicies[trial % 3];
    for (const double floor : {0.0, 0.4, 1.0, 2.5}) {
      const MotionValidator motion(map, policy, 0.0, floor);
      for (int k = 0; k < 40; ++k) {
        // Short segments, as relax checks them, and long ones.
        const Point2 a = random_point(rng, map, 0.0);
        const Point2 b = k % 2 == 0 ? a + Point2(std::uniform_real_distribution<>(-2, 2)(rng),
                                                 std::uniform_real_distribution<>(-2, 2)(rng))
                                    : random_point(rng, map, 0.0);
        if (distance_to_nearest_corner(a, b) < kCornerMarginCells) continue;
        const double clearance = clearance_oracle(map, a, b);
        if (std::abs(clearance - floor) < 1e-6) continue;  // too close to call either way
        const bool want =
            segment_clear_sampled(map, a, b, policy, kSamplesPerCell) && clearance >= floor;
        ASSERT_EQ(motion.segment_keeps_clearance(a, b), want)
            << a.transpose() << " -> " << b.transpose() << ", floor " << floor << ", clearance "
            << clearance;
        (want ? kept : refused) += 1;
      }
    }
  }
  EXPECT_GT(kept, 500);
  EXPECT_GT(refused, 500);
}

}  // namespace
}  // namespace vnsba::test
