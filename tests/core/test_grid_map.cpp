#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <random>
#include <thread>
#include <vector>

#include "core/test_support.hpp"
#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/metrics.hpp"

namespace vnsba::test {
namespace {

using core::GridBuildOptions;
using core::OccupancyGrid;
using core::StatusCode;

OccupancyGrid grid_of(int w, int h, int8_t fill = 0) {
  OccupancyGrid g;
  g.width = w;
  g.height = h;
  g.data.assign(static_cast<size_t>(std::max(w, 0)) * std::max(h, 0), fill);
  return g;
}

TEST(GridMap, ThresholdAndUnknownHandling) {
  OccupancyGrid g = grid_of(4, 1);
  g.data = {0, 64, 65, -1};
  auto strict = GridMap::build(g);
  ASSERT_TRUE(strict) << strict.error().message;
  EXPECT_FALSE(strict->blocked(0, 0));
  EXPECT_FALSE(strict->blocked(1, 0));  // just under the default threshold 65
  EXPECT_TRUE(strict->blocked(2, 0));
  EXPECT_TRUE(strict->blocked(3, 0));  // unknown is blocked by default
  GridBuildOptions lenient;
  lenient.allow_unknown = true;
  lenient.occupied_threshold = 50;
  auto open = GridMap::build(g, lenient);
  ASSERT_TRUE(open);
  EXPECT_TRUE(open->blocked(1, 0));
  EXPECT_FALSE(open->blocked(3, 0));
}

TEST(GridMap, RowsReadTopFirst) {
  auto map = GridMap::from_rows({"#..", "...", "..#"});
  ASSERT_TRUE(map);
  EXPECT_TRUE(map->blocked(0, 2));  // top-left character is the top row
  EXPECT_TRUE(map->blocked(2, 0));
  EXPECT_FALSE(map->blocked(0, 0));
  EXPECT_TRUE(map->blocked(-1, 0));  // outside counts as blocked
  EXPECT_TRUE(map->blocked(3, 0));
}

TEST(GridMap, InvalidMapsNameTheField) {
  struct Case {
    OccupancyGrid grid;
    GridBuildOptions options;
    std::string field;
  };
  std::vector<Case> cases;
  cases.push_back({grid_of(0, 3), {}, "width"});
  cases.push_back({grid_of(3, -1), {}, "height"});
  OccupancyGrid short_data = grid_of(3, 3);
  short_data.data.pop_back();
  cases.push_back({short_data, {}, "data has 8 values"});
  OccupancyGrid bad_res = grid_of(2, 2);
  bad_res.resolution = std::nan("");
  cases.push_back({bad_res, {}, "resolution"});
  OccupancyGrid zero_res = grid_of(2, 2);
  zero_res.resolution = 0.0;
  cases.push_back({zero_res, {}, "resolution"});
  OccupancyGrid bad_origin = grid_of(2, 2);
  bad_origin.origin_y = INFINITY;
  cases.push_back({bad_origin, {}, "origin y"});
  OccupancyGrid bad_value = grid_of(2, 2);
  bad_value.data[3] = 101;
  cases.push_back({bad_value, {}, "data[3] = 101"});
  GridBuildOptions big_limit;
  big_limit.max_cells = 3;
  cases.push_back({grid_of(2, 2), big_limit, "too large: the limit is 3 cells"});
  GridBuildOptions bad_threshold;
  bad_threshold.occupied_threshold = 0;
  cases.push_back({grid_of(2, 2), bad_threshold, "occupied_threshold"});
  GridBuildOptions bad_radius;
  bad_radius.robot_radius = -1;
  cases.push_back({grid_of(2, 2), bad_radius, "robot_radius"});
  for (const Case& c : cases) {
    auto map = GridMap::build(c.grid, c.options);
    ASSERT_FALSE(map) << c.field;
    EXPECT_EQ(map.error().code, StatusCode::kInvalidMap);
    EXPECT_NE(map.error().message.find(c.field), std::string::npos)
        << "message '" << map.error().message << "' should name " << c.field;
  }
}

TEST(GridMap, ReportsEveryErrorAtOnce) {
  OccupancyGrid g = grid_of(0, 0);
  g.resolution = -1;
  auto map = GridMap::build(g);
  ASSERT_FALSE(map);
  for (const char* field : {"width", "height", "resolution"})
    EXPECT_NE(map.error().message.find(field), std::string::npos) << field;
}

// Inflation equals the brute-force definition: blocked iff some originally blocked centre lies
// within the radius.
TEST(GridMap, InflationMatchesBruteForce) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 60; ++trial) {
    const int w = 5 + trial % 17, h = 4 + (trial * 7) % 19;
    OccupancyGrid g = grid_of(w, h);
    g.resolution = 0.05 + 0.05 * (trial % 4);
    std::bernoulli_distribution blocked(0.05 + 0.01 * (trial % 10));
    for (auto& v : g.data) v = blocked(rng) ? 100 : 0;
    GridBuildOptions options;
    options.robot_radius = g.resolution * (0.5 + 0.37 * (trial % 9));
    auto map = GridMap::build(g, options);
    ASSERT_TRUE(map);
    const double r = options.robot_radius / g.resolution;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        bool expect = false;
        for (int oy = 0; oy < h && !expect; ++oy)
          for (int ox = 0; ox < w && !expect; ++ox)
            expect = g.at(ox, oy) == 100 && (ox - x) * (ox - x) + (oy - y) * (oy - y) <= r * r;
        ASSERT_EQ(map->blocked(x, y), expect) << "cell " << x << "," << y << " trial " << trial;
      }
    }
  }
}

