// Cell costs, clearance and tolerance (docs/algorithm.md section 8) against independent oracles
// written here: a brute-force classification of every cell and its cost, a Dijkstra over the
// planners' move graph priced by dense sampling of each move's segment, a brute-force clearance
// over every obstacle square and a brute-force nearest free cell. Nothing is compared with numbers
// copied from a run.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <queue>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/movingai_support.hpp"
#include "core/test_support.hpp"
#include "vnsba/core/line_of_sight.hpp"
#include "vnsba/core/metrics.hpp"
#include "vnsba/core/path_poses.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/core/postprocess.hpp"

namespace vnsba::test {
namespace {

using core::CellLayer;
using core::GridBuildOptions;
using core::Neighborhood;
using core::OccupancyGrid;
using core::PlannerKind;
using core::PlannerOptions;
using core::PlanQuery;
using core::PlanResult;
using core::StatusCode;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string str(const Cell& c) {
  return "(" + std::to_string(c.x) + ", " + std::to_string(c.y) + ")";
}

double uniform(std::mt19937& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}
int uniform_int(std::mt19937& rng, int lo, int hi) {
  return std::uniform_int_distribution<int>(lo, hi)(rng);
}
template <class T>
const T& pick(std::mt19937& rng, const std::vector<T>& v) {
  return v[std::uniform_int_distribution<size_t>(0, v.size() - 1)(rng)];
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// ---------------------------------------------------------------------------------------------
// Random maps with occupied, unknown and graded values, and random build options.

struct Scenario {
  OccupancyGrid grid;
  GridBuildOptions options;

  std::string describe() const {
    std::ostringstream s;
    s.precision(17);
    s << grid.width << " x " << grid.height << " cells at " << grid.resolution << " m, threshold "
      << options.occupied_threshold << ", allow_unknown " << options.allow_unknown
      << ", inflate_unknown " << options.inflate_unknown << ", robot_radius "
      << options.robot_radius << ", inflation_radius " << options.inflation_radius
      << ", cost_scaling_factor " << options.cost_scaling_factor;
    return s.str();
  }
};

struct Spec {
  int min_side = 6, max_side = 40;
  double max_occupied = 0.35;
  bool force_costs = false;   // graded values and a gradient, always
  bool no_costs = false;      // neither graded values nor a gradient
  bool no_obstacles = false;  // no occupied cell, unknown cells free
  int min_radius_cells = 0;   // robot radius at least this (cells), at most 3.2
};

Scenario random_scenario(std::mt19937& rng, const Spec& spec = {}) {
  Scenario s;
  OccupancyGrid& g = s.grid;
  GridBuildOptions& o = s.options;
  g.width = uniform_int(rng, spec.min_side, spec.max_side);
  g.height = uniform_int(rng, spec.min_side, spec.max_side);
  static const std::vector<double> resolutions = {0.05, 0.1, 0.15, 0.25, 0.3, 0.5, 1.0};
  g.resolution = rng() % 3 == 0 ? uniform(rng, 0.05, 1.0) : pick(rng, resolutions);
  g.origin_x = uniform(rng, -5.0, 5.0);
  g.origin_y = uniform(rng, -5.0, 5.0);
  static const std::vector<int> thresholds = {65, 65, 65, 40, 90};
  o.occupied_threshold = pick(rng, thresholds);
  o.allow_unknown = spec.no_obstacles || rng() % 4 == 0;
  // Half the maps inflate their unknown cells (drawn without the generator: the maps stay those
  // the tests were written with).
  o.inflate_unknown = (g.width + g.height) % 2 == 0;
  const double p_occupied = spec.no_obstacles ? 0.0 : uniform(rng, 0.0, spec.max_occupied);
  const double p_unknown = rng() % 4 == 0 ? 0.0 : uniform(rng, 0.0, 0.08);
  const double p_graded =
      spec.no_costs ? 0.0 : (!spec.force_costs && rng() % 4 == 0 ? 0.0 : uniform(rng, 0.05, 0.5));
  const int graded_max = spec.no_obstacles ? std::min(64, o.occupied_threshold - 1) : 64;
  g.data.resize(static_cast<size_t>(g.width) * g.height);
  for (int8_t& v : g.data) {
    const double u = uniform(rng, 0.0, 1.0);
    if (u < p_occupied) {
      v = static_cast<int8_t>(uniform_int(rng, o.occupied_threshold, 100));
    } else if (u < p_occupied + p_unknown) {
      v = core::kOccupancyUnknown;
    } else if (u < p_occupied + p_unknown + p_graded) {
      v = static_cast<int8_t>(uniform_int(rng, 1, graded_max));
    } else {
      v = 0;
    }
  }
  // Robot radius: none, a whole number of cells (metres = cells * resolution, which the build
  // must snap back to whole cells), or any value.
  const int mode = spec.min_radius_cells > 0 ? 1 + static_cast<int>(rng() % 2) : rng() % 3;
  if (mode == 1) {
    o.robot_radius = uniform_int(rng, std::max(1, spec.min_radius_cells), 3) * g.resolution;
  } else if (mode == 2) {
    o.robot_radius = uniform(rng, std::max(0.2, double(spec.min_radius_cells)), 3.2) * g.resolution;
  }
  const bool gradient = !spec.no_costs && (spec.force_costs || rng() % 4 != 0);
  if (gradient) o.inflation_radius = o.robot_radius + uniform(rng, 0.3, 8.0) * g.resolution;
  o.cost_scaling_factor = rng() % 5 == 0 ? 0.0 : uniform(rng, 0.05, 2.0) / g.resolution;
  return s;
}

std::shared_ptr<const GridMap> build_shared(const Scenario& s) {
  auto built = GridMap::build(s.grid, s.options);
  if (!built) {
    ADD_FAILURE() << built.error().message << " for " << s.describe();
    return nullptr;
  }
  return std::make_shared<const GridMap>(std::move(built).value());
}

// ---------------------------------------------------------------------------------------------
// Brute force: the classification and cost of every cell from the map values alone.

struct Truth {
  int32_t width = 0, height = 0;
  double resolution = 1.0;
  std::vector<CellLayer> layer;
  std::vector<int64_t> squared;    // cells^2 to the nearest obstacle centre; -1 without any
  std::vector<double> cost;        // free cells (0 elsewhere)
  std::vector<uint8_t> ambiguous;  // centre exactly on the inflation_radius: either cost is right
  std::vector<Cell> obstacles;     // occupied cells, and unknown ones with inflate_unknown
  bool graded = false;             // some value 0 < v < threshold

  size_t index(int32_t x, int32_t y) const { return static_cast<size_t>(y) * width + x; }
  bool free(int64_t x, int64_t y) const {
    return x >= 0 && y >= 0 && x < width && y < height &&
           layer[index(static_cast<int32_t>(x), static_cast<int32_t>(y))] == CellLayer::kFree;
  }
};

Truth brute_force(const Scenario& s) {
  const OccupancyGrid& g = s.grid;
  const GridBuildOptions& o = s.options;
  Truth t;
  t.width = g.width;
  t.height = g.height;
  t.resolution = g.resolution;
  const size_t cells = g.data.size();
  t.layer.assign(cells, CellLayer::kFree);
  t.squared.assign(cells, -1);
  t.cost.assign(cells, 0.0);
  t.ambiguous.assign(cells, 0);
  for (int32_t y = 0; y < g.height; ++y) {
    for (int32_t x = 0; x < g.width; ++x) {
      const int v = g.at(x, y);
      if (v == -1) {
        if (!o.allow_unknown) t.layer[t.index(x, y)] = CellLayer::kUnknown;
      } else if (v >= o.occupied_threshold) {
        t.layer[t.index(x, y)] = CellLayer::kOccupied;
      } else if (v > 0) {
        t.graded = true;
      }
      // Inflation and costs grow from occupied cells, and from blocked unknown ones only with
      // inflate_unknown (Nav2's inflation layer inflates lethal cells only).
      const CellLayer layer = t.layer[t.index(x, y)];
      if (layer == CellLayer::kOccupied || (o.inflate_unknown && layer == CellLayer::kUnknown))
        t.obstacles.push_back({x, y});
    }
  }
  double r = o.robot_radius / g.resolution;  // cells, snapped to a whole number within 1e-9
  if (std::abs(r - std::round(r)) <= 1e-9) r = std::round(r);
  const double gradient_cells = o.inflation_radius / g.resolution;
  for (int32_t y = 0; y < g.height; ++y) {
    for (int32_t x = 0; x < g.width; ++x) {
      const size_t i = t.index(x, y);
      for (const Cell& b : t.obstacles) {
        const int64_t d2 = int64_t{b.x - x} * (b.x - x) + int64_t{b.y - y} * (b.y - y);
        if (t.squared[i] < 0 || d2 < t.squared[i]) t.squared[i] = d2;
      }
      if (t.layer[i] != CellLayer::kFree) continue;
      if (t.squared[i] >= 0 && static_cast<double>(t.squared[i]) <= r * r) {
        t.layer[i] = CellLayer::kInflated;
        continue;
      }
      const int v = g.at(x, y);
      double c = (v > 0 && v < o.occupied_threshold) ? v / 100.0 : 0.0;
      if (o.inflation_radius > 0.0 && t.squared[i] >= 0) {
        const double d_cells = std::sqrt(static_cast<double>(t.squared[i]));
        const double d_m = d_cells * g.resolution;
        if (d_m > o.robot_radius && d_m <= o.inflation_radius)
          c = std::max(c, 0.99 * std::exp(-o.cost_scaling_factor * (d_m - o.robot_radius)));
        if (std::abs(d_cells - gradient_cells) <= 1e-9 * std::max(1.0, d_cells)) t.ambiguous[i] = 1;
      }
      t.cost[i] = c;
    }
  }
  return t;
}

// One random scenario as most tests here use it: its map, the brute-force truth and the free
// cells. `map` is null (and a failure recorded) when the map does not build.
struct Trial {
  Scenario s;
  std::shared_ptr<const GridMap> map;
  Truth t;
  std::vector<Cell> free;
};
Trial random_trial(std::mt19937& rng, const Spec& spec = {}) {
  Trial trial{random_scenario(rng, spec), nullptr, {}, {}};
  trial.map = build_shared(trial.s);
  if (!trial.map) return trial;
  trial.t = brute_force(trial.s);
  trial.free = free_cells(*trial.map);
  return trial;
}

// ---------------------------------------------------------------------------------------------
// Move costs by dense sampling, and Dijkstra over the 8-neighbour move graph.

// The highest map.cost() of the cells whose inside the segment a -> b enters, found by sampling
// it `per_cell` times per cell; points exactly on a lattice corner are skipped (a segment that only
// touches a corner enters neither cell beside it).
double sampled_max_cost(const GridMap& map, const Point2& a, const Point2& b, int per_cell = 16) {
  const double length = (b - a).norm();
  const int n = std::max(1, static_cast<int>(std::ceil(length * per_cell)));
  double highest = 0.0;
  for (int i = 0; i <= n; ++i) {
    const Point2 p = a + (b - a) * (static_cast<double>(i) / n);
    if (p.x() == std::floor(p.x()) && p.y() == std::floor(p.y())) continue;
    const Cell c{static_cast<int32_t>(std::floor(p.x())), static_cast<int32_t>(std::floor(p.y()))};
    highest = std::max(highest, map.in_bounds(c) ? map.cost(c) : 1.0);
  }
  return highest;
}

// length * (1 + w * highest cell cost along the segment).
double oracle_segment_cost(const GridMap& map, const Point2& a, const Point2& b, double w) {
  return (b - a).norm() * (1.0 + w * sampled_max_cost(map, a, b));
}

double oracle_path_cost(const GridMap& map, const std::vector<Cell>& path, double w) {
  double total = 0.0;
  for (size_t i = 1; i < path.size(); ++i)
    total +=
        oracle_segment_cost(map, core::cell_centre(path[i - 1]), core::cell_centre(path[i]), w);
  return total;
}

// Optimal cost from `s` to every cell over the 8-neighbour moves that `policy` allows, each move
// priced by oracle_segment_cost; +inf where unreachable.
std::vector<double> dijkstra_from(const GridMap& map, Cell s, CornerPolicy policy, double w) {
  const int64_t width = map.width(), height = map.height();
  std::vector<double> dist(static_cast<size_t>(width * height), kInf);
  using Item = std::pair<double, int64_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> open;
  dist[s.y * width + s.x] = 0.0;
  open.push({0.0, s.y * width + s.x});
  while (!open.empty()) {
    const auto [d, i] = open.top();
    open.pop();
    if (d > dist[i]) continue;
    const int32_t x = static_cast<int32_t>(i % width), y = static_cast<int32_t>(i / width);
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if ((dx == 0 && dy == 0) || !cell_free(map, x + dx, y + dy)) continue;
        if (dx != 0 && dy != 0 &&
            !corner_allowed(cell_free(map, x + dx, y), cell_free(map, x, y + dy), policy))
          continue;
        const double nd = d + oracle_segment_cost(map, core::cell_centre({x, y}),
                                                  core::cell_centre({x + dx, y + dy}), w);
        const int64_t j = (y + dy) * width + (x + dx);
        if (nd < dist[j]) {
          dist[j] = nd;
          open.push({nd, j});
        }
      }
    }
  }
  return dist;
}

// A raw grid path that starts at s, ends at g and moves only through free cells: with
// max_step 1 along the 8-neighbour moves that `policy` allows, with 2 along steps of Chebyshev
// length 1 or 2 with exact line of sight (the 8-11-13 moves).
::testing::AssertionResult valid_raw_path(const GridMap& map, const std::vector<Cell>& path, Cell s,
                                          Cell g, CornerPolicy policy, int max_step) {
  if (path.empty()) return ::testing::AssertionFailure() << "empty path";
  if (path.front() != s) return ::testing::AssertionFailure() << "does not begin at the start";
  if (path.back() != g) return ::testing::AssertionFailure() << "does not end at the goal";
  for (size_t i = 0; i < path.size(); ++i) {
    const Cell c = path[i];
    if (!cell_free(map, c.x, c.y))
      return ::testing::AssertionFailure() << "cell " << i << " " << str(c) << " is blocked";
    if (i == 0) continue;
    const Cell p = path[i - 1];
    const int dx = c.x - p.x, dy = c.y - p.y;
    const int cheb = std::max(std::abs(dx), std::abs(dy));
    if (cheb < 1 || cheb > max_step)
      return ::testing::AssertionFailure() << "step " << i << " " << str(p) << " -> " << str(c);
    if (cheb == 1 && dx != 0 && dy != 0 &&
        !corner_allowed(cell_free(map, p.x + dx, p.y), cell_free(map, p.x, p.y + dy), policy))
      return ::testing::AssertionFailure() << "step " << i << " " << str(p) << " -> " << str(c)
                                           << " passes a corner the policy forbids";
    if (!reference_los_centres(map, p, c, policy))
      return ::testing::AssertionFailure()
             << "step " << i << " " << str(p) << " -> " << str(c) << " lacks line of sight";
  }
  return ::testing::AssertionSuccess();
}

const std::vector<PlannerKind> kCostPlanners = {
    PlannerKind::kAStar, PlannerKind::kWeightedAStar, PlannerKind::kBidirectionalAStar,
    PlannerKind::kAlternatingBidirectionalAStar, PlannerKind::kVnsBaStar};

// ---------------------------------------------------------------------------------------------
// 1. Layers and obstacle distances.

TEST(CostsLayers, EveryCellMatchesBruteForce) {
  std::mt19937 rng(81001);
  int inflated = 0, unknown = 0, occupied = 0, whole_radius = 0, empty_maps = 0;
  for (int trial = 0; trial < 600; ++trial) {
    Spec spec;
    if (trial % 10 == 0) spec.no_obstacles = true;
    const Scenario s = random_scenario(rng, spec);
    SCOPED_TRACE("trial " + std::to_string(trial) + ": " + s.describe());
    const auto map = build_shared(s);
    ASSERT_TRUE(map);
    const Truth t = brute_force(s);
    const double r = s.options.robot_radius / s.grid.resolution;
    if (r > 0.5 && std::abs(r - std::round(r)) <= 1e-9) ++whole_radius;
    if (t.obstacles.empty()) ++empty_maps;
    for (int32_t y = 0; y < t.height; ++y) {
      for (int32_t x = 0; x < t.width; ++x) {
        const Cell c{x, y};
        const CellLayer expected = t.layer[t.index(x, y)];
        ASSERT_EQ(map->layer(c), expected)
            << "cell " << str(c) << ": got " << core::to_string(map->layer(c)) << ", expected "
            << core::to_string(expected) << " (value " << int{s.grid.at(x, y)} << ", squared "
            << t.squared[t.index(x, y)] << ")";
        ASSERT_EQ(map->blocked(c), expected != CellLayer::kFree) << "cell " << str(c);
        const int64_t d2 = t.squared[t.index(x, y)];
        // The field: exact squared distances up to its saturation, bounds beyond it.
        if (d2 < 0) {
          ASSERT_EQ(core::nearest_obstacle_distance(*map, c), kInf) << "cell " << str(c);
          if (map->has_obstacle_distances()) {
            ASSERT_EQ(map->obstacle_distance_at_most(c), kInf) << "cell " << str(c);
          }
        } else {
          const double d = std::sqrt(static_cast<double>(d2));
          ASSERT_EQ(core::nearest_obstacle_distance(*map, c), d) << "cell " << str(c);
          ASSERT_LE(map->obstacle_distance_at_least(c), d) << "cell " << str(c);
          ASSERT_GE(map->obstacle_distance_at_most(c), d) << "cell " << str(c);
          if (map->has_obstacle_distances() && d2 < GridMap::kSaturatedSquaredDistance) {
            ASSERT_EQ(map->obstacle_distance_at_most(c), d) << "cell " << str(c);
            ASSERT_EQ(map->obstacle_distance_at_least(c), d) << "cell " << str(c);
          }
        }
        inflated += expected == CellLayer::kInflated;
        unknown += expected == CellLayer::kUnknown;
        occupied += expected == CellLayer::kOccupied;
      }
    }
  }
  EXPECT_GT(inflated, 1000);
  EXPECT_GT(unknown, 500);
  EXPECT_GT(occupied, 5000);
  EXPECT_GT(whole_radius, 30);
  EXPECT_GT(empty_maps, 10);
}

// docs/algorithm.md section 1's example: 0.15 m at 0.05 m is exactly 3 cells, so the cell 3 cells
// from an obstacle is inflated and the one at sqrt(10) cells is not.
TEST(CostsLayers, WholeCellRadiusIsSnapped) {
  OccupancyGrid g;
  g.width = g.height = 15;
  g.resolution = 0.05;
  g.data.assign(225, 0);
  g.data[7 * 15 + 7] = 100;
  GridBuildOptions o;
  o.robot_radius = 0.15;
  auto map = GridMap::build(g, o);
  ASSERT_TRUE(map) << map.error().message;
  EXPECT_EQ(map->layer({7, 7}), CellLayer::kOccupied);
  EXPECT_EQ(map->layer({10, 7}), CellLayer::kInflated);
  EXPECT_EQ(map->layer({7, 4}), CellLayer::kInflated);
  EXPECT_EQ(map->layer({10, 8}), CellLayer::kFree);
  EXPECT_EQ(map->layer({11, 7}), CellLayer::kFree);
  EXPECT_EQ(map->layer({9, 9}), CellLayer::kInflated);  // 2 sqrt 2 < 3
}

// ---------------------------------------------------------------------------------------------
// 2. Cell costs.

TEST(CostsCellCosts, EveryFreeCellMatchesBruteForce) {
  std::mt19937 rng(82002);
  int without = 0, with = 0, graded_cells = 0, gradient_cells = 0, ambiguous = 0;
  for (int trial = 0; trial < 600; ++trial) {
    Spec spec;
    if (trial % 5 == 0) spec.no_costs = true;
    if (trial % 7 == 0) spec.force_costs = !spec.no_costs;
    const Scenario s = random_scenario(rng, spec);
    SCOPED_TRACE("trial " + std::to_string(trial) + ": " + s.describe());
    const auto map = build_shared(s);
    ASSERT_TRUE(map);
    const Truth t = brute_force(s);
    const bool expect_costs = t.graded || s.options.inflation_radius > 0.0;
    bool any_free_cost = false;
    for (int32_t y = 0; y < t.height; ++y) {
      for (int32_t x = 0; x < t.width; ++x) {
        const Cell c{x, y};
        const size_t i = t.index(x, y);
        if (!expect_costs) {
          ASSERT_EQ(map->cost(c), 0.0) << "cell " << str(c);
          continue;
        }
        if (t.layer[i] != CellLayer::kFree) continue;
        const double got = map->cost(c);
        ASSERT_GE(got, 0.0) << "cell " << str(c);
        ASSERT_LT(got, 1.0) << "cell " << str(c);
        any_free_cost = any_free_cost || got > 0.0;
        if (t.ambiguous[i]) {
          ++ambiguous;
          continue;
        }
        ASSERT_NEAR(got, t.cost[i], 1e-6) << "cell " << str(c) << " value " << int{s.grid.at(x, y)}
                                          << " squared distance " << t.squared[i];
        const int v = s.grid.at(x, y);
        if (v > 0 && v < s.options.occupied_threshold) ++graded_cells;
        if (t.cost[i] > 0.0 && !(v > 0 && v < s.options.occupied_threshold)) ++gradient_cells;
      }
    }
    if (!expect_costs) {
      ++without;
      ASSERT_FALSE(map->has_costs());
      ASSERT_EQ(map->cost_data(), nullptr);
    } else {
      ++with;
      if (any_free_cost) {
        ASSERT_TRUE(map->has_costs());
      }
      if (map->has_costs()) {
        ASSERT_NE(map->cost_data(), nullptr);
      }
    }
  }
  EXPECT_GT(without, 30);
  EXPECT_GT(with, 150);
  EXPECT_GT(graded_cells, 10000);
  EXPECT_GT(gradient_cells, 5000);
  EXPECT_LT(ambiguous, 50);
}

// ---------------------------------------------------------------------------------------------
// 3. Optimality with costs.

TEST(CostsOptimality, AStarEqualsDijkstraForEveryWeightAndCornerPolicy) {
  std::mt19937 rng(83003);
  int compared = 0, unreachable = 0, detours = 0;
  for (int trial = 0; trial < 250; ++trial) {
    Spec spec;
    spec.max_side = 30;
    spec.force_costs = true;
    const Scenario s = random_scenario(rng, spec);
    SCOPED_TRACE("trial " + std::to_string(trial) + ": " + s.describe());
    const auto map = build_shared(s);
    ASSERT_TRUE(map);
    ASSERT_TRUE(map->has_costs());
    const auto cells = free_cells(*map);
    if (cells.size() < 2) continue;
    core::Planner planner(map);
    for (CornerPolicy policy : kAllCornerPolicies) {
      for (double w : {0.5, 2.0, 10.0}) {
        const Cell start = pick(rng, cells);
        const std::vector<double> best = dijkstra_from(*map, start, policy, w);
        for (int q = 0; q < 4; ++q) {
          const Cell goal = pick(rng, cells);
          SCOPED_TRACE("policy " + std::string(core::to_string(policy)) + " weight " +
                       std::to_string(w) + " start " + str(start) + " goal " + str(goal));
          PlannerOptions o = core::default_options(PlannerKind::kAStar);
          o.corner_policy = policy;
          o.cost_weight = w;
          const PlanResult r = planner.plan({start, goal}, o);
          const double optimum = best[static_cast<size_t>(goal.y) * map->width() + goal.x];
          if (!std::isfinite(optimum)) {
            ++unreachable;
            ASSERT_EQ(r.status.code, StatusCode::kNoValidPath) << r.status.message;
            continue;
          }
          ASSERT_TRUE(r.status.is_ok()) << r.status.message;
          ASSERT_TRUE(valid_raw_path(*map, r.raw_path, start, goal, policy, 1));
          const double got = oracle_path_cost(*map, r.raw_path, w);
          ASSERT_NEAR(got, optimum, 1e-9 * std::max(1.0, optimum));
          ++compared;
          const double shortest = reference_shortest_cost(*map, start, goal, policy);
          if (core::polyline_length(core::cell_centres(r.raw_path)) > shortest + 1e-6) ++detours;
        }
      }
    }
  }
  EXPECT_GT(compared, 3500);
  EXPECT_GT(unreachable, 80);
  EXPECT_GT(detours, 400);  // costs really change the paths
}

// Issue 15's invariant: with costs on, the exact planner's path is never dearer, under the cost
// model, than the path it plans with costs off (the binary path is a valid path of the same
// graph, priced by the oracle), and its final path after pruning and smoothing is never dearer
// than that either.
TEST(CostsOptimality, CostAwareAStarIsNeverDearerThanBinaryUnderTheCostModel) {
  std::mt19937 rng(83011);
  int compared = 0, cheaper = 0;
  for (int trial = 0; trial < 200; ++trial) {
    Spec spec;
    spec.max_side = 40;
    spec.force_costs = true;
    const Scenario s = random_scenario(rng, spec);
    SCOPED_TRACE("trial " + std::to_string(trial) + ": " + s.describe());
    const auto map = build_shared(s);
    ASSERT_TRUE(map);
    const auto cells = free_cells(*map);
    if (cells.size() < 2) continue;
    core::Planner planner(map);
    // Every pairing of corner policy and weight.
    const CornerPolicy policy = kAllCornerPolicies[trial % 3];
    const double w = std::vector<double>{0.5, 2.0, 10.0}[(trial / 3) % 3];
    for (int q = 0; q < 4; ++q) {
      const Cell start = pick(rng, cells), goal = pick(rng, cells);
      SCOPED_TRACE("weight " + std::to_string(w) + " start " + str(start) + " goal " + str(goal));
      PlannerOptions binary = core::default_options(PlannerKind::kAStar);
      binary.corner_policy = policy;
      PlannerOptions costed = binary;
      costed.cost_weight = w;
      const PlanResult off = planner.plan({start, goal}, binary);
      const PlanResult on = planner.plan({start, goal}, costed);
      ASSERT_EQ(off.status.code, on.status.code) << on.status.message;
      if (!on.status.is_ok()) continue;
      const double on_cost = oracle_path_cost(*map, on.raw_path, w);
      const double off_cost = oracle_path_cost(*map, off.raw_path, w);
      ASSERT_LE(on_cost, off_cost * (1.0 + 1e-9));
      cheaper += on_cost < off_cost * (1.0 - 1e-9);
      PlannerOptions post = costed;
      post.prune = post.smooth = true;
      const PlanResult final_path = planner.plan({start, goal}, post);
      ASSERT_TRUE(final_path.status.is_ok()) << final_path.status.message;
      ASSERT_LE(core::path_cost(*map, final_path.path, w, policy), off_cost * (1.0 + 1e-9));
      ++compared;
    }
  }
  EXPECT_GT(compared, 400);
  EXPECT_GT(cheaper, 50);  // costs really change the paths
}

TEST(CostsOptimality, OtherPlannersReturnValidPathsWithCosts) {
  std::mt19937 rng(83004);
  int checked = 0, long_moves = 0;
  for (int trial = 0; trial < 400; ++trial) {
    Spec spec;
    spec.force_costs = true;
    const Scenario s = random_scenario(rng, spec);
    SCOPED_TRACE("trial " + std::to_string(trial) + ": " + s.describe());
    const auto map = build_shared(s);
    ASSERT_TRUE(map);
    const auto cells = free_cells(*map);
    if (cells.size() < 2) continue;
    core::Planner planner(map);
    const CornerPolicy policy = kAllCornerPolicies[trial % 3];
    const double w = std::vector<double>{0.5, 2.0, 10.0, 100.0}[trial % 4];
    const Cell start = pick(rng, cells);
    const std::vector<double> best = dijkstra_from(*map, start, policy, w);
    for (int q = 0; q < 3; ++q) {
      const Cell goal = pick(rng, cells);
      const double optimum = best[static_cast<size_t>(goal.y) * map->width() + goal.x];
      for (PlannerKind kind : kCostPlanners) {
        if (kind == PlannerKind::kAStar) continue;
        SCOPED_TRACE(std::string(core::to_string(kind)) + " policy " +
                     std::string(core::to_string(policy)) + " weight " + std::to_string(w) +
                     " start " + str(start) + " goal " + str(goal));
        PlannerOptions o = core::default_options(kind);
        o.corner_policy = policy;
        o.cost_weight = w;
        const PlanResult r = planner.plan({start, goal}, o);
        if (!std::isfinite(optimum)) {
          ASSERT_EQ(r.status.code, StatusCode::kNoValidPath) << r.status.message;
          continue;
        }
        ASSERT_TRUE(r.status.is_ok()) << r.status.message;
        const int max_step = o.neighborhood == Neighborhood::kEight ? 1 : 2;
        ASSERT_TRUE(valid_raw_path(*map, r.raw_path, start, goal, policy, max_step));
        const double got = oracle_path_cost(*map, r.raw_path, w);
        // The oracle prices a path as path_cost does (the planners' move cost).
        ASSERT_NEAR(got, core::path_cost(*map, core::cell_centres(r.raw_path), w, policy),
                    1e-9 * std::max(1.0, got));
        if (max_step == 1) {
          ASSERT_GE(got, optimum * (1.0 - 1e-9));
        }
        for (size_t i = 1; i < r.raw_path.size(); ++i)
          long_moves += std::max(std::abs(r.raw_path[i].x - r.raw_path[i - 1].x),
                                 std::abs(r.raw_path[i].y - r.raw_path[i - 1].y)) == 2;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 2000);
  EXPECT_GT(long_moves, 300);
}

// The one rule for a cost_weight configured for every planner: dropped (and reported) only for a
// planner that plans on uniform costs.
TEST(CostsOptimality, OnlyUniformCostPlannersDropACostWeight) {
  for (PlannerKind kind : core::all_planner_kinds()) {
    SCOPED_TRACE(std::string(core::to_string(kind)));
    PlannerOptions o = core::default_options(kind);
    o.cost_weight = 2.0;
    EXPECT_EQ(core::drop_unsupported_costs(o), !core::supports_costs(kind));
    EXPECT_EQ(o.cost_weight, core::supports_costs(kind) ? 2.0 : 0.0);
    EXPECT_TRUE(core::validate(o).is_ok()) << core::validate(o).message;
    o.cost_weight = 0.0;
    EXPECT_FALSE(core::drop_unsupported_costs(o));
  }
}

TEST(CostsOptimality, JpsRefusesCostWeight) {
  std::mt19937 rng(83005);
  for (bool costs : {true, false}) {
    Spec spec;
    spec.force_costs = costs;
    spec.no_costs = !costs;
    spec.max_occupied = 0.1;
    const Scenario s = random_scenario(rng, spec);
    const auto map = build_shared(s);
    ASSERT_TRUE(map);
    const auto cells = free_cells(*map);
    ASSERT_GE(cells.size(), 2u);
    PlannerOptions o = core::default_options(PlannerKind::kJps);
    o.cost_weight = 1.0;
    const PlanResult r = core::plan_once(map, {cells.front(), cells.back()}, o);
    EXPECT_EQ(r.status.code, StatusCode::kInvalidRequest);
    EXPECT_TRUE(contains(r.status.message, "cost_weight")) << r.status.message;
    const core::Status v = core::validate(o);
    EXPECT_EQ(v.code, StatusCode::kInvalidRequest);
    EXPECT_TRUE(contains(v.message, "cost_weight")) << v.message;
    // cost_weight 0 is the binary jps, costs or not.
    o.cost_weight = 0.0;
    EXPECT_TRUE(core::validate(o).is_ok());
  }
}

// ---------------------------------------------------------------------------------------------
// 4. Post-processing with costs.

TEST(CostsPostprocess, PruningAndSmoothingNeverMakeAPathDearer) {
  std::mt19937 rng(84004);
  int checked = 0, pruned_cheaper = 0, smoothed = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    Spec spec;
    spec.force_costs = true;
    const Scenario s = random_scenario(rng, spec);
    SCOPED_TRACE("trial " + std::to_string(trial) + ": " + s.describe());
    const auto map = build_shared(s);
    ASSERT_TRUE(map);
    const auto cells = free_cells(*map);
    if (cells.size() < 2) continue;
    core::Planner planner(map);
    for (int q = 0; q < 3; ++q) {
      const Cell start = pick(rng, cells), goal = pick(rng, cells);
      const PlannerKind kind = kCostPlanners[rng() % kCostPlanners.size()];
      PlannerOptions o = core::default_options(kind);
      o.corner_policy = kAllCornerPolicies[rng() % 3];
      o.cost_weight = std::vector<double>{0.5, 2.0, 10.0, 100.0, 1000.0}[rng() % 5];
      o.prune = o.smooth = true;
      o.smoothing_distance = uniform(rng, 0.5, 3.0);
      SCOPED_TRACE(std::string(core::to_string(kind)) + " policy " +
                   std::string(core::to_string(o.corner_policy)) + " weight " +
                   std::to_string(o.cost_weight) + " start " + str(start) + " goal " + str(goal));
      const PlanResult r = planner.plan({start, goal}, o);
      if (!r.status.is_ok()) {
        ASSERT_EQ(r.status.code, StatusCode::kNoValidPath) << r.status.message;
        continue;
      }
      const double w = o.cost_weight;
      const double raw = core::path_cost(*map, core::cell_centres(r.raw_path), w, o.corner_policy);
      ASSERT_TRUE(std::isfinite(raw));
      ASSERT_NEAR(raw, oracle_path_cost(*map, r.raw_path, w), 1e-9 * std::max(1.0, raw));
      const double pruned = core::path_cost(*map, r.waypoints, w, o.corner_policy);
      const double final_cost = core::path_cost(*map, r.path, w, o.corner_policy);
      ASSERT_LE(pruned, raw * (1.0 + 1e-9));
      ASSERT_LE(final_cost, raw * (1.0 + 1e-9))
          << "raw " << raw << ", pruned " << pruned << ", final " << final_cost;
      ASSERT_EQ(r.path.front(), core::cell_centre(start));
      ASSERT_EQ(r.path.back(), core::cell_centre(goal));
      for (size_t i = 1; i < r.path.size(); ++i) {
        ASSERT_TRUE(segment_clear_sampled(*map, r.path[i - 1], r.path[i], o.corner_policy, 32))
            << "final segment " << i << ": " << r.path[i - 1].transpose() << " -> "
            << r.path[i].transpose();
      }
      ++checked;
      pruned_cheaper += pruned < raw * (1.0 - 1e-9);
      smoothed += r.path.size() > r.waypoints.size();
    }
  }
  EXPECT_GT(checked, 3000);
  EXPECT_GT(pruned_cheaper, 1000);
  EXPECT_GT(smoothed, 500);
}

// Section 4 pruning, written out here with the reference line of sight.
std::vector<Point2> reference_prune(const GridMap& map, const std::vector<Cell>& path,
                                    CornerPolicy policy) {
  std::vector<Point2> out = {core::cell_centre(path.front())};
  Cell anchor = path.front();
  size_t i = 1;
  while (i < path.size()) {
    if (reference_los_centres(map, anchor, path[i], policy)) {
      ++i;
    } else {
      anchor = path[i - 1];
      out.push_back(core::cell_centre(anchor));
    }
  }
  out.push_back(core::cell_centre(path.back()));
  return out;
}

// Where every cell a path and its shortcuts pass costs 0, the cost model is the length model: the
// pruned and smoothed path with costs is the binary one (a review found straight shortcuts
// refused because the step-by-step price of the stretch rounded one ulp below the shortcut's).
TEST(CostsPostprocess, CostFreeStretchesPruneAsWithoutCosts) {
  int compared = 0;
  for (int side = 5; side <= 61; side += 4) {
    core::OccupancyGrid grid;
    grid.width = grid.height = side;
    grid.data.assign(static_cast<size_t>(side) * side, 0);
    grid.data.back() = 10;  // one graded cell, in the far corner: the map has costs
    auto built = core::GridMap::build(grid);
    ASSERT_TRUE(built);
    ASSERT_TRUE(built->has_costs());
    auto map = std::make_shared<const core::GridMap>(std::move(built).value());
    core::Planner planner(map);
    for (int gx = 1; gx <= side - 2; gx += 3) {
      for (int gy = 0; gy <= side - 2; gy += 2) {
        for (PlannerKind kind : {PlannerKind::kAStar, PlannerKind::kVnsBaStar}) {
          SCOPED_TRACE(::testing::Message() << "side " << side << " goal (" << gx << ", " << gy
                                            << ") " << core::to_string(kind));
          PlannerOptions binary = core::default_options(kind);
          binary.prune = binary.smooth = true;
          PlannerOptions costed = binary;
          costed.cost_weight = 2.0;
          const PlanResult off = planner.plan({{0, 0}, {gx, gy}}, binary);
          const PlanResult on = planner.plan({{0, 0}, {gx, gy}}, costed);
          ASSERT_TRUE(off.status.is_ok() && on.status.is_ok());
          if (off.raw_path != on.raw_path) continue;  // equal-cost grid paths may differ
          EXPECT_EQ(on.waypoints, off.waypoints);
          EXPECT_EQ(on.path, off.path);
          ++compared;
        }
      }
    }
  }
  EXPECT_GT(compared, 1000);
}

TEST(CostsPostprocess, PruneWithCostWeightZeroIsSectionFour) {
  std::mt19937 rng(84005);
  int paths = 0, walks = 0;
  for (int trial = 0; trial < 150; ++trial) {
    const Scenario s = random_scenario(rng);
    SCOPED_TRACE("trial " + std::to_string(trial) + ": " + s.describe());
    const auto map = build_shared(s);
    ASSERT_TRUE(map);
    const auto cells = free_cells(*map);
    if (cells.size() < 2) continue;
    const CornerPolicy policy = kAllCornerPolicies[trial % 3];
    // Planner paths (valid) and random walks over the map (steps may be blocked).
    PlannerOptions o = core::default_options(kCostPlanners[trial % kCostPlanners.size()]);
    o.corner_policy = policy;
    o.prune = o.smooth = false;
    const PlanResult r = core::plan_once(map, {pick(rng, cells), pick(rng, cells)}, o);
    std::vector<std::vector<Cell>> inputs;
    if (r.status.is_ok() && r.raw_path.size() >= 2) inputs.push_back(r.raw_path);
    std::vector<Cell> walk = {pick(rng, cells)};
    for (int k = 0; k < 30; ++k) {
      Cell next{walk.back().x + uniform_int(rng, -1, 1), walk.back().y + uniform_int(rng, -1, 1)};
      if (map->in_bounds(next) && next != walk.back()) walk.push_back(next);
    }
    inputs.push_back(walk);
    for (size_t k = 0; k < inputs.size(); ++k) {
      const std::vector<Cell>& path = inputs[k];
      const auto plain = core::prune_path(*map, path, policy);
      ASSERT_TRUE(core::prune_path(*map, path, policy, nullptr, 0.0) == plain);
      if (k == 0 && inputs.size() == 2) {
        ASSERT_TRUE(plain == reference_prune(*map, path, policy));
        ++paths;
      } else {
        ++walks;
      }
    }
  }
  EXPECT_GT(paths, 50);
  EXPECT_GT(walks, 100);
}

// ---------------------------------------------------------------------------------------------
// 5. cost_weight 0 is the binary planner of sections 1-7.

void expect_same_plan(const PlanResult& a, const PlanResult& b) {
  ASSERT_EQ(a.status.code, b.status.code) << a.status.message << " / " << b.status.message;
  ASSERT_TRUE(a.raw_path == b.raw_path);
  ASSERT_TRUE(a.waypoints == b.waypoints);
  ASSERT_TRUE(a.path == b.path);
  ASSERT_EQ(a.metrics.expanded, b.metrics.expanded);
  if (a.status.is_ok()) {
    ASSERT_EQ(a.metrics.clearance_m, b.metrics.clearance_m);
    ASSERT_EQ(a.metrics.length_cells, b.metrics.length_cells);
  }
}

TEST(CostsWeightZero, EqualsThePlanOnTheMapWithoutCosts) {
  std::mt19937 rng(85005);
  int compared = 0;
  for (int trial = 0; trial < 300; ++trial) {
    Spec spec;
    spec.force_costs = true;
    const Scenario s = random_scenario(rng, spec);
    Scenario binary = s;
    binary.options.inflation_radius = 0.0;
    for (int8_t& v : binary.grid.data)
      if (v > 0 && v < binary.options.occupied_threshold) v = 0;
    SCOPED_TRACE("trial " + std::to_string(trial) + ": " + s.describe());
    const auto with = build_shared(s);
    const auto without = build_shared(binary);
    ASSERT_TRUE(with && without);
    ASSERT_TRUE(with->has_costs());
    ASSERT_FALSE(without->has_costs());
    const auto cells = free_cells(*with);
    ASSERT_EQ(cells.size(), free_cells(*without).size());
    if (cells.size() < 2) continue;
    core::Planner planner_with(with), planner_without(without);
    for (int q = 0; q < 3; ++q) {
      const PlanQuery query{pick(rng, cells), pick(rng, cells)};
      const CornerPolicy policy = kAllCornerPolicies[rng() % 3];
      for (PlannerKind kind : core::all_planner_kinds()) {
        for (bool post : {false, true}) {
          PlannerOptions o = core::default_options(kind);
          o.corner_policy = kind == PlannerKind::kJps ? CornerPolicy::kNever : policy;
          if (post) o.prune = o.smooth = true;
          SCOPED_TRACE(std::string(core::to_string(kind)) + (post ? " with" : " without") +
                       " post-processing, start " + str(query.start) + " goal " + str(query.goal));
          const PlanResult a = planner_with.plan(query, o);
          const PlanResult b = planner_without.plan(query, o);
          expect_same_plan(a, b);
          if (::testing::Test::HasFatalFailure()) return;
          // And on a map without costs any weight is the binary planner.
          if (core::supports_costs(kind)) {
            PlannerOptions weighted = o;
            weighted.cost_weight = 5.0;
            expect_same_plan(planner_without.plan(query, weighted), b);
            if (::testing::Test::HasFatalFailure()) return;
          }
          ++compared;
        }
      }
    }
  }
  EXPECT_GT(compared, 7500);
}

// ---------------------------------------------------------------------------------------------
// 6. Clearance.

double distance_to_square(const Point2& p, const Cell& c) {
  const double dx = std::max({c.x - p.x(), p.x() - (c.x + 1.0), 0.0});
  const double dy = std::max({c.y - p.y(), p.y() - (c.y + 1.0), 0.0});
  return std::sqrt(dx * dx + dy * dy);
}

// Samples of a polyline: every vertex, and each segment cut into the fewest equal pieces at most
// `step` cells long (docs/algorithm.md section 8 allows clearance from samples 0.1 cell apart).
std::vector<Point2> clearance_samples(const std::vector<Point2>& polyline, double step) {
  std::vector<Point2> out;
  if (polyline.empty()) return out;
  out.push_back(polyline.front());
  for (size_t i = 1; i < polyline.size(); ++i) {
    const Point2& a = polyline[i - 1];
    const Point2& b = polyline[i];
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step)));
    for (int k = 1; k <= n; ++k) out.push_back(a + (b - a) * (static_cast<double>(k) / n));
  }
  return out;
}

