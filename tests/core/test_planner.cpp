#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>

#include "core/test_support.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/core/postprocess.hpp"

namespace vnsba::test {
namespace {

using core::default_options;
using core::PlannerKind;
using core::PlannerOptions;
using core::PlanResult;
using core::StatusCode;

std::shared_ptr<const GridMap> shared(const std::vector<std::string>& rows) {
  auto map = GridMap::from_rows(rows);
  EXPECT_TRUE(map) << map.error().message;
  return std::make_shared<const GridMap>(std::move(map).value());
}

std::shared_ptr<const GridMap> open_map(int w, int h) {
  return shared(std::vector<std::string>(h, std::string(w, '.')));
}

// A wall down the middle with a gap at the top: from (0, 0) to (w-1, 0) every planner must
// explore thousands of cells, far more than the 256 expansions between two clock polls.
std::shared_ptr<const GridMap> detour_map(int size) {
  std::vector<std::string> rows(size, std::string(size, '.'));
  for (int row = 1; row < size; ++row) rows[row][size / 2] = '#';
  return shared(rows);
}

const std::vector<std::string> kWallMap = {
    "..........", "..........", "....#.....", "....#.....",
    "....#.....", "....#.....", "....#.....", "..........",
};

class EveryPlanner : public ::testing::TestWithParam<PlannerKind> {};

TEST_P(EveryPlanner, ErrorStatusesNameTheProblem) {
  auto map = shared(kWallMap);
  core::Planner planner(map);
  const PlannerOptions o = default_options(GetParam());
  auto expect = [&](core::PlanQuery q, StatusCode code, const std::string& words) {
    const PlanResult r = planner.plan(q, o);
    EXPECT_EQ(r.status.code, code) << r.status.message;
    EXPECT_NE(r.status.message.find(words), std::string::npos) << r.status.message;
    EXPECT_TRUE(r.raw_path.empty());
    EXPECT_TRUE(r.world_path.empty());
  };
  expect({{-1, 0}, {9, 0}}, StatusCode::kStartOutsideMap, "start (-1, 0)");
  expect({{0, 0}, {10, 0}}, StatusCode::kGoalOutsideMap, "goal (10, 0)");
  expect({{4, 3}, {9, 0}}, StatusCode::kStartOccupied,
         "start (4.500, 3.500) m, in cell (4, 3), is in an occupied cell");
  expect({{0, 0}, {4, 5}}, StatusCode::kGoalOccupied,
         "goal (4.500, 5.500) m, in cell (4, 5), is in an occupied cell");
  // The requested points themselves, not their cells' centres, with the cell they fall in.
  expect({{4, 3}, {9, 0}, Point2(4.2, 3.9), std::nullopt}, StatusCode::kStartOccupied,
         "start (4.200, 3.900) m, in cell (4, 3), is in an occupied cell");
  expect({{0, 0}, {4, 5}, std::nullopt, Point2(4.95, 5.05)}, StatusCode::kGoalOccupied,
         "goal (4.950, 5.050) m, in cell (4, 5), is in an occupied cell");
  // A requested point outside its cell, or not finite, is refused naming the field.
  expect({{0, 0}, {9, 0}, Point2(1.5, 0.5), std::nullopt}, StatusCode::kInvalidRequest,
         "start_point (1.5, 0.5) cells must be finite and lie in cell (0, 0)");
  expect({{0, 0}, {9, 0}, std::nullopt, Point2(9.5, std::nan(""))}, StatusCode::kInvalidRequest,
         "goal_point");
  // Outside wins over occupied for the start, and start is reported before goal.
  expect({{-5, -5}, {4, 5}}, StatusCode::kStartOutsideMap, "start");
}

TEST_P(EveryPlanner, NoPathBetweenComponents) {
  auto map = shared({"...#...", "...#...", "...#...", "...#..."});
  core::Planner planner(map);
  const PlanResult r =
      planner.plan({{0, 0}, {6, 3}, Point2(0.25, 0.75), std::nullopt}, default_options(GetParam()));
  EXPECT_EQ(r.status.code, StatusCode::kNoValidPath);
  EXPECT_NE(r.status.message.find("no path from start (0.250, 0.750) m, in cell (0, 0) to goal "
                                  "(6.500, 3.500) m, in cell (6, 3): they are not connected"),
            std::string::npos)
      << r.status.message;
  EXPECT_GT(r.metrics.expanded, 0);
}

// NO_VALID_PATH says when blocked unknown cells close the way (a slice's scan frontiers are
// unknown): a wall of unknown cells does, one of occupied cells does not, nor a wall of unknown
// cells behind which an occupied wall closes the way anyway.
TEST_P(EveryPlanner, NoValidPathSaysWhenUnknownCellsCloseTheWay) {
  struct Case {
    int8_t column3, column5;  // the values of two whole columns
    bool hinted;
  };
  for (const Case& c : {Case{-1, 0, true}, Case{100, 0, false}, Case{-1, 100, false}}) {
    core::OccupancyGrid g;
    g.width = 7;
    g.height = 4;
    g.data.assign(28, 0);
    for (int y = 0; y < 4; ++y) {
      g.data[static_cast<size_t>(y * 7 + 3)] = c.column3;
      g.data[static_cast<size_t>(y * 7 + 5)] = c.column5;
    }
    const bool hinted = c.hinted;
    auto map = std::make_shared<const GridMap>(GridMap::build(g).value());
    core::Planner planner(map);
    const PlanResult r = planner.plan({{0, 0}, {6, 3}}, default_options(GetParam()));
    ASSERT_EQ(r.status.code, StatusCode::kNoValidPath) << r.status.message;
    EXPECT_EQ(r.status.message.find("unknown cells close the way") != std::string::npos, hinted)
        << r.status.message;
  }
}

TEST_P(EveryPlanner, StartEqualsGoalIsTheOneCellPath) {
  auto map = shared(kWallMap);
  core::Planner planner(map);
  const PlanResult r = planner.plan({{2, 2}, {2, 2}}, default_options(GetParam()));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message;
  ASSERT_EQ(r.raw_path.size(), 1u);
  EXPECT_EQ(r.raw_path[0], (Cell{2, 2}));
  ASSERT_EQ(r.world_path.size(), 1u);
  EXPECT_DOUBLE_EQ(r.metrics.length_cells, 0.0);
  EXPECT_EQ(r.metrics.turns, 0);
}

TEST_P(EveryPlanner, TimeoutWhenTheBudgetIsTooSmall) {
  auto map = detour_map(400);
  core::Planner planner(map);
  PlannerOptions o = default_options(GetParam());
  o.max_planning_time = std::chrono::microseconds(1);
  const PlanResult r = planner.plan({{0, 0}, {399, 0}}, o);
  EXPECT_EQ(r.status.code, StatusCode::kTimeout) << r.status.message;
  EXPECT_NE(r.status.message.find("max_planning_time"), std::string::npos);
  // The planner is still usable afterwards, with the budget lifted.
  o.max_planning_time = std::chrono::microseconds(0);
  EXPECT_TRUE(planner.plan({{0, 0}, {399, 0}}, o).status.is_ok());
}

TEST_P(EveryPlanner, CancelFlagStopsTheSearch) {
  auto map = detour_map(400);
  core::Planner planner(map);
  std::atomic<bool> cancel{true};
  const PlanResult r = planner.plan({{0, 0}, {399, 399}}, default_options(GetParam()), &cancel);
  EXPECT_EQ(r.status.code, StatusCode::kCanceled);
  cancel = false;
  EXPECT_TRUE(
      planner.plan({{0, 0}, {399, 399}}, default_options(GetParam()), &cancel).status.is_ok());
}

TEST_P(EveryPlanner, InvalidOptionsAreRejectedByName) {
  auto map = shared(kWallMap);
  core::Planner planner(map);
  struct Case {
    void (*mutate)(PlannerOptions&);
    const char* field;
  };
  const Case cases[] = {
      {[](PlannerOptions& o) { o.omega = std::nan(""); }, "omega"},
      {[](PlannerOptions& o) { o.eta = -1; }, "eta"},
      {[](PlannerOptions& o) { o.smoothing_distance = 0; }, "smoothing_distance"},
      {[](PlannerOptions& o) { o.sample_step = INFINITY; }, "sample_step"},
      {[](PlannerOptions& o) { o.planner = PlannerKind{}; }, "planner"},
      {[](PlannerOptions& o) { o.smoother = static_cast<core::PathSmoother>(7); }, "smoother"},
      {[](PlannerOptions& o) { o.smoother_smoothness = 0; }, "smoother_smoothness"},
      {[](PlannerOptions& o) { o.smoother_closeness = -0.1; }, "smoother_closeness"},
      {[](PlannerOptions& o) {
         o.smoother_smoothness = 0.99;
         o.smoother_closeness = 0.5;
       },
       "2 * smoother_smoothness + smoother_closeness"},
      {[](PlannerOptions& o) { o.smoother_cost = NAN; }, "smoother_cost"},
      {[](PlannerOptions& o) { o.smoother_iterations = 0; }, "smoother_iterations"},
  };
  for (const Case& c : cases) {
    PlannerOptions o = default_options(GetParam());
    c.mutate(o);
    const PlanResult r = planner.plan({{0, 0}, {9, 0}}, o);
    EXPECT_EQ(r.status.code, StatusCode::kInvalidRequest) << c.field;
    EXPECT_NE(r.status.message.find(c.field), std::string::npos) << r.status.message;
  }
}

TEST_P(EveryPlanner, RecordsExpansionsOfEachSearch) {
  auto map = shared(kWallMap);
  core::Planner planner(map);
  PlannerOptions o = default_options(GetParam());
  o.record_expansions = true;
  const PlanResult r = planner.plan({{0, 3}, {9, 3}}, o);
  ASSERT_TRUE(r.status.is_ok()) << r.status.message;
  EXPECT_EQ(static_cast<int64_t>(r.expanded_forward.size() + r.expanded_backward.size()),
            r.metrics.expanded);
  const bool bidirectional = GetParam() != PlannerKind::kAStar &&
                             GetParam() != PlannerKind::kWeightedAStar &&
                             GetParam() != PlannerKind::kJps;
  EXPECT_EQ(!r.expanded_backward.empty(), bidirectional);
  EXPECT_EQ(r.meeting_cell.has_value(), bidirectional);
  if (r.meeting_cell) {
    EXPECT_NE(std::find(r.raw_path.begin(), r.raw_path.end(), *r.meeting_cell), r.raw_path.end());
  }
  EXPECT_EQ(r.expanded_forward.front(), (Cell{0, 3}));
  if (bidirectional) {
    EXPECT_EQ(r.expanded_backward.front(), (Cell{9, 3}));
  }
}

TEST_P(EveryPlanner, ReusedPlannerMatchesFreshPlanner) {
  std::mt19937 rng(17);
  auto map = shared(random_rows(rng, 60, 45, 0.2));
  core::Planner reused(map);
  const auto cells = free_cells(*map);
  std::uniform_int_distribution<size_t> pick(0, cells.size() - 1);
  for (int q = 0; q < 40; ++q) {
    const core::PlanQuery query{cells[pick(rng)], cells[pick(rng)]};
    const PlanResult a = reused.plan(query, default_options(GetParam()));
    const PlanResult b = core::plan_once(map, query, default_options(GetParam()));
    ASSERT_EQ(a.status.code, b.status.code);
    ASSERT_EQ(a.raw_path, b.raw_path);
    ASSERT_EQ(a.metrics.expanded, b.metrics.expanded);
  }
}

TEST_P(EveryPlanner, LengthRatioIsAgainstOptimalAStar) {
  auto map = shared(kWallMap);
  PlannerOptions o = default_options(GetParam());
  o.compute_length_ratio = true;
  const PlanResult r = core::plan_once(map, {{0, 2}, {9, 5}}, o);
  ASSERT_TRUE(r.status.is_ok());
  const double optimal = reference_shortest_cost(*map, {0, 2}, {9, 5}, o.corner_policy);
  EXPECT_NEAR(r.metrics.length_ratio, r.metrics.length_cells / optimal, 1e-12);
  o.compute_length_ratio = false;
  EXPECT_TRUE(std::isnan(core::plan_once(map, {{0, 2}, {9, 5}}, o).metrics.length_ratio));
}

INSTANTIATE_TEST_SUITE_P(Planners, EveryPlanner, ::testing::ValuesIn(core::all_planner_kinds()),
                         [](const auto& info) { return std::string(core::to_string(info.param)); });

TEST(Planner, NoMapIsInvalidMap) {
  core::Planner planner(nullptr);
  const PlanResult r = planner.plan({{0, 0}, {1, 1}}, default_options(PlannerKind::kVnsBaStar));
  EXPECT_EQ(r.status.code, StatusCode::kInvalidMap);
}

TEST(Planner, StatusNames) {
  EXPECT_EQ(core::to_string(StatusCode::kStartOccupied), "START_OCCUPIED");
  EXPECT_EQ(core::to_string(StatusCode::kNoValidPath), "NO_VALID_PATH");
}

TEST(Planner, VnsOnOpenGroundIsOneStraightSegment) {
  auto map = open_map(40, 30);
  const PlanResult r =
      core::plan_once(map, {{1, 2}, {37, 25}}, default_options(PlannerKind::kVnsBaStar));
  ASSERT_TRUE(r.status.is_ok());
  ASSERT_EQ(r.waypoints.size(), 2u);
  EXPECT_EQ(r.metrics.turns, 0);
  EXPECT_NEAR(r.metrics.length_cells, std::hypot(36.0, 23.0), 1e-9);
  // World coordinates follow the map's resolution and origin.
  EXPECT_NEAR(r.metrics.length_m, r.metrics.length_cells * map->resolution(), 1e-12);
  EXPECT_NEAR(r.world_path.front().x(), 1.5, 1e-12);
  EXPECT_NEAR(r.world_path.back().y(), 25.5, 1e-12);
}

TEST(Planner, SmoothingRoundsTheCornersOfTheWaypoints) {
  auto map = shared(kWallMap);
  PlannerOptions o = default_options(PlannerKind::kVnsBaStar);
  const PlanResult smooth = core::plan_once(map, {{0, 2}, {9, 2}}, o);
  ASSERT_TRUE(smooth.status.is_ok());
  ASSERT_GE(smooth.metrics.turns, 1);
  EXPECT_GT(smooth.path.size(), smooth.waypoints.size());
  EXPECT_LE(smooth.metrics.length_cells, core::polyline_length(smooth.waypoints) + 1e-9);
  o.smooth = false;
  const PlanResult sharp = core::plan_once(map, {{0, 2}, {9, 2}}, o);
  EXPECT_EQ(sharp.path, sharp.waypoints);
}

TEST(Planner, AStarIsOptimalAndOthersAreNotShorter) {
  auto map = shared(kWallMap);
  for (CornerPolicy p : {CornerPolicy::kNever, CornerPolicy::kTouch, CornerPolicy::kAlways}) {
    const double optimal = reference_shortest_cost(*map, {0, 0}, {9, 7}, p);
    for (PlannerKind k : core::all_planner_kinds()) {
      PlannerOptions o = default_options(k);
      o.corner_policy = p;
      o.neighborhood = core::Neighborhood::kEight;
      const PlanResult r = core::plan_once(map, {{0, 0}, {9, 7}}, o);
      if (!core::supports(k, p)) {
        EXPECT_EQ(r.status.code, core::StatusCode::kInvalidRequest);
        continue;
      }
      ASSERT_TRUE(r.status.is_ok()) << core::to_string(k) << ": " << r.status.message;
      if (k == PlannerKind::kAStar || k == PlannerKind::kJps) {
        EXPECT_NEAR(r.metrics.raw_cost_cells, optimal, 1e-9);
      }
      EXPECT_GE(r.metrics.raw_cost_cells, optimal - 1e-9) << core::to_string(k);
    }
  }
}

// Bytes of this process resident in memory now (the second field of /proc/self/statm, in pages),
// or -1 where the system does not tell.
int64_t resident_bytes_now() {
  std::FILE* statm = std::fopen("/proc/self/statm", "r");
  if (statm == nullptr) return -1;
  long long size_pages = 0, resident_pages = 0;
  const int read = std::fscanf(statm, "%lld %lld", &size_pages, &resident_pages);
  std::fclose(statm);
  return read == 2 ? resident_pages * sysconf(_SC_PAGESIZE) : -1;
}

// Installing a map makes the planners of it (the node makes one per worker): that must not
// commit per-cell search state, which on a big map would be tens of bytes a cell per planner
// before any query, and a short query must commit memory for the cells it reaches, not the map.
// Measured as the process's resident memory, not as the planner reports it.
TEST(Planner, MemoryGrowsWithTheSearchNotTheMap) {
  if (resident_bytes_now() < 0) GTEST_SKIP() << "no /proc/self/statm to read resident memory from";
  constexpr int kSide = 2048;
  // Open but for a sealed cell near the top-right corner (rows are given top first): the goal of
  // the last query, which A* cannot reach without closing every other cell.
  std::vector<std::string> rows(kSide, std::string(kSide, '.'));
  for (int d = -1; d <= 1; ++d) {
    rows[2 + d][kSide - 4] = rows[2 + d][kSide - 2] = '#';
    rows[1][kSide - 3 + d] = rows[3][kSide - 3 + d] = '#';
  }
  const core::Cell sealed{kSide - 3, kSide - 3};
  auto map = shared(rows);
  ASSERT_TRUE(map->free(sealed));
  const double cells = static_cast<double>(map->padded_size());
  // What one planner would commit at install if it allocated per cell: the shared flags (2 bytes)
  // and one direction's records (16 bytes), the least any dense layout of both could take.
  const double dense_bytes = cells * (2 + 16);
  // The map's own obstacle-density table (which VNS-BA*'s first query would build) is map
  // memory, built as the node builds it for its planner, before the measurement.
  map->build_density_table();
  const int64_t before_install = resident_bytes_now();
  std::vector<std::unique_ptr<core::Planner>> workers;
  for (int i = 0; i < 4; ++i) workers.push_back(std::make_unique<core::Planner>(map));
  const int64_t after_install = resident_bytes_now();
  EXPECT_LT(static_cast<double>(after_install - before_install), 0.01 * dense_bytes)
      << "four planners committed " << (after_install - before_install) << " bytes at install";
  for (const auto& planner : workers) EXPECT_EQ(planner->search_state_bytes(), 0u);

  // Short queries of every planner kind across the middle of the map: a few hundred cells each.
  core::Planner& planner = *workers.front();
  for (const core::PlannerKind kind : {PlannerKind::kAStar, PlannerKind::kJps,
                                       PlannerKind::kVnsBaStar, PlannerKind::kBidirectionalAStar}) {
    core::PlannerOptions options = default_options(kind);
    options.prune = false;
    options.smooth = false;
    const core::PlanResult r =
        planner.plan({{kSide / 2, kSide / 2}, {kSide / 2 + 40, kSide / 2 + 25}}, options);
    ASSERT_TRUE(r.status.is_ok()) << core::to_string(kind) << ": " << r.status.message;
  }
  const int64_t after_queries = resident_bytes_now();
  EXPECT_LT(static_cast<double>(after_queries - after_install), 0.05 * dense_bytes)
      << "short queries committed " << (after_queries - after_install) << " bytes";
  EXPECT_LT(static_cast<double>(planner.search_state_bytes()), 0.05 * dense_bytes);
  EXPECT_GT(planner.search_state_bytes(), 0u);

  // A query that reaches every cell commits the dense state of one direction at least: the
  // memory follows the search.
  const core::PlanResult flood =
      planner.plan({{0, 0}, sealed}, default_options(PlannerKind::kAStar));
  ASSERT_EQ(flood.status.code, StatusCode::kNoValidPath) << flood.status.message;
  EXPECT_GT(static_cast<double>(planner.search_state_bytes()), 0.5 * dense_bytes);
}

// prepare() builds the obstacle-density table only for a planner that reads it (its 4 bytes a
// cell appear in the map's memory then, not before), and plans stay the same either way.
TEST(Planner, PrepareBuildsOnlyWhatItsPlannerReads) {
  auto map = detour_map(64);
  const size_t bare = map->bytes();
  core::Planner planner(map);
  planner.prepare(default_options(PlannerKind::kJps));
  planner.prepare(default_options(PlannerKind::kAStar));
  EXPECT_EQ(map->bytes(), bare) << "a planner that reads no density built the table";
  const PlanResult before =
      core::Planner(map).plan({{0, 0}, {63, 0}}, default_options(PlannerKind::kVnsBaStar));
  planner.prepare(default_options(PlannerKind::kVnsBaStar));
  EXPECT_GE(map->bytes(), bare + 65u * 65u * sizeof(int32_t));
  const PlanResult after =
      planner.plan({{0, 0}, {63, 0}}, default_options(PlannerKind::kVnsBaStar));
  ASSERT_TRUE(after.status.is_ok()) << after.status.message;
  EXPECT_EQ(after.raw_path, before.raw_path);
  EXPECT_EQ(after.metrics.expanded, before.metrics.expanded);
}

// A* on a query with no path closes exactly the start's component: its expansion count is the
// component's size, and its time is what it took, not 0.
TEST(Planner, FailedPlansReportTheirRealExpansionsAndTime) {
  std::vector<std::string> rows(300, std::string(300, '.'));
  for (int row = 0; row < 300; ++row) rows[row][200] = '#';
  auto map = shared(rows);
  const Cell start{0, 0}, goal{299, 299};
  // A wall across the whole height at column 200: the start's component is columns 0..199.
  const PlanResult r = core::plan_once(map, {start, goal}, default_options(PlannerKind::kAStar));
  ASSERT_EQ(r.status.code, StatusCode::kNoValidPath);
  EXPECT_EQ(r.metrics.expanded, 200 * 300);  // every cell left of the wall
  EXPECT_GT(r.metrics.planning_time_us, 0);
  for (PlannerKind k : core::all_planner_kinds()) {
    const PlanResult other = core::plan_once(map, {start, goal}, default_options(k));
    EXPECT_EQ(other.status.code, StatusCode::kNoValidPath) << core::to_string(k);
    EXPECT_GT(other.metrics.expanded, 0) << core::to_string(k);
    EXPECT_GT(other.metrics.planning_time_us, 0) << core::to_string(k);
  }
}

// Pruning and smoothing poll the same budget as the search: a budget that has run out stops
// them (the plan reports TIMEOUT or CANCELED, never an unbounded post-processing step).
TEST(Planner, PostProcessingHonoursTheBudget) {
  auto map = shared(kWallMap);
  const std::vector<Cell> raw = {{0, 2}, {1, 2}, {2, 2}, {3, 1}, {4, 1}, {5, 1}, {6, 2}, {9, 2}};
  std::atomic<bool> cancel{true};
  core::PlanningBudget canceled(core::PlanningBudget::Clock::now(), std::chrono::microseconds{0},
                                &cancel);
  EXPECT_TRUE(core::prune_path(*map, raw, CornerPolicy::kNever, &canceled).empty());
  EXPECT_EQ(canceled.state(), StatusCode::kCanceled);
  core::PlanningBudget late(core::PlanningBudget::Clock::now() - std::chrono::seconds(1),
                            std::chrono::microseconds{1}, nullptr);
  const std::vector<Point2> corner = {{0.5, 0.5}, {5.5, 0.5}, {5.5, 5.5}};
  EXPECT_TRUE(core::smooth_path(*open_map(8, 8), corner, {}, &late).empty());
  EXPECT_EQ(late.state(), StatusCode::kTimeout);
  // Without a budget, or with one left, both do their work.
  EXPECT_FALSE(core::prune_path(*map, raw, CornerPolicy::kNever).empty());
  core::PlanningBudget plenty(core::PlanningBudget::Clock::now(), std::chrono::seconds(60),
                              nullptr);
  EXPECT_GT(core::smooth_path(*open_map(8, 8), corner, {}, &plenty).size(), corner.size());
}

}  // namespace
}  // namespace vnsba::test