// Unknown cells (-1) are blocked (allow_unknown false) but, by default, not inflated and not a
// source of the cost gradient: only occupied cells are (Nav2's inflation layer). With
// inflate_unknown they are both, and the obstacle distance counts them. Brute force over random
// maps with occupied and unknown cells.
TEST(GridMap, UnknownCellsAreBlockedButInflatedOnlyWhenAsked) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 40; ++trial) {
    const int w = 6 + trial % 13, h = 5 + (trial * 5) % 11;
    OccupancyGrid g = grid_of(w, h);
    g.resolution = 0.1;
    std::discrete_distribution<int> kind({0.8, 0.1, 0.1});  // free, occupied, unknown
    for (auto& v : g.data) {
      const int k = kind(rng);
      v = k == 0 ? 0 : k == 1 ? 100 : -1;
    }
    for (const bool inflate_unknown : {false, true}) {
      SCOPED_TRACE("trial " + std::to_string(trial) + ", inflate_unknown " +
                   std::to_string(inflate_unknown));
      GridBuildOptions options;
      options.robot_radius = 0.1 * (1 + trial % 3);
      options.inflation_radius = options.robot_radius + 0.2;
      options.inflate_unknown = inflate_unknown;
      auto map = GridMap::build(g, options);
      ASSERT_TRUE(map);
      const double r = options.robot_radius / g.resolution;
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          double nearest = std::numeric_limits<double>::infinity();  // cells, to a source
          for (int oy = 0; oy < h; ++oy)
            for (int ox = 0; ox < w; ++ox) {
              const bool source = g.at(ox, oy) == 100 || (inflate_unknown && g.at(ox, oy) == -1);
              if (source) nearest = std::min(nearest, std::hypot(ox - x, oy - y));
            }
          const bool own_blocked = g.at(x, y) != 0;  // occupied, or unknown (allow_unknown false)
          ASSERT_EQ(map->blocked(x, y), own_blocked || nearest <= r + 1e-9) << x << "," << y;
          // Exact within the field's saturation (every distance of this small map).
          if (std::isfinite(nearest)) {
            EXPECT_DOUBLE_EQ(map->obstacle_distance_at_least({x, y}), nearest) << x << "," << y;
            EXPECT_DOUBLE_EQ(map->obstacle_distance_at_most({x, y}), nearest) << x << "," << y;
          } else {
            EXPECT_EQ(map->obstacle_distance_at_most({x, y}), nearest) << x << "," << y;
          }
        }
      }
    }
  }
}