// Smallest distance (cells) from the samples to the square of any obstacle cell (occupied, and
// unknown with inflate_unknown).
double brute_clearance_cells(const Truth& t, const std::vector<Point2>& polyline, double step) {
  double best = kInf;
  for (const Point2& p : clearance_samples(polyline, step))
    for (const Cell& b : t.obstacles) best = std::min(best, distance_to_square(p, b));
  return best;
}

// path_clearance_cells is the exact distance from the polyline: never more than the sampled
// brute force, and less by at most half a sample step (every point of the polyline is that close
// to a sample, and the distance to a set changes no faster than the point moves).
void expect_clearance_within_sampling(double got, double sampled, double step) {
  if (std::isinf(sampled)) {
    ASSERT_EQ(got, kInf);
    return;
  }
  ASSERT_LE(got, sampled + 1e-9);
  ASSERT_GE(got, sampled - step / 2 - 1e-9);
  ASSERT_GE(got, 0.0);
}

// Exact where the answer is known in closed form.
TEST(ClearanceMetric, IsTheExactDistanceFromTheSegments) {
  std::vector<std::string> rows(11, std::string(11, '.'));
  rows[10 - 5][5] = '#';  // obstacle square [5, 6] x [5, 6]
  auto built = core::GridMap::from_rows(rows);
  ASSERT_TRUE(built);
  const core::GridMap& map = built.value();
  // Passing above it: 7.5 - 6.
  EXPECT_DOUBLE_EQ(core::path_clearance_cells(map, {{0.5, 7.5}, {10.5, 7.5}}), 1.5);
  // The diagonal x + y = 8 passes its corner (5, 5) at sqrt 2 (samples 0.1 apart would miss the
  // nearest point and overstate it).
  EXPECT_NEAR(core::path_clearance_cells(map, {{0.0, 8.0}, {8.0, 0.0}}), std::sqrt(2.0), 1e-12);
  // Through its corner: 0.
  EXPECT_EQ(core::path_clearance_cells(map, {{3.0, 7.0}, {7.0, 3.0}}), 0.0);
  // A single vertex: its distance to the square.
  EXPECT_DOUBLE_EQ(core::path_clearance_cells(map, {{8.0, 9.0}}), std::hypot(2.0, 3.0));
}