// Independent integer oracle for inflation: cell (x, y) is blocked iff some originally blocked
// cell's centre is at squared distance <= max_d2 (cells^2, an integer given by the test).
std::vector<bool> inflated_by_definition(const OccupancyGrid& g, int64_t max_d2) {
  std::vector<bool> out(g.data.size(), false);
  for (int y = 0; y < g.height; ++y)
    for (int x = 0; x < g.width; ++x)
      for (int oy = 0; oy < g.height && !out[y * g.width + x]; ++oy)
        for (int ox = 0; ox < g.width && !out[y * g.width + x]; ++ox)
          out[y * g.width + x] = g.at(ox, oy) == 100 &&
                                 int64_t{ox - x} * (ox - x) + int64_t{oy - y} * (oy - y) <= max_d2;
  return out;
}

// docs/algorithm.md section 1: a radius that is a whole number of cells in decimal metres is
// exactly that many cells, although radius / resolution falls just short of it in doubles
// (0.15 / 0.05 = 2.9999999999999996); the cell that far away is inflated. A radius between
// whole cells keeps its value (0.12 m / 0.05 m = 2.4 cells: squared distances up to 5).
TEST(GridMap, InflationSnapsWholeCellRadii) {
  struct Case {
    double radius, resolution;  // metres
    int64_t max_d2;             // cells^2: the intended bound on dx*dx + dy*dy
    int isolated_disc;          // cells blocked around one isolated obstacle
    bool whole;                 // the radius is meant to be a whole number of cells
  };
  const Case cases[] = {{0.15, 0.05, 9, 29, true},
                        {0.30, 0.05, 36, 113, true},
                        {0.30, 0.10, 9, 29, true},
                        {0.12, 0.05, 5, 21, false},
                        {0.35, 0.10, 12, 37, false}};
  std::mt19937 rng(23);
  for (const Case& c : cases) {
    const double quotient = c.radius / c.resolution;
    if (c.whole) {
      EXPECT_NE(quotient, std::round(quotient));  // the floating-point trap is real
    }
    GridBuildOptions options;
    options.robot_radius = c.radius;
    // One isolated obstacle in the middle of a 21 x 21 map.
    OccupancyGrid single = grid_of(21, 21);
    single.resolution = c.resolution;
    single.data[10 * 21 + 10] = 100;
    auto map = GridMap::build(single, options);
    ASSERT_TRUE(map);
    EXPECT_EQ(map->blocked_count(), c.isolated_disc) << c.radius << " m at " << c.resolution;
    // Random maps of several sizes and densities.
    for (int trial = 0; trial < 12; ++trial) {
      OccupancyGrid g = grid_of(6 + trial * 3 % 23, 5 + trial * 5 % 19);
      g.resolution = c.resolution;
      std::bernoulli_distribution blocked(0.01 + 0.02 * (trial % 5));
      for (auto& v : g.data) v = blocked(rng) ? 100 : 0;
      const std::vector<bool> expected = inflated_by_definition(g, c.max_d2);
      auto built = GridMap::build(g, options);
      ASSERT_TRUE(built);
      for (int y = 0; y < g.height; ++y)
        for (int x = 0; x < g.width; ++x)
          ASSERT_EQ(built->blocked(x, y), expected[y * g.width + x])
              << "cell " << x << "," << y << ", " << c.radius << " m at " << c.resolution;
    }
  }
}

// A radius of up to the map's diagonal inflates as its definition says, at a cost linear in
// the cells (before, the disc of (2r+1)^2 offsets alone was 10 GB for r = 1e5 / 0.05 m); one
// beyond the diagonal is refused, naming robot_radius, instead of overflowing the radius in cells
// to INT_MIN and skipping inflation (1e10 m) or exhausting memory.
TEST(GridMap, LargeRadiiInflateByDefinitionOrAreRefused) {
  std::mt19937 rng(99);
  OccupancyGrid g = grid_of(60, 45);
  g.resolution = 0.05;
  std::bernoulli_distribution blocked(0.004);
  for (auto& v : g.data) v = blocked(rng) ? 100 : 0;
  g.data[7 * 60 + 50] = 100;                       // at least one obstacle
  const double diagonal = std::hypot(60.0, 45.0);  // cells
  for (int64_t max_d2 : {int64_t{100}, int64_t{1000}, int64_t{4000}, int64_t{5600}}) {
    GridBuildOptions options;
    options.robot_radius = std::sqrt(double(max_d2)) * g.resolution;
    ASSERT_LE(std::sqrt(double(max_d2)), diagonal);
    auto map = GridMap::build(g, options);
    ASSERT_TRUE(map) << map.error().message;
    const std::vector<bool> expected = inflated_by_definition(g, max_d2);
    for (int y = 0; y < g.height; ++y)
      for (int x = 0; x < g.width; ++x)
        ASSERT_EQ(map->blocked(x, y), expected[y * g.width + x]) << x << "," << y << " " << max_d2;
  }
  for (double radius : {diagonal * g.resolution * 1.001, 1e5, 1e10, 1e300}) {
    GridBuildOptions options;
    options.robot_radius = radius;
    auto map = GridMap::build(g, options);
    ASSERT_FALSE(map) << radius;
    EXPECT_EQ(map.error().code, StatusCode::kInvalidMap);
    EXPECT_NE(map.error().message.find("robot_radius"), std::string::npos) << map.error().message;
    EXPECT_NE(map.error().message.find("diagonal"), std::string::npos) << map.error().message;
  }
  // The options alone (what a config checks) do not depend on any map.
  GridBuildOptions huge;
  huge.robot_radius = 1e5;
  EXPECT_TRUE(core::validate(huge).is_ok());
  huge.robot_radius = -1.0;
  EXPECT_FALSE(core::validate(huge).is_ok());
}

// A conversion superseded by a newer map stops with kCanceled and builds nothing.
TEST(GridMap, BuildStopsWhenCanceled) {
  OccupancyGrid g = grid_of(64, 64);
  g.data[100] = 100;
  GridBuildOptions options;
  options.robot_radius = 3.0;
  std::atomic<bool> cancel{true};
  auto map = GridMap::build(g, options, &cancel);
  ASSERT_FALSE(map);
  EXPECT_EQ(map.error().code, StatusCode::kCanceled);
  cancel = false;
  EXPECT_TRUE(GridMap::build(g, options, &cancel));
}

// The bit grids for line of sight hold exactly the blocked flags, in rows and in columns, for
// sizes that are and are not multiples of the 64-cell word, and nothing in the padding bits.
TEST(GridMap, BitGridsMirrorBlockedFlags) {
  std::mt19937 rng(31);
  const int sizes[] = {1, 2, 63, 64, 65, 127, 128, 130};
  for (int w : sizes) {
    for (int h : sizes) {
      auto map = GridMap::from_rows(random_rows(rng, w, h, 0.3));
      ASSERT_TRUE(map);
      const core::BlockedBits rows = map->blocked_rows(), columns = map->blocked_columns();
      ASSERT_EQ(rows.words_per_line, static_cast<size_t>((w + 63) / 64));
      ASSERT_EQ(columns.words_per_line, static_cast<size_t>((h + 63) / 64));
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          ASSERT_EQ(rows.blocked(y, x), map->blocked(x, y))
              << w << "x" << h << " " << x << "," << y;
          ASSERT_EQ(columns.blocked(x, y), map->blocked(x, y)) << x << "," << y;
        }
      for (int y = 0; y < h; ++y)
        for (int x = w; x < static_cast<int>(64 * rows.words_per_line); ++x)
          ASSERT_FALSE(rows.blocked(y, x));
      for (int x = 0; x < w; ++x)
        for (int y = h; y < static_cast<int>(64 * columns.words_per_line); ++y)
          ASSERT_FALSE(columns.blocked(x, y));
    }
  }
}

TEST(GridMap, SummedAreaDensityEqualsBruteForce) {
  std::mt19937 rng(11);
  auto map = GridMap::from_rows(random_rows(rng, 37, 23, 0.3));
  ASSERT_TRUE(map);
  std::uniform_int_distribution<int> rx(0, 36), ry(0, 22);
  for (int trial = 0; trial < 2000; ++trial) {
    const Cell a{rx(rng), ry(rng)}, b{rx(rng), ry(rng)};
    int64_t count = 0;
    for (int y = std::min(a.y, b.y); y <= std::max(a.y, b.y); ++y)
      for (int x = std::min(a.x, b.x); x <= std::max(a.x, b.x); ++x) count += map->blocked(x, y);
    ASSERT_EQ(map->blocked_in_rect(a, b), count);
    const double area = (std::abs(a.x - b.x) + 1.0) * (std::abs(a.y - b.y) + 1.0);
    ASSERT_DOUBLE_EQ(map->density(a, b), count / area);
  }
}