TEST(ClearanceMetric, WithinHalfASampleOfTheBruteForceOnPlannedPaths) {
  std::mt19937 rng(86006);
  int checked = 0, smoothed = 0;
  for (int trial = 0; trial < 500; ++trial) {
    const auto [s, map, t, cells] = random_trial(rng);
    SCOPED_TRACE("trial " + std::to_string(trial) + ": " + s.describe());
    ASSERT_TRUE(map);
    if (cells.size() < 2) continue;
    core::Planner planner(map);
    for (int q = 0; q < 3; ++q) {
      const PlannerKind kind = kCostPlanners[rng() % kCostPlanners.size()];
      PlannerOptions o = core::default_options(kind);
      o.corner_policy = kAllCornerPolicies[rng() % 3];
      o.prune = o.smooth = rng() % 2 == 0;
      if (map->has_costs()) o.cost_weight = std::vector<double>{0.0, 1.0, 10.0}[rng() % 3];
      const Cell start = pick(rng, cells), goal = pick(rng, cells);
      SCOPED_TRACE(std::string(core::to_string(kind)) + " start " + str(start) + " goal " +
                   str(goal));
      const PlanResult r = planner.plan({start, goal}, o);
      if (!r.status.is_ok()) {
        EXPECT_TRUE(std::isnan(r.metrics.clearance_m));
        continue;
      }
      const double sampled = brute_clearance_cells(t, r.path, 0.1);
      expect_clearance_within_sampling(r.metrics.clearance_m / s.grid.resolution, sampled, 0.1);
      ++checked;
      smoothed += r.path.size() > r.waypoints.size();
    }
  }
  EXPECT_GT(checked, 800);
  EXPECT_GT(smoothed, 80);
}