TEST(GridMap, WorldCellConversionRoundTrips) {
  OccupancyGrid g = grid_of(10, 8);
  g.resolution = 0.25;
  g.origin_x = -1.0;
  g.origin_y = 2.0;
  auto map = GridMap::build(g);
  ASSERT_TRUE(map);
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 10; ++x) {
      const Eigen::Vector2d w = map->cell_centre_world({x, y});
      EXPECT_NEAR(w.x(), -1.0 + (x + 0.5) * 0.25, 1e-12);
      EXPECT_NEAR(w.y(), 2.0 + (y + 0.5) * 0.25, 1e-12);
      auto back = map->world_to_cell(w.x(), w.y());
      ASSERT_TRUE(back);
      EXPECT_EQ(*back, (Cell{x, y}));
    }
  }
  EXPECT_FALSE(map->world_to_cell(-1.01, 2.1));
  EXPECT_FALSE(map->world_to_cell(-1.0 + 2.5, 2.1));  // x = width exactly is outside
  EXPECT_FALSE(map->world_to_cell(std::nan(""), 2.1));
  EXPECT_FALSE(map->world_to_cell(0, INFINITY));
}

// --- Memory layout (issue 47): what a map holds, against what it was built with. ---

// A random occupancy grid: occupied (100), unknown (-1), graded (1..64) and free values.
OccupancyGrid random_grid(std::mt19937& rng, int w, int h, double occupied, double unknown = 0.0,
                          double graded = 0.0) {
  OccupancyGrid g = grid_of(w, h);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::uniform_int_distribution<int> grade(1, 64);
  for (int8_t& v : g.data) {
    const double draw = u(rng);
    v = draw < occupied                      ? int8_t{100}
        : draw < occupied + unknown          ? core::kOccupancyUnknown
        : draw < occupied + unknown + graded ? static_cast<int8_t>(grade(rng))
                                             : int8_t{0};
  }
  return g;
}

TEST(GridMap, WithoutRadiusHoldsNeitherDistancesNorSummedAreaUntilAsked) {
  std::mt19937 rng(47);
  const OccupancyGrid g = random_grid(rng, 1024, 1024, 0.2);
  auto map = GridMap::build(g);
  ASSERT_TRUE(map);
  EXPECT_FALSE(map->has_obstacle_distances());
  EXPECT_FALSE(map->has_costs());
  const double cells = 1024.0 * 1024.0;
  // A byte a cell (padded) and two bits: no distance field, no costs, no summed-area table.
  EXPECT_LT(static_cast<double>(map->bytes()), 1.6 * cells);
  // The table comes with the first count (4 bytes a cell), and the count is right.
  int64_t blocked = 0;
  for (int y = 0; y < 1024; ++y)
    for (int x = 0; x < 1024; ++x) blocked += map->blocked(x, y);
  EXPECT_EQ(map->blocked_count(), blocked);
  EXPECT_EQ(map->blocked_in_rect({0, 0}, {1023, 1023}), blocked);
  EXPECT_GE(static_cast<double>(map->bytes()), 5.0 * cells);
  // A radius brings the field (2 bytes a cell), still no table.
  GridBuildOptions options;
  options.robot_radius = 2.0;
  auto inflated = GridMap::build(g, options);
  ASSERT_TRUE(inflated);
  EXPECT_TRUE(inflated->has_obstacle_distances());
  EXPECT_LT(static_cast<double>(inflated->bytes()), 3.6 * cells);
}

TEST(GridMap, BytesNeverExceedTheEstimate) {
  std::mt19937 rng(5);
  struct Case {
    int w, h;
    double robot_radius, inflation_radius;
    double graded;
    bool allow_unknown;
  };
  const Case cases[] = {{1, 1, 0.0, 0.0, 0.0, false},     {65, 3, 0.0, 0.0, 0.0, false},
                        {200, 130, 0.0, 0.0, 0.0, true},  {200, 130, 0.0, 0.0, 0.2, false},
                        {130, 200, 0.3, 0.0, 0.0, false}, {130, 200, 0.3, 1.1, 0.1, true},
                        {300, 64, 0.0, 0.8, 0.0, false},  {64, 300, 25.0, 30.0, 0.0, false}};
  for (const Case& c : cases) {
    SCOPED_TRACE(std::to_string(c.w) + "x" + std::to_string(c.h) + " r " +
                 std::to_string(c.robot_radius) + " inflation " +
                 std::to_string(c.inflation_radius));
    OccupancyGrid g = random_grid(rng, c.w, c.h, 0.05, 0.02, c.graded);
    g.resolution = 0.1;
    GridBuildOptions options;
    options.robot_radius = c.robot_radius;
    options.inflation_radius = c.inflation_radius;
    options.allow_unknown = c.allow_unknown;
    const core::MapMemoryEstimate estimate = GridMap::estimate_memory(c.w, c.h, options);
    auto map = GridMap::build(g, options);
    ASSERT_TRUE(map);
    EXPECT_EQ(map->has_obstacle_distances(), c.robot_radius > 0.0 || c.inflation_radius > 0.0);
    EXPECT_LE(map->bytes(), estimate.map_bytes);
    map->blocked_in_rect({0, 0}, {c.w - 1, c.h - 1});  // builds the summed-area table
    EXPECT_LE(map->bytes(), estimate.map_bytes);
    if (!map->has_obstacle_distances()) {
      EXPECT_EQ(estimate.scratch_bytes, 0u);
    }
  }
}

// The brute-force distance (cells) from cell c's centre to the nearest obstacle centre.
double brute_obstacle_distance(const OccupancyGrid& g, bool inflate_unknown, const Cell& c) {
  int64_t best = -1;
  for (int32_t y = 0; y < g.height; ++y)
    for (int32_t x = 0; x < g.width; ++x) {
      const int8_t v = g.at(x, y);
      if (!(v == 100 || (inflate_unknown && v == core::kOccupancyUnknown))) continue;
      const int64_t d2 = int64_t{x - c.x} * (x - c.x) + int64_t{y - c.y} * (y - c.y);
      if (best < 0 || d2 < best) best = d2;
    }
  return best < 0 ? std::numeric_limits<double>::infinity() : std::sqrt(double(best));
}

// The field bounds the exact distance from both sides (exact within its saturation, beyond 255
// cells), and nearest_obstacle_distance is exact everywhere, with or without the field.
TEST(GridMap, DistanceFieldBoundsTheExactDistance) {
  std::mt19937 rng(9);
  for (int trial = 0; trial < 6; ++trial) {
    // Long thin maps with obstacles only near one end: distances well past the saturation.
    const int w = trial < 3 ? 700 : 45, h = trial < 3 ? 9 : 37;
    OccupancyGrid g = grid_of(w, h);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int32_t y = 0; y < h; ++y)
      for (int32_t x = 0; x < w; ++x) {
        const bool far_end = trial < 3 && x >= 20;  // free: hundreds of cells from anything
        const double p = trial < 3 ? 0.2 : 0.15;
        const double draw = u(rng);
        int8_t value = 0;
        if (!far_end)
          value = draw < p ? int8_t{100} : draw < p + 0.05 ? core::kOccupancyUnknown : int8_t{0};
        g.data[static_cast<size_t>(y) * w + x] = value;
      }
    for (const double robot_radius : {0.0, 1.5}) {
      for (const bool inflate_unknown : {false, true}) {
        GridBuildOptions options;
        options.robot_radius = robot_radius;
        options.inflation_radius = trial % 2 == 0 ? robot_radius + 2.0 : 0.0;
        options.inflate_unknown = inflate_unknown;
        auto map = GridMap::build(g, options);
        ASSERT_TRUE(map);
        int saturated = 0;
        for (int32_t y = 0; y < h; ++y)
          for (int32_t x = 0; x < w; ++x) {
            const Cell c{x, y};
            const double exact = brute_obstacle_distance(g, inflate_unknown, c);
            ASSERT_EQ(core::nearest_obstacle_distance(*map, c), exact) << x << "," << y;
            ASSERT_LE(map->obstacle_distance_at_least(c), exact) << x << "," << y;
            ASSERT_GE(map->obstacle_distance_at_most(c), exact) << x << "," << y;
            if (map->has_obstacle_distances() && exact * exact < 65535.0) {
              ASSERT_EQ(map->obstacle_distance_at_least(c), exact) << x << "," << y;
              ASSERT_EQ(map->obstacle_distance_at_most(c), exact) << x << "," << y;
            }
            saturated += !std::isfinite(map->obstacle_distance_at_most(c));
          }
        if (trial < 3 && map->has_obstacle_distances()) {
          EXPECT_GT(saturated, 0);
        }
      }
    }
  }
}