TEST(ClearanceMetric, InfiniteWithoutObstacles) {
  std::mt19937 rng(86007);
  for (int trial = 0; trial < 20; ++trial) {
    Spec spec;
    spec.no_obstacles = true;  // graded values and unknown cells (allowed), no obstacle
    const Scenario s = random_scenario(rng, spec);
    SCOPED_TRACE(s.describe());
    const auto map = build_shared(s);
    ASSERT_TRUE(map);
    const auto cells = free_cells(*map);
    ASSERT_EQ(static_cast<int64_t>(cells.size()), map->cell_count());
    PlannerOptions o = core::default_options(PlannerKind::kVnsBaStar);
    if (map->has_costs()) o.cost_weight = 2.0;
    const PlanResult r = core::plan_once(map, {pick(rng, cells), pick(rng, cells)}, o);
    ASSERT_TRUE(r.status.is_ok()) << r.status.message;
    EXPECT_EQ(r.metrics.clearance_m, kInf);
    EXPECT_EQ(core::path_clearance_cells(*map, r.path), kInf);
  }
}

TEST(ClearancePolylines, WithinHalfASampleOfTheBruteForceOnRandomPolylines) {
  std::mt19937 rng(86008);
  int finite = 0;
  for (int trial = 0; trial < 200; ++trial) {
    Spec spec;
    if (trial % 10 == 0) spec.no_obstacles = true;
    const Scenario s = random_scenario(rng, spec);
    SCOPED_TRACE("trial " + std::to_string(trial) + ": " + s.describe());
    const auto map = build_shared(s);
    ASSERT_TRUE(map);
    const Truth t = brute_force(s);
    EXPECT_EQ(core::path_clearance_cells(*map, {}), kInf);
    for (int k = 0; k < 5; ++k) {
      std::vector<Point2> polyline;
      const int n = uniform_int(rng, 1, 8);
      for (int i = 0; i < n; ++i) {
        Point2 p(uniform(rng, 0.0, t.width), uniform(rng, 0.0, t.height));
        if (rng() % 6 == 0) p = p.array().round().matrix();  // lattice points, map edges included
        if (rng() % 6 == 0) p = (p.array().floor() + 0.5).matrix();  // centres
        polyline.push_back(p);
      }
      const double sampled = brute_clearance_cells(t, polyline, 0.02);
      const double got = core::path_clearance_cells(*map, polyline);
      SCOPED_TRACE("polyline " + std::to_string(k));
      expect_clearance_within_sampling(got, sampled, 0.02);
      finite += std::isfinite(sampled);
    }
  }
  EXPECT_GT(finite, 700);
}

// Against every obstacle square, exactly: long flat, steep, diagonal and axis-parallel segments
// (the metric reads rows for flat segments and columns for steep ones, and only the nearest
// obstacles of each line on either side of the segment), with and without inflation; and grid
// paths, runs from cell centre to cell centre along the axes and diagonals, mostly with line of
// sight and some cutting corners or crossing obstacles (once half a cell has been measured the
// metric skips the runs with line of sight, which cannot come nearer: the skip must be taken
// often and change nothing).
TEST(ClearancePolylines, EqualsTheExactDistanceToTheNearestObstacleSquare) {
  std::mt19937 rng(86009);
  int finite = 0, inflated = 0, grid_finite = 0, skippable = 0;
  auto cell_of = [](const Point2& p) {
    return Cell{static_cast<int32_t>(p.x()), static_cast<int32_t>(p.y())};
  };
  for (int trial = 0; trial < 150; ++trial) {
    const Scenario s = random_scenario(rng);
    SCOPED_TRACE("trial " + std::to_string(trial) + ": " + s.describe());
    const auto map = build_shared(s);
    ASSERT_TRUE(map);
    const Truth t = brute_force(s);
    inflated += map->build_options().robot_radius > 0.0;
    // The exact distance and the metric's, which must agree; nullopt where there is no obstacle.
    auto compare = [&](const std::vector<Point2>& polyline) -> std::optional<double> {
      double exact = kInf;
      for (const Cell& b : t.obstacles)
        exact = std::min(exact, polyline_square_distance(polyline, b));
      const double got = core::path_clearance_cells(*map, polyline);
      if (std::isinf(exact)) {
        EXPECT_EQ(got, kInf);
        return std::nullopt;
      }
      EXPECT_NEAR(got, exact, 1e-9);
      return exact;
    };
    for (int k = 0; k < 6; ++k) {
      SCOPED_TRACE("grid path " + std::to_string(k));
      std::vector<Point2> polyline{
          Point2(uniform_int(rng, 0, t.width - 1) + 0.5, uniform_int(rng, 0, t.height - 1) + 0.5)};
      const int n = uniform_int(rng, 2, 12);
      for (int i = 1; i < n; ++i) {
        Point2 next;
        for (int attempt = 0; attempt < 12; ++attempt) {
          const int dx = uniform_int(rng, -1, 1), dy = uniform_int(rng, -1, 1);
          next = (polyline.back() + uniform_int(rng, 1, 6) * Point2(dx, dy))
                     .cwiseMax(Point2(0.5, 0.5))
                     .cwiseMin(Point2(t.width - 0.5, t.height - 0.5));
          if (core::line_of_sight(*map, cell_of(polyline.back()), cell_of(next),
                                  core::CornerPolicy::kNever))
            break;
        }
        polyline.push_back(next);
      }
      const std::optional<double> exact = compare(polyline);
      if (!exact) continue;
      ++grid_finite;
      // A run after the first with line of sight, on a path within half a cell of an obstacle.
      for (size_t i = 2; *exact <= 0.5 && i < polyline.size(); ++i) {
        const Cell a = cell_of(polyline[i - 1]), b = cell_of(polyline[i]);
        if (!(a == b) && core::line_of_sight(*map, a, b, core::CornerPolicy::kNever)) {
          ++skippable;
          break;
        }
      }
    }
    for (int k = 0; k < 6; ++k) {
      std::vector<Point2> polyline;
      const int n = uniform_int(rng, 1, 6);
      for (int i = 0; i < n; ++i) {
        Point2 p(uniform(rng, 0.0, t.width), uniform(rng, 0.0, t.height));
        if (!polyline.empty() && rng() % 3 == 0) {  // axis-parallel or 45 degrees from the last
          const Point2& last = polyline.back();
          const double run = uniform(rng, -8.0, 8.0);
          const int shape = static_cast<int>(rng() % 3);
          p = last + (shape == 0   ? Point2(run, 0.0)
                      : shape == 1 ? Point2(0.0, run)
                                   : Point2(run, run));
          p = p.cwiseMax(Point2(0.0, 0.0)).cwiseMin(Point2(t.width, t.height));
        }
        if (rng() % 4 == 0) p = (p.array().floor() + 0.5).matrix();  // centres
        polyline.push_back(p);
      }
      SCOPED_TRACE("polyline " + std::to_string(k));
      if (compare(polyline)) ++finite;
    }
  }
  EXPECT_GT(finite, 700);
  EXPECT_GT(inflated, 20);
  EXPECT_GT(grid_finite, 600);
  EXPECT_GT(skippable, 150);
}

// ---------------------------------------------------------------------------------------------
// 7. Clearance rises with the cost weight.

TEST(ClearanceCorridor, RisesWithCostWeight) {
  OccupancyGrid g;
  g.width = 60;
  g.height = 21;
  g.resolution = 0.1;
  g.data.assign(static_cast<size_t>(g.width) * g.height, 0);
  auto set = [&](int x, int y, int8_t v) { g.data[static_cast<size_t>(y) * g.width + x] = v; };
  for (int x = 0; x < g.width; ++x) {
    set(x, 0, 100);
    set(x, g.height - 1, 100);
  }
  // Pillars on the centre line, which the start and goal share, and two near the walls: the
  // shortest path brushes the central pillars, a weighted one keeps away from them.
  for (const Cell& p : std::vector<Cell>{
           {20, 10}, {21, 10}, {20, 11}, {40, 9}, {40, 10}, {41, 10}, {30, 4}, {30, 16}})
    set(p.x, p.y, 100);
  GridBuildOptions build;
  build.robot_radius = 0.15;
  build.inflation_radius = 1.5;
  build.cost_scaling_factor = 3.0;
  auto built = GridMap::build(g, build);
  ASSERT_TRUE(built) << built.error().message;
  const auto map = std::make_shared<const GridMap>(std::move(built).value());
  core::Planner planner(map);
  const PlanQuery query{{2, 10}, {57, 10}};
  std::vector<double> clearance;
  for (double w : {0.0, 1.0, 10.0}) {
    PlannerOptions o = core::default_options(PlannerKind::kAStar);
    o.cost_weight = w;
    const PlanResult r = planner.plan(query, o);
    ASSERT_TRUE(r.status.is_ok()) << r.status.message;
    clearance.push_back(r.metrics.clearance_m);
  }
  EXPECT_LE(clearance[0], clearance[1]);
  EXPECT_LE(clearance[1], clearance[2]);
  EXPECT_GT(clearance[1], clearance[0] + 0.05);  // half a cell at least
  EXPECT_GT(clearance[2], clearance[0] + 0.05);
}

// ---------------------------------------------------------------------------------------------
// 8. Goal and start tolerance.
//
// The oracle of reachability is component_labels (test_support.hpp): a breadth-first search over
// the whole grid under the planners' moves, independent of the planner's floods. The expected
// cell is then chosen by brute force over every cell of the map.

struct Nearest {
  std::optional<Cell> cell;
  double squared = kInf;  // cells^2
};

// Every free cell whose centre lies within tolerance_m metres of p (cell coordinates), in
// row-major order: brute force over the whole map.
std::vector<Cell> brute_free_within(const GridMap& map, const Point2& p, double tolerance_m) {
  std::vector<Cell> out;
  for (int32_t y = 0; y < map.height(); ++y)
    for (int32_t x = 0; x < map.width(); ++x)
      if (cell_free(map, x, y) &&
          std::hypot(x + 0.5 - p.x(), y + 0.5 - p.y()) * map.resolution() <= tolerance_m)
        out.push_back({x, y});
  return out;
}

// The one of those nearest to p, ties to the lower row-major index, among the cells `keep`
// accepts (all of them without it).
Nearest brute_nearest_free(const GridMap& map, const Point2& p, double tolerance_m,
                           const std::function<bool(const Cell&)>& keep = nullptr) {
  Nearest best;
  for (const Cell& c : brute_free_within(map, p, tolerance_m)) {
    const double squared = (core::cell_centre(c) - p).squaredNorm();
    if ((!keep || keep(c)) && squared < best.squared) best = {c, squared};
  }
  return best;
}

Point2 point_in(std::mt19937& rng, const Cell& c) {
  if (rng() % 2 == 0) return core::cell_centre(c);
  return {c.x + uniform(rng, 0.01, 0.99), c.y + uniform(rng, 0.01, 0.99)};
}

std::vector<Cell> cells_where(const Truth& t, const std::function<bool(CellLayer)>& keep) {
  std::vector<Cell> out;
  for (int32_t y = 0; y < t.height; ++y)
    for (int32_t x = 0; x < t.width; ++x)
      if (keep(t.layer[t.index(x, y)])) out.push_back({x, y});
  return out;
}

// A planner and a corner policy it accepts, at random: what is reachable depends on the policy.
PlannerOptions random_policy_options(std::mt19937& rng) {
  static const PlannerKind kinds[] = {PlannerKind::kAStar,
                                      PlannerKind::kWeightedAStar,
                                      PlannerKind::kBidirectionalAStar,
                                      PlannerKind::kAlternatingBidirectionalAStar,
                                      PlannerKind::kVnsBaStar,
                                      PlannerKind::kJps};
  PlannerOptions o = core::default_options(kinds[rng() % 6]);
  o.corner_policy =
      o.planner == PlannerKind::kJps ? core::CornerPolicy::kNever : kAllCornerPolicies[rng() % 3];
  return o;
}

// Same component of `labels` (component_labels of a map `width` cells wide).
bool connected(const std::vector<int32_t>& labels, int32_t width, const Cell& a, const Cell& b) {
  const int32_t la = labels[static_cast<size_t>(a.y) * width + a.x];
  return la >= 0 && la == labels[static_cast<size_t>(b.y) * width + b.x];
}

// The nearest free cell within tolerance_m of p, and the nearest of those in the component of
// `anchor` (labels from component_labels).
struct Choice {
  Nearest any, reachable;
};
Choice brute_choice(const GridMap& map, const std::vector<int32_t>& labels, const Point2& p,
                    double tolerance_m, const Cell& anchor) {
  return {brute_nearest_free(map, p, tolerance_m),
          brute_nearest_free(map, p, tolerance_m, [&](const Cell& c) {
            return connected(labels, map.width(), c, anchor);
          })};
}