// An independent oracle of path_clearance_cells: the least exact distance from the polyline
// to every obstacle square (test_support.hpp).
double clearance_oracle(const GridMap& map, const std::vector<Point2>& polyline) {
  double best = std::numeric_limits<double>::infinity();
  for (int32_t y = 0; y < map.height(); ++y)
    for (int32_t x = 0; x < map.width(); ++x) {
      if (!map.is_obstacle(map.layer({x, y}))) continue;
      best = std::min(best, polyline_square_distance(polyline, {x, y}));
    }
  return best;
}

TEST(GridMap, PathClearanceEqualsTheOracleWithAndWithoutTheField) {
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int without_field = 0, with_field = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const bool long_map = trial % 6 == 0;  // far from obstacles: beyond the field's saturation
    const int w = long_map ? 600 : 10 + static_cast<int>(rng() % 50);
    const int h = long_map ? 12 : 10 + static_cast<int>(rng() % 50);
    OccupancyGrid g = grid_of(w, h);
    const double density = long_map ? 0.0 : 0.02 + 0.25 * unit(rng);
    for (int32_t y = 0; y < h; ++y)
      for (int32_t x = 0; x < w; ++x) {
        const double draw = unit(rng);
        const bool wall = long_map && x < 3 && draw < 0.5;
        g.data[static_cast<size_t>(y) * w + x] = wall || draw < density  ? int8_t{100}
                                                 : draw < density + 0.03 ? core::kOccupancyUnknown
                                                                         : int8_t{0};
      }
    GridBuildOptions options;
    options.allow_unknown = trial % 3 == 0;
    options.inflate_unknown = trial % 4 == 0;
    if (trial % 2 == 1) {
      options.robot_radius = (trial % 4 == 1) ? 0.0 : 1.0 + unit(rng);
      options.inflation_radius = options.robot_radius + 1.0;
    }
    auto map = GridMap::build(g, options);
    ASSERT_TRUE(map);
    (map->has_obstacle_distances() ? with_field : without_field)++;
    for (int path = 0; path < 20; ++path) {
      // Vertices at cell centres (grid paths, straight runs included) or anywhere.
      std::vector<Point2> polyline;
      const int vertices = 1 + static_cast<int>(rng() % 6);
      for (int i = 0; i < vertices; ++i) {
        const double x = unit(rng) * w, y = unit(rng) * h;
        polyline.push_back(path % 2 == 0 ? Point2(std::floor(x) + 0.5, std::floor(y) + 0.5)
                                         : Point2(x, y));
      }
      const double expected = clearance_oracle(*map, polyline);
      const double got = core::path_clearance_cells(*map, polyline);
      if (std::isinf(expected)) {
        ASSERT_EQ(got, expected) << "trial " << trial << " path " << path;
      } else {
        ASSERT_NEAR(got, expected, 1e-9) << "trial " << trial << " path " << path;
      }
    }
  }
  EXPECT_GT(with_field, 0);
  EXPECT_GT(without_field, 0);
}