// The goal is moved to the nearest free cell within goal_tolerance that the start reaches; a
// sealed-off free cell nearer to the goal is passed over. NO_VALID_PATH, saying that free cells
// were there but unreachable, when none is reachable; GOAL_OCCUPIED when none is free. A moved
// goal always plans.
TEST(ToleranceGoal, BlockedGoalMovesToTheNearestReachableFreeCell) {
  std::mt19937 rng(88008);
  int moved = 0, refused = 0, unreachable = 0, passed_over = 0, occupied_goals = 0;
  for (int trial = 0; trial < 1500; ++trial) {
    Spec spec;
    spec.max_occupied = 0.5;  // walls enough to seal specks off
    const Scenario s = random_scenario(rng, spec);
    SCOPED_TRACE("trial " + std::to_string(trial) + ": " + s.describe());
    const auto map = build_shared(s);
    ASSERT_TRUE(map);
    const Truth t = brute_force(s);
    const auto free = cells_where(t, [](CellLayer l) { return l == CellLayer::kFree; });
    const auto blocked = cells_where(t, [](CellLayer l) { return l != CellLayer::kFree; });
    if (free.empty() || blocked.empty()) continue;
    // Occupied goals first, as a robot's goal on a wall.
    const auto occupied = cells_where(t, [](CellLayer l) { return l == CellLayer::kOccupied; });
    const Cell goal =
        !occupied.empty() && rng() % 3 != 0 ? pick(rng, occupied) : pick(rng, blocked);
    occupied_goals += t.layer[t.index(goal.x, goal.y)] == CellLayer::kOccupied;
    const Point2 goal_point = point_in(rng, goal);
    const Cell start = pick(rng, free);
    PlannerOptions o = random_policy_options(rng);
    o.goal_tolerance = uniform(rng, 0.2, 4.0) * s.grid.resolution;
    const PlanQuery q(start, goal, std::nullopt, goal_point);
    SCOPED_TRACE("start " + str(start) + " goal " + str(goal) + " point (" +
                 std::to_string(goal_point.x()) + ", " + std::to_string(goal_point.y()) +
                 ") tolerance " + std::to_string(o.goal_tolerance) + " corner_policy " +
                 std::string(core::to_string(o.corner_policy)));
    const auto [any, expected] = brute_choice(*map, component_labels(*map, o.corner_policy),
                                              goal_point, o.goal_tolerance, start);
    const auto endpoints = core::resolve_endpoints(*map, q, o);
    const PlanResult r = core::plan_once(map, q, o);
    if (!any.cell) {
      ++refused;
      ASSERT_FALSE(endpoints);
      ASSERT_EQ(endpoints.error().code, StatusCode::kGoalOccupied);
      ASSERT_TRUE(contains(endpoints.error().message, "no free cell within goal_tolerance"))
          << endpoints.error().message;
      ASSERT_EQ(r.status.code, StatusCode::kGoalOccupied);
      continue;
    }
    if (!expected.cell) {
      ++unreachable;
      ASSERT_FALSE(endpoints);
      ASSERT_EQ(endpoints.error().code, StatusCode::kNoValidPath);
      const std::string& m = endpoints.error().message;
      ASSERT_TRUE(contains(m, "within goal_tolerance")) << m;
      ASSERT_TRUE(contains(m, "none of them is reachable from the start")) << m;
      ASSERT_EQ(r.status.code, StatusCode::kNoValidPath);
      ASSERT_EQ(r.status.message, m);
      // The request itself is well-formed: only the plan finds the cells unreachable.
      ASSERT_TRUE(core::check_query(*map, q, o).is_ok());
      continue;
    }
    ++moved;
    passed_over += *expected.cell != *any.cell;
    ASSERT_TRUE(endpoints) << endpoints.error().message;
    ASSERT_EQ(endpoints->goal, *expected.cell)
        << "got " << str(endpoints->goal) << ", expected " << str(*expected.cell);
    ASSERT_EQ(map->layer(endpoints->goal), CellLayer::kFree);
    ASSERT_TRUE(endpoints->goal_adjusted);
    const double moved_m = std::sqrt(expected.squared) * s.grid.resolution;
    ASSERT_NEAR(endpoints->goal_moved_m, moved_m, 1e-9 * std::max(1.0, moved_m));
    ASSERT_EQ(endpoints->goal_point, core::cell_centre(*expected.cell));
    ASSERT_EQ(endpoints->start, start);
    ASSERT_FALSE(endpoints->start_adjusted);
    ASSERT_EQ(endpoints->start_moved_m, 0.0);
    // The plan uses the same endpoints, and always finds a path.
    ASSERT_TRUE(r.status.is_ok()) << r.status.message;
    ASSERT_EQ(r.endpoints.goal, *expected.cell);
    ASSERT_TRUE(r.endpoints.goal_adjusted);
    ASSERT_EQ(r.raw_path.front(), start);
    ASSERT_EQ(r.raw_path.back(), *expected.cell);
  }
  EXPECT_GT(moved, 350);
  EXPECT_GT(refused, 350);
  EXPECT_GT(unreachable, 150);
  EXPECT_GT(passed_over, 25);  // the nearest free cell was sealed off, a farther one reachable
  EXPECT_GT(occupied_goals, 300);
}

TEST(ToleranceGoal, BlockedGoalWithoutToleranceNamesTheLayer) {
  std::mt19937 rng(88009);
  int seen[4] = {0, 0, 0, 0};
  for (int trial = 0; trial < 100; ++trial) {
    const Scenario s = random_scenario(rng);
    const auto map = build_shared(s);
    ASSERT_TRUE(map);
    const Truth t = brute_force(s);
    const auto free = cells_where(t, [](CellLayer l) { return l == CellLayer::kFree; });
    const auto blocked = cells_where(t, [](CellLayer l) { return l != CellLayer::kFree; });
    if (free.empty() || blocked.empty()) continue;
    const Cell goal = pick(rng, blocked);
    const CellLayer layer = t.layer[t.index(goal.x, goal.y)];
    const auto endpoints = core::resolve_endpoints(*map, {pick(rng, free), goal},
                                                   core::default_options(PlannerKind::kAStar));
    ASSERT_FALSE(endpoints);
    ASSERT_EQ(endpoints.error().code, StatusCode::kGoalOccupied);
    const std::string& m = endpoints.error().message;
    ASSERT_TRUE(contains(m, std::string(core::to_string(layer)))) << m;
    if (layer == CellLayer::kInflated) {
      ASSERT_TRUE(contains(m, "robot_radius")) << m;
    }
    ++seen[static_cast<int>(layer)];
  }
  EXPECT_GT(seen[static_cast<int>(CellLayer::kOccupied)], 10);
  EXPECT_GT(seen[static_cast<int>(CellLayer::kInflated)], 10);
  EXPECT_GT(seen[static_cast<int>(CellLayer::kUnknown)], 0);
}

TEST(ToleranceGoal, GoalOutsideTheMapIsMovedIn) {
  std::mt19937 rng(88010);
  int moved = 0, refused = 0, unreachable = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const Scenario s = random_scenario(rng);
    SCOPED_TRACE("trial " + std::to_string(trial) + ": " + s.describe());
    const auto map = build_shared(s);
    ASSERT_TRUE(map);
    const Truth t = brute_force(s);
    const auto free = cells_where(t, [](CellLayer l) { return l == CellLayer::kFree; });
    if (free.empty()) continue;
    Cell goal;
    do {
      goal = {uniform_int(rng, -4, t.width + 3), uniform_int(rng, -4, t.height + 3)};
    } while (map->in_bounds(goal));
    const Point2 goal_point = point_in(rng, goal);
    PlannerOptions o = random_policy_options(rng);
    o.goal_tolerance = uniform(rng, 0.5, 6.0) * s.grid.resolution;
    const Cell start = pick(rng, free);
    const PlanQuery q(start, goal, std::nullopt, goal_point);
    SCOPED_TRACE("start " + str(start) + " goal " + str(goal) + " tolerance " +
                 std::to_string(o.goal_tolerance));
    const auto [any, expected] = brute_choice(*map, component_labels(*map, o.corner_policy),
                                              goal_point, o.goal_tolerance, start);
    const auto endpoints = core::resolve_endpoints(*map, q, o);
    if (!any.cell) {
      ++refused;
      ASSERT_FALSE(endpoints);
      ASSERT_EQ(endpoints.error().code, StatusCode::kGoalOutsideMap);
      ASSERT_TRUE(contains(endpoints.error().message, "goal_tolerance"))
          << endpoints.error().message;
      continue;
    }
    if (!expected.cell) {
      ++unreachable;
      ASSERT_FALSE(endpoints);
      ASSERT_EQ(endpoints.error().code, StatusCode::kNoValidPath);
      ASSERT_TRUE(contains(endpoints.error().message, "is outside the map"))
          << endpoints.error().message;
      ASSERT_TRUE(contains(endpoints.error().message, "none of them is reachable"))
          << endpoints.error().message;
      continue;
    }
    ++moved;
    ASSERT_TRUE(endpoints) << endpoints.error().message;
    ASSERT_EQ(endpoints->goal, *expected.cell) << "got " << str(endpoints->goal);
    ASSERT_TRUE(endpoints->goal_adjusted);
    const double moved_m = std::sqrt(expected.squared) * s.grid.resolution;
    ASSERT_NEAR(endpoints->goal_moved_m, moved_m, 1e-9 * std::max(1.0, moved_m));
    // Without tolerance: outside, not moved.
    o.goal_tolerance = 0.0;
    const auto exact = core::resolve_endpoints(*map, q, o);
    ASSERT_FALSE(exact);
    ASSERT_EQ(exact.error().code, StatusCode::kGoalOutsideMap);
  }
  EXPECT_GT(moved, 60);
  EXPECT_GT(refused, 100);
  EXPECT_GT(unreachable, 20);
}

// Tolerances and the gradient's reach are whole cells when metres / resolution is within 1e-9 of
// one, as robot_radius is (0.15 / 0.05 = 2.9999999999999996 in doubles): a review found the free
// cell exactly goal_tolerance away refused, and the cell exactly inflation_radius away costless.
TEST(ToleranceGoal, WholeCellTolerancesAndGradientReachAreSnapped) {
  auto line = core::GridMap::from_rows({"...#####"}, 0.05);
  ASSERT_TRUE(line);
  auto map = std::make_shared<const core::GridMap>(std::move(line).value());
  PlannerOptions o = core::default_options(PlannerKind::kAStar);
  o.goal_tolerance = 0.15;  // 3 cells: from the centre of (5, 0) to the centre of (2, 0)
  const auto endpoints = core::resolve_endpoints(*map, {{0, 0}, {5, 0}}, o);
  ASSERT_TRUE(endpoints) << endpoints.error().message;
  EXPECT_EQ(endpoints->goal, (Cell{2, 0}));
  EXPECT_NEAR(endpoints->goal_moved_m, 0.15, 1e-12);

  core::OccupancyGrid grid;
  grid.width = 6;
  grid.height = 1;
  grid.resolution = 0.1;
  grid.data = {100, 0, 0, 0, 0, 0};
  core::GridBuildOptions build;
  build.robot_radius = 0.1;
  build.inflation_radius = 0.3;  // 0.3 / 0.1 = 2.9999999999999996
  build.cost_scaling_factor = 3.0;
  auto gradient = core::GridMap::build(grid, build);
  ASSERT_TRUE(gradient);
  EXPECT_TRUE(gradient->blocked({1, 0}));  // within robot_radius
  EXPECT_NEAR(gradient->cost({3, 0}), 0.99 * std::exp(-3.0 * (0.3 - 0.1)), 1e-6);
  EXPECT_EQ(gradient->cost({4, 0}), 0.0);
}

// With the tolerances off, errors come in the order of sections 1-7: a goal outside the map is
// reported before a blocked start.
TEST(ToleranceGoal, WithoutToleranceAGoalOutsideComesBeforeABlockedStart) {
  auto built = core::GridMap::from_rows({"#.."});
  ASSERT_TRUE(built);
  auto map = std::make_shared<const core::GridMap>(std::move(built).value());
  core::Planner planner(map);
  PlannerOptions o = core::default_options(PlannerKind::kAStar);
  EXPECT_EQ(planner.plan({{0, 0}, {5, 0}}, o).status.code, StatusCode::kGoalOutsideMap);
  EXPECT_EQ(planner.plan({{0, 0}, {2, 0}}, o).status.code, StatusCode::kStartOccupied);
  EXPECT_EQ(planner.plan({{-1, 0}, {5, 0}}, o).status.code, StatusCode::kStartOutsideMap);
}

TEST(ToleranceGoal, FreeGoalIsNeverMoved) {
  std::mt19937 rng(88011);
  for (int trial = 0; trial < 50; ++trial) {
    const Scenario s = random_scenario(rng);
    const auto map = build_shared(s);
    ASSERT_TRUE(map);
    const auto cells = free_cells(*map);
    if (cells.size() < 2) continue;
    const Cell goal = pick(rng, cells);
    PlannerOptions o = core::default_options(PlannerKind::kAStar);
    o.goal_tolerance = o.start_tolerance = 5.0 * s.grid.resolution;
    const auto e = core::resolve_endpoints(
        *map, PlanQuery(pick(rng, cells), goal, std::nullopt, point_in(rng, goal)), o);
    ASSERT_TRUE(e) << e.error().message;
    EXPECT_EQ(e->goal, goal);
    EXPECT_FALSE(e->goal_adjusted);
    EXPECT_FALSE(e->start_adjusted);
    EXPECT_EQ(e->goal_moved_m, 0.0);
    EXPECT_EQ(e->start_moved_m, 0.0);
  }
}