// grid_path_clearance_cells on walks of unit steps (runs along walls, open space, corners cut
// and not, repeated cells) equals the oracle on the cells' centres, and path_clearance_cells on
// them to the bit: the plan reports one or the other for the same path.
TEST(GridMap, GridPathClearanceEqualsTheOracleAndPathClearance) {
  std::mt19937 rng(47);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int beside = 0, away = 0, cut = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const int w = 8 + static_cast<int>(rng() % 40), h = 8 + static_cast<int>(rng() % 40);
    OccupancyGrid g = grid_of(w, h);
    const double density = 0.01 + 0.3 * unit(rng);
    for (int32_t y = 0; y < h; ++y)
      for (int32_t x = 0; x < w; ++x) {
        const double draw = unit(rng);
        g.data[static_cast<size_t>(y) * w + x] = draw < density          ? int8_t{100}
                                                 : draw < density + 0.03 ? core::kOccupancyUnknown
                                                                         : int8_t{0};
      }
    GridBuildOptions options;
    options.allow_unknown = trial % 3 == 0;
    options.inflate_unknown = trial % 4 == 0;
    if (trial % 5 == 1) {
      options.robot_radius = 1.0;
      options.inflation_radius = 2.0;
    }
    auto map = GridMap::build(g, options);
    ASSERT_TRUE(map);
    for (int walk = 0; walk < 20; ++walk) {
      // A walk in runs: a direction held for a few steps while the next cell is free (a diagonal
      // step also past blocked corners, so that some walks cut one), or a repeated cell.
      Cell at{static_cast<int32_t>(rng() % w), static_cast<int32_t>(rng() % h)};
      if (map->blocked(at)) continue;
      std::vector<Cell> cells = {at};
      for (int run = 0; run < 1 + static_cast<int>(rng() % 5); ++run) {
        const int dx = static_cast<int>(rng() % 3) - 1, dy = static_cast<int>(rng() % 3) - 1;
        for (int step = 0; step < 1 + static_cast<int>(rng() % 12); ++step) {
          const Cell next{at.x + dx, at.y + dy};
          if (map->blocked(next)) break;
          cells.push_back(next);
          at = next;
        }
      }
      std::vector<Point2> centres;
      for (const Cell& c : cells) centres.push_back(core::cell_centre(c));
      const double expected = clearance_oracle(*map, centres);
      const double got = core::grid_path_clearance_cells(*map, cells);
      EXPECT_EQ(got, core::path_clearance_cells(*map, centres)) << "trial " << trial;
      if (std::isinf(expected)) {
        ASSERT_EQ(got, expected) << "trial " << trial << " walk " << walk;
      } else {
        ASSERT_NEAR(got, expected, 1e-9) << "trial " << trial << " walk " << walk;
      }
      bool cuts = false;
      for (size_t i = 1; i < cells.size(); ++i) {
        const int dx = cells[i].x - cells[i - 1].x, dy = cells[i].y - cells[i - 1].y;
        cuts = cuts || (dx != 0 && dy != 0 &&
                        (map->blocked(cells[i - 1].x + dx, cells[i - 1].y) ||
                         map->blocked(cells[i - 1].x, cells[i - 1].y + dy)));
      }
      cut += cuts;
      (!cuts && got == 0.5 ? beside : away)++;
    }
  }
  // Each kind of walk occurs: passing an obstacle side on, not, and cutting a corner.
  EXPECT_GT(beside, 50);
  EXPECT_GT(away, 50);
  EXPECT_GT(cut, 10);
}

// The summed-area table built on first use equals brute force, also when several threads make
// that first use at once (one builds it, the others wait for it).
TEST(GridMap, LazySummedAreaFromSeveralThreadsEqualsBruteForce) {
  std::mt19937 rng(3);
  for (int round = 0; round < 5; ++round) {
    const int w = 150 + round * 37, h = 120 + round * 11;
    auto map = GridMap::from_rows(random_rows(rng, w, h, 0.3));
    ASSERT_TRUE(map);
    const GridMap& shared = *map;
    std::atomic<bool> go{false};
    std::atomic<int> wrong{0};
    std::vector<std::thread> threads;
    for (int t = 0; t < 6; ++t) {
      threads.emplace_back([&, seed = static_cast<unsigned>(round * 10 + t)] {
        std::mt19937 local(seed);
        std::uniform_int_distribution<int> rx(0, w - 1), ry(0, h - 1);
        while (!go.load()) std::this_thread::yield();
        for (int trial = 0; trial < 300; ++trial) {
          const Cell a{rx(local), ry(local)}, b{rx(local), ry(local)};
          int64_t count = 0;
          for (int y = std::min(a.y, b.y); y <= std::max(a.y, b.y); ++y)
            for (int x = std::min(a.x, b.x); x <= std::max(a.x, b.x); ++x)
              count += shared.blocked(x, y);
          if (shared.blocked_in_rect(a, b) != count) ++wrong;
        }
      });
    }
    go = true;
    for (std::thread& t : threads) t.join();
    EXPECT_EQ(wrong.load(), 0);
  }
}

}  // namespace
}  // namespace vnsba::test