TEST(ToleranceStart, InflatedStartMovesObstacleStartNever) {
  std::mt19937 rng(88012);
  int moved = 0, refused = 0, unreachable = 0, passed_over = 0, occupied_starts = 0,
      unknown_starts = 0;
  for (int trial = 0; trial < 1000; ++trial) {
    Spec spec;
    spec.min_radius_cells = 1;
    const Scenario s = random_scenario(rng, spec);
    SCOPED_TRACE("trial " + std::to_string(trial) + ": " + s.describe());
    const auto map = build_shared(s);
    ASSERT_TRUE(map);
    const Truth t = brute_force(s);
    const auto free = cells_where(t, [](CellLayer l) { return l == CellLayer::kFree; });
    const auto inflated = cells_where(t, [](CellLayer l) { return l == CellLayer::kInflated; });
    const auto obstacles = t.obstacles;
    if (free.empty() || inflated.empty()) continue;
    const Cell goal = pick(rng, free);
    // Inflated start, with tolerance: moved to the nearest free cell that reaches the goal.
    const Cell start = pick(rng, inflated);
    const Point2 start_point = point_in(rng, start);
    PlannerOptions o = random_policy_options(rng);
    o.start_tolerance = uniform(rng, 0.2, 4.0) * s.grid.resolution;
    const PlanQuery q(start, goal, start_point, std::nullopt);
    SCOPED_TRACE("start " + str(start) + " goal " + str(goal) + " tolerance " +
                 std::to_string(o.start_tolerance));
    const auto [any, expected] = brute_choice(*map, component_labels(*map, o.corner_policy),
                                              start_point, o.start_tolerance, goal);
    const auto endpoints = core::resolve_endpoints(*map, q, o);
    if (expected.cell) {
      ++moved;
      passed_over += *expected.cell != *any.cell;
      ASSERT_TRUE(endpoints) << endpoints.error().message;
      ASSERT_EQ(endpoints->start, *expected.cell) << "got " << str(endpoints->start);
      ASSERT_EQ(map->layer(endpoints->start), CellLayer::kFree);
      ASSERT_TRUE(endpoints->start_adjusted);
      const double moved_m = std::sqrt(expected.squared) * s.grid.resolution;
      ASSERT_NEAR(endpoints->start_moved_m, moved_m, 1e-9 * std::max(1.0, moved_m));
      ASSERT_EQ(endpoints->start_point, core::cell_centre(*expected.cell));
      ASSERT_EQ(endpoints->goal, goal);
      ASSERT_FALSE(endpoints->goal_adjusted);
      const PlanResult r = core::plan_once(map, q, o);
      ASSERT_TRUE(r.status.is_ok()) << r.status.message;
      ASSERT_EQ(r.raw_path.front(), *expected.cell);
      ASSERT_EQ(r.raw_path.back(), goal);
      ASSERT_TRUE(r.endpoints.start_adjusted);
    } else if (any.cell) {
      ++unreachable;
      ASSERT_FALSE(endpoints);
      ASSERT_EQ(endpoints.error().code, StatusCode::kNoValidPath);
      const std::string& m = endpoints.error().message;
      ASSERT_TRUE(contains(m, "within start_tolerance")) << m;
      ASSERT_TRUE(contains(m, "none of them connects to the goal")) << m;
    } else {
      ++refused;
      ASSERT_FALSE(endpoints);
      ASSERT_EQ(endpoints.error().code, StatusCode::kStartOccupied);
      ASSERT_TRUE(contains(endpoints.error().message, "start_tolerance"))
          << endpoints.error().message;
    }
    // Inflated start without tolerance: refused, saying why.
    o.start_tolerance = 0.0;
    const auto exact = core::resolve_endpoints(*map, q, o);
    ASSERT_FALSE(exact);
    ASSERT_EQ(exact.error().code, StatusCode::kStartOccupied);
    ASSERT_TRUE(contains(exact.error().message, "inflation")) << exact.error().message;
    ASSERT_TRUE(contains(exact.error().message, "robot_radius")) << exact.error().message;
    // A start in an obstacle is never moved, whatever the tolerance.
    if (!obstacles.empty()) {
      const Cell bad = pick(rng, obstacles);
      o.start_tolerance = 10.0 * s.grid.resolution;
      const auto refused_start = core::resolve_endpoints(*map, {bad, goal}, o);
      ASSERT_FALSE(refused_start);
      ASSERT_EQ(refused_start.error().code, StatusCode::kStartOccupied);
      const bool occupied = t.layer[t.index(bad.x, bad.y)] == CellLayer::kOccupied;
      ASSERT_TRUE(contains(refused_start.error().message, occupied ? "occupied" : "unknown"))
          << refused_start.error().message;
      (occupied ? occupied_starts : unknown_starts)++;
      const PlanResult r = core::plan_once(map, {bad, goal}, o);
      ASSERT_EQ(r.status.code, StatusCode::kStartOccupied);
    }
  }
  EXPECT_GT(moved, 100);
  EXPECT_GT(refused, 300);
  EXPECT_GT(unreachable, 150);
  EXPECT_GT(passed_over, 10);
  EXPECT_GT(occupied_starts, 300);
  EXPECT_GT(unknown_starts, 10);
}

// Both ends moved: the start first, to the nearest free cell within start_tolerance connected to
// any free cell within goal_tolerance of the goal; then the goal, to the nearest free cell within
// goal_tolerance that start reaches.
TEST(ToleranceStart, BothEndsMovedStartFirstTowardsTheGoalsCandidates) {
  std::mt19937 rng(88013);
  int moved = 0, unreachable = 0, not_nearest = 0;
  for (int trial = 0; trial < 1500; ++trial) {
    Spec spec;
    spec.min_radius_cells = 1;
    spec.max_occupied = 0.45;
    const Scenario s = random_scenario(rng, spec);
    SCOPED_TRACE("trial " + std::to_string(trial) + ": " + s.describe());
    const auto map = build_shared(s);
    ASSERT_TRUE(map);
    const Truth t = brute_force(s);
    const auto inflated = cells_where(t, [](CellLayer l) { return l == CellLayer::kInflated; });
    const auto blocked = cells_where(t, [](CellLayer l) { return l != CellLayer::kFree; });
    if (inflated.empty()) continue;
    const Cell start = pick(rng, inflated), goal = pick(rng, blocked);
    const Point2 start_point = point_in(rng, start), goal_point = point_in(rng, goal);
    PlannerOptions o = random_policy_options(rng);
    o.start_tolerance = uniform(rng, 0.5, 4.0) * s.grid.resolution;
    o.goal_tolerance = uniform(rng, 0.5, 4.0) * s.grid.resolution;
    const PlanQuery q(start, goal, start_point, goal_point);
    SCOPED_TRACE("start " + str(start) + " goal " + str(goal));
    const auto labels = component_labels(*map, o.corner_policy);
    const auto goal_candidates = brute_free_within(*map, goal_point, o.goal_tolerance);
    const Nearest any_start = brute_nearest_free(*map, start_point, o.start_tolerance);
    if (!any_start.cell || goal_candidates.empty()) continue;  // refusals: tested above
    const Nearest expected_start =
        brute_nearest_free(*map, start_point, o.start_tolerance, [&](const Cell& c) {
          return std::any_of(goal_candidates.begin(), goal_candidates.end(),
                             [&](const Cell& g) { return connected(labels, t.width, c, g); });
        });
    const auto endpoints = core::resolve_endpoints(*map, q, o);
    if (!expected_start.cell) {
      ++unreachable;
      ASSERT_FALSE(endpoints);
      ASSERT_EQ(endpoints.error().code, StatusCode::kNoValidPath);
      ASSERT_TRUE(contains(endpoints.error().message, "none of them connects to any of the " +
                                                          std::to_string(goal_candidates.size()) +
                                                          " free cells within goal_tolerance"))
          << endpoints.error().message;
      continue;
    }
    const Nearest expected_goal = brute_nearest_free(
        *map, goal_point, o.goal_tolerance,
        [&](const Cell& c) { return connected(labels, t.width, c, *expected_start.cell); });
    ASSERT_TRUE(expected_goal.cell);
    ++moved;
    not_nearest += *expected_start.cell != *any_start.cell;
    ASSERT_TRUE(endpoints) << endpoints.error().message;
    ASSERT_EQ(endpoints->start, *expected_start.cell) << "got " << str(endpoints->start);
    ASSERT_EQ(endpoints->goal, *expected_goal.cell) << "got " << str(endpoints->goal);
    ASSERT_TRUE(endpoints->start_adjusted && endpoints->goal_adjusted);
    const PlanResult r = core::plan_once(map, q, o);
    ASSERT_TRUE(r.status.is_ok()) << r.status.message;
    ASSERT_EQ(r.raw_path.front(), *expected_start.cell);
    ASSERT_EQ(r.raw_path.back(), *expected_goal.cell);
  }
  EXPECT_GT(moved, 90);
  EXPECT_GT(unreachable, 100);
  EXPECT_GT(not_nearest, 8);
}

// The case a robot meets: a goal clicked 0.1 m inside a wall (0.05 m cells), whose nearest free
// cell is a speck sealed inside the wall. The plan goes to the room's side of the wall, farther
// but reachable; with a tolerance that reaches only the speck, NO_VALID_PATH says so.
TEST(ToleranceGoal, AGoalInsideAWallSkipsTheSealedSpeckNearestToIt) {
  // 40 x 24 cells at 0.05 m, origin (0, 0); a wall 8 cells thick (rows 10..17) across the room,
  // with one free cell (20, 13) sealed inside it. Row 0 is the bottom row.
  std::vector<std::string> rows(24, std::string(40, '.'));
  for (int y = 10; y <= 17; ++y) rows[23 - y] = std::string(40, '#');
  rows[23 - 13][20] = '.';
  auto built = GridMap::from_rows(rows, 0.05);
  ASSERT_TRUE(built);
  const auto map = std::make_shared<const GridMap>(std::move(built).value());
  // The wall's face is y = 10 cells; the goal (20.5, 12.0) is 2 cells (0.1 m) beyond it, in the
  // wall cell (20, 12). The speck's centre is 1.5 cells (0.075 m) from it, the room's cell
  // (20, 9) 2.5 cells (0.125 m).
  const PlanQuery q({5, 2}, {20, 12}, std::nullopt, Point2(20.5, 12.0));
  ASSERT_TRUE(map->blocked({20, 12}));
  ASSERT_TRUE(map->free({20, 13}));
  for (PlannerKind kind : {PlannerKind::kAStar, PlannerKind::kVnsBaStar, PlannerKind::kJps}) {
    SCOPED_TRACE(std::string(core::to_string(kind)));
    PlannerOptions o = core::default_options(kind);
    o.goal_tolerance = 0.2;
    const PlanResult r = core::plan_once(map, q, o);
    ASSERT_TRUE(r.status.is_ok()) << r.status.message;
    EXPECT_EQ(r.endpoints.goal, (Cell{20, 9}));
    EXPECT_TRUE(r.endpoints.goal_adjusted);
    EXPECT_NEAR(r.endpoints.goal_moved_m, 0.125, 1e-12);
    EXPECT_EQ(r.raw_path.back(), (Cell{20, 9}));
    // A tolerance of 0.1 m reaches the speck only: free, but sealed off.
    o.goal_tolerance = 0.1;
    const PlanResult sealed = core::plan_once(map, q, o);
    EXPECT_EQ(sealed.status.code, StatusCode::kNoValidPath) << sealed.status.message;
    EXPECT_TRUE(contains(sealed.status.message,
                         "goal (1.025, 0.600) m, in cell (20, 12), is in an occupied cell"))
        << sealed.status.message;
    EXPECT_TRUE(contains(sealed.status.message,
                         "1 free cell lies within goal_tolerance 0.100 m (the nearest (1.025, "
                         "0.675) m, cell (20, 13)), but none of them is reachable from the start "
                         "(0.275, 0.125) m, in cell (5, 2)"))
        << sealed.status.message;
  }
}

// Real maps (Moving AI benchmark maps, read from the shared data folder): goals on blocked cells
// beside free ones, half of them beside a small sealed pocket, moved within goal_tolerance from a
// benchmark scenario's start; against the whole-grid oracle, for every corner policy.
TEST(ToleranceGoal, OnMovingAiMapsTheGoalMovesToTheNearestReachableFreeCell) {
  const std::string dir = data_path("movingai");
  if (!std::filesystem::exists(dir)) GTEST_SKIP() << "Moving AI data not found at " << dir;
  std::mt19937 rng(88014);
  int moved = 0, passed_over = 0, unreachable = 0;
  for (const char* name : {"random512-20-0", "arena", "den312d", "Berlin_0_256"}) {
    SCOPED_TRACE(name);
    MovingAiCase loaded;
    ASSERT_TRUE(load_movingai(dir + "/" + name + ".map", &loaded));
    const auto& map = loaded.map;
    core::Planner planner(map);
    const int32_t w = map->width();
    for (core::CornerPolicy policy : kAllCornerPolicies) {
      SCOPED_TRACE(std::string(core::to_string(policy)));
      const auto labels = component_labels(*map, policy);
      std::vector<int64_t> size;
      for (const int32_t l : labels) {
        if (l < 0) continue;
        if (static_cast<size_t>(l) >= size.size()) size.resize(l + 1, 0);
        ++size[l];
      }
      // Blocked cells beside a free one, and those beside a pocket of fewer than 50 cells.
      std::vector<Cell> beside_free, beside_pocket;
      for (int32_t y = 0; y < map->height(); ++y) {
        for (int32_t x = 0; x < w; ++x) {
          if (!map->blocked(x, y)) continue;
          bool free = false, pocket = false;
          for (int dy = -1; dy <= 1; ++dy) {
            for (int dx = -1; dx <= 1; ++dx) {
              if (!cell_free(*map, x + dx, y + dy)) continue;
              free = true;
              pocket = pocket || size[labels[static_cast<size_t>(y + dy) * w + x + dx]] < 50;
            }
          }
          if (free) beside_free.push_back({x, y});
          if (pocket) beside_pocket.push_back({x, y});
        }
      }
      ASSERT_FALSE(beside_free.empty());
      PlannerOptions o = core::default_options(PlannerKind::kVnsBaStar);
      o.corner_policy = policy;
      for (int i = 0; i < 40; ++i) {
        const Cell start = pick(rng, loaded.scenarios).start;
        const Cell goal = !beside_pocket.empty() && i % 2 == 0 ? pick(rng, beside_pocket)
                                                               : pick(rng, beside_free);
        const Point2 point = point_in(rng, goal);
        // Beyond 2.13 cells: a free cell beside the goal's is always within it.
        o.goal_tolerance = uniform(rng, 2.2, 5.0);  // metres = cells here
        SCOPED_TRACE("start " + str(start) + " goal " + str(goal) + " tolerance " +
                     std::to_string(o.goal_tolerance));
        const auto [any, expected] = brute_choice(*map, labels, point, o.goal_tolerance, start);
        const PlanResult r = planner.plan(PlanQuery(start, goal, std::nullopt, point), o);
        ASSERT_TRUE(any.cell);
        if (!expected.cell) {
          ++unreachable;
          ASSERT_EQ(r.status.code, StatusCode::kNoValidPath) << r.status.message;
          ASSERT_TRUE(contains(r.status.message, "none of them is reachable")) << r.status.message;
          continue;
        }
        ++moved;
        passed_over += *expected.cell != *any.cell;
        ASSERT_TRUE(r.status.is_ok()) << r.status.message;
        ASSERT_EQ(r.endpoints.goal, *expected.cell) << "got " << str(r.endpoints.goal);
        ASSERT_EQ(r.raw_path.back(), *expected.cell);
      }
    }
  }
  EXPECT_GT(moved, 300);
  EXPECT_GT(passed_over, 5);
  EXPECT_GT(unreachable, 20);
}

// The floods poll the plan's budget: a goal beside a wall whose nearest free cell lies in the
// half of the map the start cannot reach (about 640,000 cells to exhaust), under a tenth of the
// time the resolution takes unbounded, ends in TIMEOUT, and a raised cancel flag in CANCELED,
// both naming the stage.
TEST(ToleranceGoal, TheReachabilityFloodsHonourTheBudget) {
  constexpr int32_t kWidth = 1601, kHeight = 800;
  core::OccupancyGrid grid;
  grid.width = kWidth;
  grid.height = kHeight;
  grid.resolution = 1.0;
  grid.data.assign(static_cast<size_t>(kWidth) * kHeight, 0);
  for (int32_t y = 0; y < kHeight; ++y) grid.data[static_cast<size_t>(y) * kWidth + 800] = 100;
  auto built = GridMap::build(grid);
  ASSERT_TRUE(built);
  const auto map = std::make_shared<const GridMap>(std::move(built).value());
  // The goal point (800.9, 400.5): the sealed-off right side's (801, 400) is 0.6 cells away, the
  // start's side (799, 400) 1.4.
  const PlanQuery q({10, 10}, {800, 400}, std::nullopt, Point2(800.9, 400.5));
  PlannerOptions o = core::default_options(PlannerKind::kAStar);
  o.goal_tolerance = 2.0;
  using Clock = std::chrono::steady_clock;
  double fastest_us = kInf;
  for (int run = 0; run < 3; ++run) {
    const auto t0 = Clock::now();
    const auto e = core::resolve_endpoints(*map, q, o);
    fastest_us =
        std::min(fastest_us, std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
    ASSERT_TRUE(e) << e.error().message;
    ASSERT_EQ(e->goal, (Cell{799, 400}));
  }
  RecordProperty("unbounded_resolution_us", static_cast<int>(fastest_us));
  ASSERT_GT(fastest_us, 1000.0) << "the flood is too quick to show a budget cut it short";
  const auto budget_us = std::chrono::microseconds(static_cast<int64_t>(fastest_us / 10));
  core::PlanningBudget budget(Clock::now(), budget_us, nullptr);
  const auto cut = core::resolve_endpoints(*map, q, o, &budget);
  ASSERT_FALSE(cut);
  EXPECT_EQ(cut.error().code, StatusCode::kTimeout);
  EXPECT_TRUE(contains(cut.error().message, "elapsed while choosing a goal within goal_tolerance"))
      << cut.error().message;

  core::Planner planner(map);
  o.max_planning_time = budget_us;
  const PlanResult timed = planner.plan(q, o);
  EXPECT_EQ(timed.status.code, StatusCode::kTimeout) << timed.status.message;
  EXPECT_TRUE(contains(timed.status.message, "while choosing a goal")) << timed.status.message;
  o.max_planning_time = std::chrono::microseconds(0);
  std::atomic<bool> cancel{true};
  const PlanResult canceled = planner.plan(q, o, &cancel);
  EXPECT_EQ(canceled.status.code, StatusCode::kCanceled) << canceled.status.message;
  EXPECT_EQ(canceled.status.message,
            "planning canceled while choosing a goal within goal_tolerance");
  cancel = false;
  const PlanResult planned = planner.plan(q, o, &cancel);
  ASSERT_TRUE(planned.status.is_ok()) << planned.status.message;
  EXPECT_EQ(planned.endpoints.goal, (Cell{799, 400}));
}

// check_query, the verdict a request gets before it waits for a planner, does not flood: it
// accepts a goal whose only free cells within goal_tolerance are sealed off (the plan then says
// NO_VALID_PATH, as it does for a free goal the start cannot reach).
TEST(ToleranceGoal, CheckQueryLeavesReachabilityToThePlan) {
  auto built = GridMap::from_rows({"...#...", "...#.#.", "...###."});
  ASSERT_TRUE(built);
  const auto map = std::make_shared<const GridMap>(std::move(built).value());
  PlannerOptions o = core::default_options(PlannerKind::kAStar);
  o.goal_tolerance = 1.0;
  const PlanQuery q({0, 0}, {5, 0}, std::nullopt, std::nullopt);  // (5, 0) is blocked
  EXPECT_TRUE(core::check_query(*map, q, o).is_ok());
  EXPECT_EQ(core::plan_once(map, q, o).status.code, StatusCode::kNoValidPath);
}

// ---------------------------------------------------------------------------------------------
// 8b. Exact end poses: the path begins at the requested start and ends at the requested goal.

// Heading changes above 1e-6 rad at the interior vertices, by atan2 here (section 7's turns).
int count_turns(const std::vector<Point2>& polyline) {
  int turns = 0;
  for (size_t i = 1; i + 1 < polyline.size(); ++i) {
    const Point2 a = polyline[i] - polyline[i - 1], b = polyline[i + 1] - polyline[i];
    const double change = std::abs(std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b)));
    turns += change > 1e-6;
  }
  return turns;
}

// turn_stats against atan2 at every vertex between two legs of some length: on grid walks (unit
// legs, straight runs, repeated points; the turns it takes from a table) exactly, and on
// polylines with legs of any length.
TEST(TurnStats, EqualsTheAtan2OfEveryVertex) {
  std::mt19937 rng(2024);
  int unit_turns = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const bool grid_walk = trial % 2 == 0;
    std::vector<Point2> polyline = {Point2(0.5, 0.5)};
    std::uniform_real_distribution<double> leg(-3.0, 3.0);
    for (int run = 0; run < 1 + static_cast<int>(rng() % 8); ++run) {
      const Point2 step =
          grid_walk ? Point2(static_cast<int>(rng() % 3) - 1.0, static_cast<int>(rng() % 3) - 1.0)
                    : Point2(leg(rng), leg(rng));
      for (int k = 0; k < 1 + static_cast<int>(rng() % 4); ++k)
        polyline.push_back(polyline.back() + step);
    }
    int turns = 0;
    double total_deg = 0.0;
    for (size_t i = 1; i + 1 < polyline.size(); ++i) {
      const Point2 a = polyline[i] - polyline[i - 1], b = polyline[i + 1] - polyline[i];
      // A repeated point (a zero leg) turns nowhere (atan2 would read -0 as a reversal).
      if (a.squaredNorm() == 0.0 || b.squaredNorm() == 0.0) continue;
      const double change = std::abs(std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b)));
      if (change > core::kTurnEpsilonRad) {
        ++turns;
        total_deg += change * 180.0 / M_PI;
      }
    }
    const core::TurnStats stats = core::turn_stats(polyline);
    ASSERT_EQ(stats.turns, turns) << "trial " << trial;
    if (grid_walk) {
      ASSERT_EQ(stats.total_angle_deg, total_deg) << "trial " << trial;
      unit_turns += turns;
    } else {
      ASSERT_NEAR(stats.total_angle_deg, total_deg, 1e-9 * std::max(1.0, total_deg));
    }
  }
  EXPECT_GT(unit_turns, 300);
}

// Every planner, corner policy, cost weight and post-processing, from and to random points inside
// random free cells: the final path's first and last points are the requested points (to 1e-12,
// in cells and in metres), every segment passes the sampled line-of-sight oracle, the path costs
// no more than the same plan joined to its cell centres, and length, turns and clearance are
// those of this path.
TEST(ExactEnds, ThePathBeginsAndEndsAtTheRequestedPoints) {
  std::mt19937 rng(88101);
  int checked = 0, dropped_centre = 0, kept_centre = 0, smoothed = 0;
  for (int trial = 0; trial < 600; ++trial) {
    const auto [s, map, t, cells] = random_trial(rng);
    SCOPED_TRACE("trial " + std::to_string(trial) + ": " + s.describe());
    ASSERT_TRUE(map);
    if (cells.size() < 2) continue;
    core::Planner planner(map);
    for (int q = 0; q < 3; ++q) {
      PlannerOptions o = random_policy_options(rng);
      if (map->has_costs() && o.planner != PlannerKind::kJps)
        o.cost_weight = std::vector<double>{0.0, 1.0, 10.0}[rng() % 3];
      o.prune = rng() % 4 != 0;
      o.smooth = o.prune && rng() % 2 == 0;
      const Cell start = pick(rng, cells), goal = pick(rng, cells);
      const Point2 start_point = point_in(rng, start), goal_point = point_in(rng, goal);
      SCOPED_TRACE(std::string(core::to_string(o.planner)) + " " +
                   std::string(core::to_string(o.corner_policy)) + " weight " +
                   std::to_string(o.cost_weight) + " prune " + std::to_string(o.prune) +
                   " smooth " + std::to_string(o.smooth) + " start (" +
                   std::to_string(start_point.x()) + ", " + std::to_string(start_point.y()) +
                   ") goal (" + std::to_string(goal_point.x()) + ", " +
                   std::to_string(goal_point.y()) + ")");
      const PlanResult r = planner.plan(PlanQuery(start, goal, start_point, goal_point), o);
      const PlanResult centred = planner.plan(PlanQuery(start, goal), o);
      ASSERT_EQ(r.status.code, centred.status.code) << r.status.message;
      if (!r.status.is_ok()) continue;
      ++checked;
      ASSERT_EQ(r.raw_path, centred.raw_path);  // the same search
      ASSERT_NEAR((r.path.front() - start_point).norm(), 0.0, 1e-12);
      ASSERT_NEAR((r.path.back() - goal_point).norm(), 0.0, 1e-12);
      ASSERT_EQ(r.waypoints.front(), r.path.front());
      ASSERT_EQ(r.waypoints.back(), r.path.back());
      const Eigen::Vector2d start_world(s.grid.origin_x + start_point.x() * s.grid.resolution,
                                        s.grid.origin_y + start_point.y() * s.grid.resolution);
      const Eigen::Vector2d goal_world(s.grid.origin_x + goal_point.x() * s.grid.resolution,
                                       s.grid.origin_y + goal_point.y() * s.grid.resolution);
      ASSERT_NEAR((r.world_path.front() - start_world).norm(), 0.0, 1e-12);
      ASSERT_NEAR((r.world_path.back() - goal_world).norm(), 0.0, 1e-12);
      ASSERT_EQ(r.world_path.size(), r.path.size());
      for (size_t i = 1; i < r.path.size(); ++i) {
        ASSERT_TRUE(segment_clear_sampled(*map, r.path[i - 1], r.path[i], o.corner_policy, 32))
            << "segment " << i << ": " << r.path[i - 1].transpose() << " -> "
            << r.path[i].transpose();
      }
      // No dearer than the centred plan's waypoints joined to the exact points by plain segments.
      std::vector<Point2> joined = centred.waypoints;
      if (joined.front() != start_point) joined.insert(joined.begin(), start_point);
      if (joined.back() != goal_point) joined.push_back(goal_point);
      const double w = map->has_costs() ? o.cost_weight : 0.0;
      const double exact_cost = core::path_cost(*map, r.waypoints, w, o.corner_policy);
      const double joined_cost = core::path_cost(*map, joined, w, o.corner_policy);
      ASSERT_TRUE(std::isfinite(exact_cost));
      ASSERT_LE(exact_cost, joined_cost * (1.0 + 1e-9));
      // The waypoints are the centred ones, the exact ends, and no more.
      ASSERT_LE(r.waypoints.size(), joined.size());
      ASSERT_GE(r.waypoints.size() + 2, joined.size());
      if (o.prune && r.waypoints.size() < joined.size()) ++dropped_centre;
      if (r.waypoints.size() == joined.size() && joined.size() > centred.waypoints.size())
        ++kept_centre;
      if (!o.prune) {
        ASSERT_EQ(r.waypoints, joined);
      }
      // The metrics are those of this path.
      double length = 0.0;
      for (size_t i = 1; i < r.path.size(); ++i) length += (r.path[i] - r.path[i - 1]).norm();
      ASSERT_NEAR(r.metrics.length_cells, length, 1e-9 * std::max(1.0, length));
      ASSERT_NEAR(r.metrics.length_m, length * s.grid.resolution, 1e-9 * std::max(1.0, length));
      ASSERT_EQ(r.metrics.turns, count_turns(r.waypoints));
      expect_clearance_within_sampling(r.metrics.clearance_m / s.grid.resolution,
                                       brute_clearance_cells(t, r.path, 0.1), 0.1);
      smoothed += r.path.size() > r.waypoints.size();
    }
  }
  EXPECT_GT(checked, 800);
  EXPECT_GT(dropped_centre, 300);
  EXPECT_GT(kept_centre, 20);
  EXPECT_GT(smoothed, 50);
}

// The report's example: (7.5, 4.5) m on a 0.05 m grid is the corner of cell (150, 90), whose
// centre is (7.525, 4.525) m. The path and the poses the node publishes begin there exactly, and
// end at the requested goal, with the goal's yaw.
TEST(ExactEnds, PosesStartAndEndAtTheRequestedWorldPoints) {
  core::OccupancyGrid grid;
  grid.width = 200;
  grid.height = 120;
  grid.resolution = 0.05;
  grid.data.assign(static_cast<size_t>(grid.width) * grid.height, 0);
  for (int32_t y = 20; y < 110; ++y) grid.data[static_cast<size_t>(y) * grid.width + 100] = 100;
  auto built = GridMap::build(grid);
  ASSERT_TRUE(built);
  const auto map = std::make_shared<const GridMap>(std::move(built).value());
  const Point2 start_point = map->world_to_grid(7.5, 4.5);
  const Point2 goal_point = map->world_to_grid(1.2345, 3.21);
  const auto start = map->world_to_cell(7.5, 4.5), goal = map->world_to_cell(1.2345, 3.21);
  ASSERT_TRUE(start && goal);
  ASSERT_EQ(*start, (Cell{150, 90}));
  for (PlannerKind kind : {PlannerKind::kVnsBaStar, PlannerKind::kAStar, PlannerKind::kJps}) {
    SCOPED_TRACE(std::string(core::to_string(kind)));
    const PlanResult r = core::plan_once(map, PlanQuery(*start, *goal, start_point, goal_point),
                                         core::default_options(kind));
    ASSERT_TRUE(r.status.is_ok()) << r.status.message;
    EXPECT_NEAR(r.world_path.front().x(), 7.5, 1e-12);
    EXPECT_NEAR(r.world_path.front().y(), 4.5, 1e-12);
    EXPECT_NEAR(r.world_path.back().x(), 1.2345, 1e-12);
    EXPECT_NEAR(r.world_path.back().y(), 3.21, 1e-12);
    const auto poses = core::path_poses(r.world_path, 0.05, 0.75);
    ASSERT_GE(poses.size(), 2u);
    EXPECT_NEAR(poses.front().x, 7.5, 1e-12);
    EXPECT_NEAR(poses.front().y, 4.5, 1e-12);
    EXPECT_NEAR(poses.back().x, 1.2345, 1e-12);
    EXPECT_NEAR(poses.back().y, 3.21, 1e-12);
    EXPECT_NEAR(poses.back().yaw, 0.75, 1e-12);
  }
}

// A goal moved by goal_tolerance ends at the used cell's centre (there is no requested point in a
// free cell to reach); the start still begins at its requested point.
TEST(ExactEnds, AMovedGoalEndsAtTheUsedCellsCentre) {
  auto built = GridMap::from_rows({"........", "....##..", "....##..", "........"}, 0.1);
  ASSERT_TRUE(built);
  const auto map = std::make_shared<const GridMap>(std::move(built).value());
  PlannerOptions o = core::default_options(PlannerKind::kVnsBaStar);
  o.goal_tolerance = 0.2;
  const Point2 start_point(0.3, 0.8), goal_point(4.2, 1.7);  // the goal in wall cell (4, 1)
  const PlanResult r = core::plan_once(map, PlanQuery({0, 0}, {4, 1}, start_point, goal_point), o);
  ASSERT_TRUE(r.status.is_ok()) << r.status.message;
  ASSERT_TRUE(r.endpoints.goal_adjusted);
  EXPECT_EQ(r.path.front(), start_point);
  EXPECT_EQ(r.path.back(), core::cell_centre(r.endpoints.goal));
  EXPECT_EQ(r.endpoints.goal_point, core::cell_centre(r.endpoints.goal));
  EXPECT_EQ(r.endpoints.start_point, start_point);
}

// Points at the cells' centres change nothing: the plan is the one without points, bit for bit
// (the Moving AI benchmarks plan cell to cell).
TEST(ExactEnds, PointsAtTheCentresGiveThePlanWithoutPoints) {
  std::mt19937 rng(88102);
  for (int trial = 0; trial < 100; ++trial) {
    auto map = random_shared_map(rng, 30, 20, 0.25);
    ASSERT_TRUE(map);
    const auto cells = free_cells(*map);
    if (cells.size() < 2) continue;
    const Cell start = pick(rng, cells), goal = pick(rng, cells);
    const PlannerOptions o = random_policy_options(rng);
    const PlanResult a = core::plan_once(map, PlanQuery(start, goal), o);
    const PlanResult b = core::plan_once(
        map, PlanQuery(start, goal, core::cell_centre(start), core::cell_centre(goal)), o);
    ASSERT_EQ(a.status.code, b.status.code);
    ASSERT_EQ(a.waypoints, b.waypoints);
    ASSERT_EQ(a.path, b.path);
    ASSERT_EQ(a.metrics.length_cells, b.metrics.length_cells);
    ASSERT_EQ(a.metrics.turns, b.metrics.turns);
  }
}

// ---------------------------------------------------------------------------------------------
// 9. Bad values are refused, naming the key.

TEST(CostsValidation, BadPlannerValuesNameTheKey) {
  const auto refused = [](const PlannerOptions& o, const std::string& key) {
    const core::Status s = core::validate(o);
    EXPECT_EQ(s.code, StatusCode::kInvalidRequest) << key;
    EXPECT_TRUE(contains(s.message, key)) << s.message;
  };
  for (PlannerKind kind : kCostPlanners) {
    for (double bad : {-1.0, -1e-9, kNaN, kInf, -kInf, 1000.5, 1e9}) {
      PlannerOptions o = core::default_options(kind);
      o.cost_weight = bad;
      refused(o, "cost_weight");
    }
    for (double good : {0.0, 1e-9, 1.0, 1000.0}) {
      PlannerOptions o = core::default_options(kind);
      o.cost_weight = good;
      EXPECT_TRUE(core::validate(o).is_ok()) << good;
    }
  }
  for (double bad : {-1.0, -1e-9, kNaN, kInf, -kInf}) {
    PlannerOptions o = core::default_options(PlannerKind::kVnsBaStar);
    o.goal_tolerance = bad;
    refused(o, "goal_tolerance");
    o.goal_tolerance = 0.0;
    o.start_tolerance = bad;
    refused(o, "start_tolerance");
  }
  PlannerOptions ok = core::default_options(PlannerKind::kVnsBaStar);
  ok.goal_tolerance = ok.start_tolerance = 0.5;
  EXPECT_TRUE(core::validate(ok).is_ok());
  // The planner refuses them too, before searching.
  auto map = std::make_shared<const GridMap>(GridMap::from_rows({"....", "....", "...."}).value());
  PlannerOptions o = core::default_options(PlannerKind::kAStar);
  o.cost_weight = -2.0;
  const PlanResult r = core::plan_once(map, {{0, 0}, {3, 2}}, o);
  EXPECT_EQ(r.status.code, StatusCode::kInvalidRequest);
  EXPECT_TRUE(contains(r.status.message, "cost_weight")) << r.status.message;
  o.cost_weight = 0.0;
  o.goal_tolerance = kNaN;
  const auto e = core::resolve_endpoints(*map, {{0, 0}, {3, 2}}, o);
  ASSERT_FALSE(e);
  EXPECT_TRUE(contains(e.error().message, "goal_tolerance")) << e.error().message;
}

TEST(CostsValidation, BadBuildValuesNameTheKey) {
  OccupancyGrid g;
  g.width = g.height = 8;
  g.resolution = 0.1;
  g.data.assign(64, 0);
  const auto refused = [&](const GridBuildOptions& o, const std::string& key) {
    const core::Status alone = core::validate(o);
    EXPECT_FALSE(alone.is_ok()) << key;
    EXPECT_TRUE(contains(alone.message, key)) << alone.message;
    const core::Status with_map = core::validate(g, o);
    EXPECT_FALSE(with_map.is_ok()) << key;
    EXPECT_TRUE(contains(with_map.message, key)) << with_map.message;
    const auto built = GridMap::build(g, o);
    ASSERT_FALSE(built) << key;
    EXPECT_EQ(built.error().code, StatusCode::kInvalidMap);
    EXPECT_TRUE(contains(built.error().message, key)) << built.error().message;
  };
  for (double bad : {-1.0, -1e-9, kNaN, kInf, -kInf}) {
    GridBuildOptions o;
    o.inflation_radius = bad;
    refused(o, "inflation_radius");
  }
  {
    GridBuildOptions o;
    o.robot_radius = 0.3;
    o.inflation_radius = 0.2;  // 0 < inflation_radius < robot_radius
    refused(o, "inflation_radius");
    o.inflation_radius = 0.29999;
    refused(o, "inflation_radius");
    o.inflation_radius = 0.3;
    EXPECT_TRUE(core::validate(o).is_ok());
    o.inflation_radius = 0.0;
    EXPECT_TRUE(core::validate(o).is_ok());
  }
  for (double bad : {-1.0, -1e-9, kNaN, kInf, -kInf}) {
    GridBuildOptions o;
    o.inflation_radius = 0.5;
    o.cost_scaling_factor = bad;
    refused(o, "cost_scaling_factor");
  }
  GridBuildOptions zero_scaling;
  zero_scaling.inflation_radius = 0.5;
  zero_scaling.cost_scaling_factor = 0.0;
  EXPECT_TRUE(core::validate(g, zero_scaling).is_ok());
}

// ---------------------------------------------------------------------------------------------
// The relax smoother (planner.smoother: relax) against the brute-force truth: it never enters a
// blocked cell, never lowers the clearance of the path it starts from, never moves the ends.

// Every segment walked in steps of at most 0.01 cells; each sample's cell must be free in the
// brute-force classification (cells outside the map are not).
::testing::AssertionResult densely_free(const Truth& t, const std::vector<Point2>& path) {
  for (size_t i = 1; i < path.size(); ++i) {
    const Point2 a = path[i - 1], b = path[i];
    if (!a.allFinite() || !b.allFinite()) return ::testing::AssertionFailure() << "not finite";
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / 0.01)));
    for (int k = 0; k <= n; ++k) {
      const Point2 p = a + (b - a) * (static_cast<double>(k) / n);
      // A diagonal through a lattice corner enters neither cell beside it (the corner policy
      // decides whether it may pass them).
      if (p.x() == std::floor(p.x()) && p.y() == std::floor(p.y())) continue;
      if (!t.free(static_cast<int64_t>(std::floor(p.x())), static_cast<int64_t>(std::floor(p.y()))))
        return ::testing::AssertionFailure() << "segment " << i - 1 << " " << a.transpose()
                                             << " -> " << b.transpose() << " enters a blocked cell "
                                             << "at " << p.transpose();
    }
  }
  return ::testing::AssertionSuccess();
}

// The largest distance from a sample of `a` (0.05 cells apart) to the polyline `b`: how far `a`
// strays from `b`.
double straying(const std::vector<Point2>& a, const std::vector<Point2>& b) {
  double most = 0.0;
  for (const Point2& p : clearance_samples(a, 0.05)) {
    double nearest = kInf;
    for (size_t i = 1; i < b.size(); ++i)
      nearest = std::min(nearest, core::distance_to_segment(p, b[i - 1], b[i]));
    if (b.size() == 1) nearest = (p - b.front()).norm();
    most = std::max(most, nearest);
  }
  return most;
}

TEST(RelaxSmoother, StaysInFreeCellsKeepsClearanceAndEndsOnEveryPlanner) {
  std::mt19937 rng(34001);
  int relaxed = 0, fewer_turns = 0, plans = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const auto [s, map, t, cells] = random_trial(rng);
    SCOPED_TRACE("trial " + std::to_string(trial) + ": " + s.describe());
    ASSERT_TRUE(map);
    if (cells.size() < 2) continue;
    core::Planner planner(map);
    for (int q = 0; q < 3; ++q) {
      const bool binary = rng() % 4 == 0;
      const PlannerKind kind = binary ? PlannerKind::kJps : kCostPlanners[rng() % 5];
      PlannerOptions none = core::default_options(kind);
      if (!binary) {
        none.corner_policy = kAllCornerPolicies[rng() % 3];
        none.prune = none.smooth = rng() % 3 != 0;
        if (map->has_costs()) none.cost_weight = std::vector<double>{0.0, 2.0, 10.0}[rng() % 3];
      }
      PlannerOptions relax = none;
      relax.smoother = core::PathSmoother::kRelax;
      if (rng() % 2 == 0) {
        relax.smoother_smoothness = uniform(rng, 0.1, 0.95);
        relax.smoother_closeness = uniform(rng, 0.0, 0.1);
        relax.smoother_cost = uniform(rng, 0.0, 3.0);
        relax.smoother_iterations = 1 + static_cast<int>(rng() % 60);
      }
      // Requested points anywhere in their cells: the ends must stay exactly there.
      const Cell start = pick(rng, cells), goal = pick(rng, cells);
      const Point2 start_point(start.x + uniform(rng, 0.0, 1.0), start.y + uniform(rng, 0.0, 1.0));
      const Point2 goal_point(goal.x + uniform(rng, 0.0, 1.0), goal.y + uniform(rng, 0.0, 1.0));
      const core::PlanQuery query(start, goal, start_point, goal_point);
      SCOPED_TRACE(std::string(core::to_string(kind)) + " start " + str(start) + " goal " +
                   str(goal));
      const PlanResult before = planner.plan(query, none);
      const PlanResult after = planner.plan(query, relax);
      ASSERT_EQ(before.status.code, after.status.code) << after.status.message;
      if (!after.status.is_ok()) continue;
      ++plans;
      // The search is the same; only the final path differs.
      ASSERT_EQ(before.raw_path.size(), after.raw_path.size());
      ASSERT_EQ(before.path.front(), after.path.front());
      ASSERT_EQ(before.path.back(), after.path.back());
      EXPECT_EQ(after.path.front(), start_point);
      EXPECT_EQ(after.path.back(), goal_point);
      ASSERT_TRUE(densely_free(t, before.path)) << "test bug: the oracle refuses the input";
      ASSERT_TRUE(densely_free(t, after.path));
      // Its clearance: the brute force within sampling, and never below the unrelaxed path's.
      const double sampled = brute_clearance_cells(t, after.path, 0.1);
      expect_clearance_within_sampling(after.metrics.clearance_m / s.grid.resolution, sampled, 0.1);
      ASSERT_GE(after.metrics.clearance_m, before.metrics.clearance_m)
          << "relaxed " << after.metrics.clearance_m << " m, unrelaxed "
          << before.metrics.clearance_m << " m";
      relaxed += after.path != before.path;
      fewer_turns += after.metrics.turn_angle_deg < before.metrics.turn_angle_deg;
    }
  }
  // Not vacuous: most plans were moved, and many lost turning.
  EXPECT_GT(plans, 400);
  EXPECT_GT(relaxed, plans / 2);
  EXPECT_GT(fewer_turns, plans / 4);
}

// Relaxing a relaxed path moves it little: within a cell of where it was, and mostly far less.
// (Not exactly idempotent: compaction leaves a point's neighbours farther away than while it was
// relaxed, so a point that was held by a neighbour's clearance can move again.)
TEST(RelaxSmoother, IsIdempotentWithinACell) {
  std::mt19937 rng(34002);
  int checked = 0;
  std::vector<double> strays;
  for (int trial = 0; trial < 200; ++trial) {
    const auto [s, map, t, cells] = random_trial(rng);
    SCOPED_TRACE("trial " + std::to_string(trial) + ": " + s.describe());
    ASSERT_TRUE(map);
    if (cells.size() < 2) continue;
    PlannerOptions o = core::default_options(kCostPlanners[rng() % 5]);
    o.prune = o.smooth = true;
    if (map->has_costs()) o.cost_weight = 2.0;
    o.smoother = core::PathSmoother::kRelax;
    const PlanResult once = core::plan_once(map, {pick(rng, cells), pick(rng, cells)}, o);
    if (!once.status.is_ok()) continue;
    core::RelaxOptions relax;
    relax.smoothness = o.smoother_smoothness;
    relax.closeness = o.smoother_closeness;
    relax.cost = o.smoother_cost;
    relax.cost_weight = o.cost_weight;
    relax.iterations = o.smoother_iterations;
    const std::vector<Point2> twice =
        core::relax_path(*map, once.path, relax, core::path_clearance_cells(*map, once.path));
    ASSERT_EQ(twice.front(), once.path.front());
    ASSERT_EQ(twice.back(), once.path.back());
    const double apart = std::max(straying(twice, once.path), straying(once.path, twice));
    EXPECT_LE(apart, 1.0);
    strays.push_back(apart);
    ++checked;
  }
  EXPECT_GT(checked, 100);
  std::sort(strays.begin(), strays.end());
  const double median = strays.empty() ? 0.0 : strays[strays.size() / 2];
  EXPECT_LE(median, 0.1);
  std::printf(
      "[ relax ] a second relaxation strayed from the first by %.3f cells at the median, "
      "%.3f at most (%d paths)\n",
      median, strays.empty() ? 0.0 : strays.back(), checked);
}

// smoother none is the path of pruning and smoothing, whatever the smoother's weights.
TEST(RelaxSmoother, NoneIgnoresTheSmoothersWeights) {
  std::mt19937 rng(34003);
  for (int trial = 0; trial < 50; ++trial) {
    const auto [s, map, t, cells] = random_trial(rng);
    ASSERT_TRUE(map);
    if (cells.size() < 2) continue;
    PlannerOptions a = core::default_options(PlannerKind::kVnsBaStar);
    if (map->has_costs()) a.cost_weight = 2.0;
    PlannerOptions b = a;
    b.smoother_smoothness = 0.3;
    b.smoother_closeness = 0.5;
    b.smoother_cost = 9.0;
    b.smoother_iterations = 3;
    const core::PlanQuery query(pick(rng, cells), pick(rng, cells));
    const PlanResult x = core::plan_once(map, query, a), y = core::plan_once(map, query, b);
    ASSERT_EQ(x.status.code, y.status.code);
    EXPECT_EQ(x.path, y.path);
    EXPECT_EQ(x.metrics.turns, y.metrics.turns);
  }
}

}  // namespace
}  // namespace vnsba::test