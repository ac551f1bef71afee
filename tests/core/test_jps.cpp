// Online Jump Point Search (core/src/jps.hpp) against an independent oracle: a single-source
// Dijkstra written here (8-connected, no corner cutting, Euclidean step lengths) on random maps
// (the published Moving AI optima: test_jps_movingai.cpp). This executable links
// vnsba_core_checked (VNSBA_CHECK_OPEN_LIST): a pop that is not the least entry of the open
// list aborts the test.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <queue>
#include <random>
#include <string>
#include <vector>

#include "core/test_support.hpp"
#include "jps.hpp"
#include "vnsba/core/neighborhood.hpp"
#include "vnsba/core/planner.hpp"

namespace vnsba::test {
namespace {

using core::PlanningBudget;
using core::StatusCode;
using core::detail::JpsOutcome;
using core::detail::SparseSearchSpace;

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Search state reused across queries and maps, as a planner reuses it.
struct JpsRunner {
  SparseSearchSpace space;

  JpsOutcome run(const GridMap& map, Cell start, Cell goal, std::vector<Cell>* expanded = nullptr) {
    PlanningBudget budget(PlanningBudget::Clock::now(), std::chrono::microseconds(0), nullptr);
    return core::detail::jps_search(map, space, start, goal, budget, expanded);
  }
};

// Dijkstra from `source` to every cell: 8-connected, a diagonal move needs both side cells free,
// steps cost 1 and sqrt 2 (cells). Infinity where unreachable.
std::vector<double> distances_from(const GridMap& map, Cell source) {
  const int64_t w = map.width(), h = map.height();
  std::vector<double> dist(static_cast<size_t>(w * h), kInfinity);
  using Item = std::pair<double, int64_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> open;
  dist[source.y * w + source.x] = 0.0;
  open.push({0.0, source.y * w + source.x});
  while (!open.empty()) {
    const auto [d, i] = open.top();
    open.pop();
    if (d > dist[i]) continue;
    const int64_t x = i % w, y = i / w;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if ((dx == 0 && dy == 0) || !cell_free(map, x + dx, y + dy)) continue;
        const bool diagonal = dx != 0 && dy != 0;
        if (diagonal && (!cell_free(map, x + dx, y) || !cell_free(map, x, y + dy))) continue;
        const double nd = d + (diagonal ? std::sqrt(2.0) : 1.0);
        const int64_t j = (y + dy) * w + (x + dx);
        if (nd < dist[j]) {
          dist[j] = nd;
          open.push({nd, j});
        }
      }
    }
  }
  return dist;
}

GridMap make_map(const std::vector<std::string>& rows_top_first) {
  auto built = GridMap::from_rows(rows_top_first);
  EXPECT_TRUE(built) << built.error().message;
  return std::move(built).value();
}

// A maze of one-cell corridors (a depth-first carve on the odd cells), with `openings` extra
// walls knocked out so that there are loops, and so several routes of different lengths.
std::vector<std::string> maze_rows(std::mt19937& rng, int width, int height, int openings) {
  std::vector<std::string> rows(height, std::string(width, '#'));
  auto at = [&](int x, int y) -> char& { return rows[y][x]; };
  const int cw = (width - 1) / 2, ch = (height - 1) / 2;  // corridor cells per axis
  if (cw < 1 || ch < 1) return random_rows(rng, width, height, 0.3);
  std::vector<std::pair<int, int>> stack{{0, 0}};
  std::vector<bool> carved(static_cast<size_t>(cw * ch), false);
  carved[0] = true;
  at(1, 1) = '.';
  while (!stack.empty()) {
    const auto [cx, cy] = stack.back();
    std::pair<int, int> next[4];
    int count = 0;
    const int steps[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
    for (const auto& s : steps) {
      const int nx = cx + s[0], ny = cy + s[1];
      if (nx >= 0 && ny >= 0 && nx < cw && ny < ch && !carved[ny * cw + nx])
        next[count++] = {nx, ny};
    }
    if (count == 0) {
      stack.pop_back();
      continue;
    }
    const auto [nx, ny] = next[rng() % count];
    carved[ny * cw + nx] = true;
    at(2 * nx + 1, 2 * ny + 1) = '.';
    at(cx + nx + 1, cy + ny + 1) = '.';  // the wall between the two corridor cells
    stack.push_back({nx, ny});
  }
  std::uniform_int_distribution<int> px(1, width - 2), py(1, height - 2);
  for (int i = 0; i < openings; ++i) at(px(rng), py(rng)) = '.';
  return rows;
}

// Rooms on a grid of walls with one- or two-cell doors, plus random clutter: long straight walls
// with gaps make many forced neighbours and long jumps.
std::vector<std::string> room_rows(std::mt19937& rng, int width, int height, double clutter) {
  std::vector<std::string> rows = random_rows(rng, width, height, clutter);
  std::uniform_int_distribution<int> room(3, 12);
  const int room_w = room(rng), room_h = room(rng);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      if (x % room_w == 0 || y % room_h == 0) rows[y][x] = '#';
  std::bernoulli_distribution door(0.5);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const bool wall_x = x % room_w == 0, wall_y = y % room_h == 0;
      if (wall_x == wall_y) continue;  // room interiors and wall crossings
      const int along = wall_x ? y % room_h : x % room_w;
      if ((along == 1 || along == 2) && door(rng)) rows[y][x] = '.';
    }
  }
  return rows;
}

std::vector<std::string> test_map_rows(std::mt19937& rng, int index) {
  std::uniform_real_distribution<double> density(0.0, 0.45);
  std::uniform_int_distribution<int> size(1, 100), small(1, 12), line(1, 100);
  switch (index % 8) {
    case 0:  // a single row
      return random_rows(rng, line(rng), 1, density(rng));
    case 1:  // a single column
      return random_rows(rng, 1, line(rng), density(rng));
    case 2:
      return maze_rows(rng, size(rng) | 1, size(rng) | 1, static_cast<int>(rng() % 20));
    case 3:
      return room_rows(rng, size(rng), size(rng), density(rng) / 3);
    case 4:
      return random_rows(rng, small(rng), small(rng), density(rng));
    case 5:  // open ground: the longest jumps
      return random_rows(rng, size(rng), size(rng), density(rng) / 20);
    default:
      return random_rows(rng, size(rng), size(rng), density(rng));
  }
}

TEST(Jps, FindsTheOnlyWayRoundWithoutCuttingCorners) {
  // The diagonal from S to G would pass between two blocked cells' corners; without corner
  // cutting the path goes round the whole wall.
  const GridMap map = make_map({
      ".....",
      ".#G..",
      "S#...",
      ".#...",
      ".....",
  });
  JpsRunner jps;
  const Cell start{0, 2}, goal{2, 3};
  const JpsOutcome out = jps.run(map, start, goal);
  ASSERT_EQ(out.code, StatusCode::kOk);
  double length = 0.0;
  ASSERT_TRUE(valid_grid_path(map, out.path, start, goal, &length));
  EXPECT_NEAR(length, distances_from(map, start)[goal.y * map.width() + goal.x], 1e-9);
  // North twice, east twice, south: every diagonal shortcut would cut the wall's corner.
  EXPECT_NEAR(length, 5.0, 1e-9);
}

TEST(Jps, StraightAndDiagonalJumpsOnOpenGround) {
  const GridMap map = make_map(std::vector<std::string>(70, std::string(130, '.')));
  JpsRunner jps;
  struct Query {
    Cell start, goal;
    int cells;  // expected path cells
  };
  const Query queries[] = {
      {{0, 0}, {129, 0}, 130},  {{129, 0}, {0, 0}, 130},  {{5, 0}, {5, 69}, 70},
      {{5, 69}, {5, 0}, 70},    {{0, 0}, {69, 69}, 70},   {{69, 0}, {0, 69}, 70},
      {{3, 4}, {120, 60}, 118}, {{120, 60}, {3, 4}, 118}, {{64, 10}, {63, 11}, 2},
      {{63, 10}, {64, 10}, 2},  {{0, 69}, {129, 0}, 130},
  };
  for (const Query& q : queries) {
    std::vector<Cell> expanded;
    const JpsOutcome out = jps.run(map, q.start, q.goal, &expanded);
    ASSERT_EQ(out.code, StatusCode::kOk);
    double length = 0.0;
    ASSERT_TRUE(valid_grid_path(map, out.path, q.start, q.goal, &length));
    EXPECT_EQ(static_cast<int>(out.path.size()), q.cells);
    const int dx = std::abs(q.goal.x - q.start.x), dy = std::abs(q.goal.y - q.start.y);
    EXPECT_NEAR(length, std::abs(dx - dy) + std::min(dx, dy) * std::sqrt(2.0), 1e-9);
    // On open ground the goal is a successor of the start: two pops.
    EXPECT_EQ(out.expanded, 2);
    EXPECT_EQ(static_cast<int64_t>(expanded.size()), out.expanded);
    EXPECT_EQ(expanded.front(), q.start);
    EXPECT_EQ(expanded.back(), q.goal);
  }
}

TEST(Jps, StartEqualToGoalIsTheOneCellPath) {
  const GridMap map = make_map({"..", ".."});
  JpsRunner jps;
  const JpsOutcome out = jps.run(map, {1, 0}, {1, 0});
  ASSERT_EQ(out.code, StatusCode::kOk);
  ASSERT_EQ(out.path.size(), 1u);
  EXPECT_EQ(out.path.front(), (Cell{1, 0}));
}

TEST(Jps, UnreachableGoalsAreNoValidPath) {
  JpsRunner jps;
  // A closed room; a goal behind a corner-touching diagonal wall (reachable only by cutting
  // it); a row cut in two.
  const GridMap room = make_map({
      "..........",
      "..####....",
      "..#..#....",
      "..####....",
      "..........",
  });
  const GridMap diagonal = make_map({
      "...#",
      "..#.",
      ".#..",
      "#...",
  });
  const GridMap row = make_map({"...#..."});
  struct Query {
    const GridMap* map;
    Cell start, goal;
  } const queries[] = {
      {&room, {0, 0}, {3, 2}},     {&room, {4, 2}, {9, 4}}, {&diagonal, {0, 3}, {3, 0}},
      {&diagonal, {3, 1}, {0, 2}}, {&row, {0, 0}, {6, 0}},  {&row, {5, 0}, {1, 0}},
  };
  for (const Query& q : queries) {
    std::vector<Cell> expanded;
    const JpsOutcome out = jps.run(*q.map, q.start, q.goal, &expanded);
    EXPECT_EQ(out.code, StatusCode::kNoValidPath)
        << "(" << q.start.x << ", " << q.start.y << ") -> (" << q.goal.x << ", " << q.goal.y << ")";
    EXPECT_TRUE(out.path.empty());
    EXPECT_GT(out.expanded, 0);
    EXPECT_EQ(static_cast<int64_t>(expanded.size()), out.expanded);
  }
}

// The path's cost in the searches' step costs (neighborhood.hpp: exact multiples of 2^-26
// cells, so equal step counts give bit-identical sums in any order).
double quantized_cost(const std::vector<Cell>& path) {
  double cost = 0.0;
  for (size_t i = 1; i < path.size(); ++i) {
    const bool diagonal = path[i].x != path[i - 1].x && path[i].y != path[i - 1].y;
    cost += diagonal ? core::detail::kStepCostDiagonal : core::detail::kStepCostStraight;
  }
  return cost;
}

// One query checked against the oracle's distances from its start (`dist`, row-major): a valid
// path exactly as long as Dijkstra's, or kNoValidPath where Dijkstra reaches nothing. Returns
// whether a path was found.
bool check_query(JpsRunner& jps, const GridMap& map, const std::vector<double>& dist, Cell start,
                 Cell goal, const std::string& where) {
  const double expected = dist[static_cast<size_t>(goal.y) * map.width() + goal.x];
  const JpsOutcome out = jps.run(map, start, goal);
  if (expected == kInfinity) {
    EXPECT_EQ(out.code, StatusCode::kNoValidPath) << where;
    EXPECT_TRUE(out.path.empty()) << where;
    return false;
  }
  EXPECT_EQ(out.code, StatusCode::kOk) << where;
  double length = 0.0;
  EXPECT_TRUE(valid_grid_path(map, out.path, start, goal, &length)) << where;
  EXPECT_NEAR(length, expected, 1e-9 * (1.0 + expected)) << where;
  EXPECT_GT(out.expanded, 0) << where;
  return out.code == StatusCode::kOk;
}

std::string describe_query(int map_index, const GridMap& map, Cell start, Cell goal) {
  return "map " + std::to_string(map_index) + " (" + std::to_string(map.width()) + " x " +
         std::to_string(map.height()) + "): (" + std::to_string(start.x) + ", " +
         std::to_string(start.y) + ") -> (" + std::to_string(goal.x) + ", " +
         std::to_string(goal.y) + ")";
}

// Maps whose sides lie on and around the scans' window (56 cells) and word (64 cells) sizes,
// mostly open so that jumps run the whole line: every scan that reaches a map's edge reads its
// last window partly past the line (into the next line or the grid's spare word).
TEST(Jps, MatchesDijkstraAcrossWindowAndWordBoundaries) {
  const int sides[] = {1, 2, 7, 8, 55, 56, 57, 63, 64, 65, 112, 113, 127, 128, 129, 200};
  std::mt19937 rng(64);
  JpsRunner jps;
  int queries = 0, m = 0;
  for (int w : sides) {
    for (int h : sides) {
      if (w * h > 200 * 64) continue;  // the oracle is quadratic-ish: keep it quick
      const GridMap map = make_map(random_rows(rng, w, h, (m % 3) * 0.04));
      const auto cells = free_cells(map);
      ++m;
      if (cells.size() < 2) continue;
      std::uniform_int_distribution<size_t> pick(0, cells.size() - 1);
      const Cell corners[] = {{0, 0}, {w - 1, 0}, {0, h - 1}, {w - 1, h - 1}};
      for (int s = 0; s < 2; ++s) {
        const Cell start = s == 0 && cell_free(map, 0, 0) ? Cell{0, 0} : cells[pick(rng)];
        const std::vector<double> dist = distances_from(map, start);
        std::vector<Cell> goals{cells[pick(rng)], cells[pick(rng)]};
        for (const Cell& c : corners)
          if (cell_free(map, c.x, c.y)) goals.push_back(c);
        for (const Cell& goal : goals) {
          if (goal == start) continue;
          check_query(jps, map, dist, start, goal, describe_query(m, map, start, goal));
          ++queries;
        }
      }
    }
  }
  RecordProperty("queries", queries);
  EXPECT_GT(queries, 500);
}

// Thousands of queries on random maps of 1 x 1 to 100 x 100 cells (0-45 % blocked, mazes of
// one-cell corridors, rooms with doors, single rows and columns, open ground): the path is valid
// cell by cell and exactly as long as Dijkstra's, or there is none exactly when Dijkstra finds
// none. One runner for all maps: the reused state must not leak between maps of any size.
TEST(Jps, MatchesDijkstraOnRandomMaps) {
  std::mt19937 rng(20250611);
  JpsRunner jps;
  int queries = 0, found = 0, unreachable = 0, adjacent = 0;
  for (int m = 0; m < 1600; ++m) {
    const GridMap map = make_map(test_map_rows(rng, m));
    const auto cells = free_cells(map);
    if (cells.size() < 2) continue;
    std::uniform_int_distribution<size_t> pick(0, cells.size() - 1);
    for (int s = 0; s < 2; ++s) {
      const Cell start = cells[pick(rng)];
      const std::vector<double> dist = distances_from(map, start);
      std::vector<Cell> goals;
      for (int i = 0; i < 3; ++i) goals.push_back(cells[pick(rng)]);
      // A neighbour of the start, when there is a free one.
      for (int k = 0; k < 8; ++k) {
        const Cell n{start.x + static_cast<int>(rng() % 3) - 1,
                     start.y + static_cast<int>(rng() % 3) - 1};
        if (n != start && cell_free(map, n.x, n.y)) {
          goals.push_back(n);
          break;
        }
      }
      for (const Cell& goal : goals) {
        if (goal == start) continue;
        ++queries;
        adjacent += std::abs(goal.x - start.x) <= 1 && std::abs(goal.y - start.y) <= 1;
        if (check_query(jps, map, dist, start, goal, describe_query(m, map, start, goal))) {
          ++found;
        } else {
          ++unreachable;
        }
        if (::testing::Test::HasFailure()) return;  // one broken query is enough to read
      }
    }
  }
  RecordProperty("queries", queries);
  EXPECT_GT(queries, 8000);
  EXPECT_GT(found, queries / 2);
  EXPECT_GT(unreachable, 200);
  EXPECT_GT(adjacent, 2000);
}

// JPS sums the same step costs as A* (whole jumps of them, exact multiples of 2^-26 cells), so
// its path costs exactly what A*'s costs, bit for bit, not only within a tolerance.
TEST(Jps, CostsExactlyWhatAStarCosts) {
  std::mt19937 rng(1729);
  std::uniform_int_distribution<int> size(2, 90);
  std::uniform_real_distribution<double> density(0.0, 0.4);
  JpsRunner jps;
  const core::PlannerOptions astar = core::default_options(core::PlannerKind::kAStar);
  ASSERT_EQ(astar.corner_policy, CornerPolicy::kNever);
  int compared = 0;
  for (int m = 0; m < 300; ++m) {
    const auto map = random_shared_map(rng, size(rng), size(rng), density(rng));
    ASSERT_TRUE(map);
    const auto cells = free_cells(*map);
    if (cells.size() < 2) continue;
    core::Planner planner(map);
    std::uniform_int_distribution<size_t> pick(0, cells.size() - 1);
    for (int q = 0; q < 4; ++q) {
      const Cell start = cells[pick(rng)], goal = cells[pick(rng)];
      if (start == goal) continue;
      const JpsOutcome out = jps.run(*map, start, goal);
      const core::PlanResult reference = planner.plan({start, goal}, astar);
      const std::string where = describe_query(m, *map, start, goal);
      if (!reference.status.is_ok()) {
        EXPECT_EQ(reference.status.code, StatusCode::kNoValidPath) << where;
        EXPECT_EQ(out.code, StatusCode::kNoValidPath) << where;
        continue;
      }
      ASSERT_EQ(out.code, StatusCode::kOk) << where;
      EXPECT_EQ(quantized_cost(out.path), quantized_cost(reference.raw_path)) << where;
      ++compared;
    }
  }
  RecordProperty("compared", compared);
  EXPECT_GT(compared, 500);
}

TEST(Jps, PollsTheBudgetOncePerExpansion) {
  const GridMap map = make_map(std::vector<std::string>(40, std::string(40, '.')));
  SparseSearchSpace space;
  // A cancel flag raised before the search: the first poll reads it.
  std::atomic<bool> cancel{true};
  PlanningBudget canceled(PlanningBudget::Clock::now(), std::chrono::microseconds(0), &cancel);
  std::vector<Cell> expanded;
  JpsOutcome out = core::detail::jps_search(map, space, {0, 0}, {39, 20}, canceled, &expanded);
  EXPECT_EQ(out.code, StatusCode::kCanceled);
  EXPECT_TRUE(out.path.empty());
  EXPECT_EQ(out.expanded, 0);
  EXPECT_TRUE(expanded.empty());
  // A budget that ran out before the search began.
  PlanningBudget late(PlanningBudget::Clock::now() - std::chrono::seconds(1),
                      std::chrono::microseconds(1), nullptr);
  out = core::detail::jps_search(map, space, {0, 0}, {39, 20}, late, nullptr);
  EXPECT_EQ(out.code, StatusCode::kTimeout);
  EXPECT_TRUE(out.path.empty());
  // The same state then plans normally.
  cancel = false;
  PlanningBudget fine(PlanningBudget::Clock::now(), std::chrono::microseconds(0), &cancel);
  out = core::detail::jps_search(map, space, {0, 0}, {39, 20}, fine, &expanded);
  ASSERT_EQ(out.code, StatusCode::kOk);
  EXPECT_GT(out.expanded, 0);
  EXPECT_EQ(static_cast<int64_t>(expanded.size()), out.expanded);
}

// One expansion can walk a diagonal across the whole map, scanning two lines at every cell, so
// the budget must be read during a walk, not only between expansions (which read the clock every
// 256th time). The map: open ground with blocked cells at (1, 3k), each of which makes a jump
// point that walks north-east across the map, and a goal sealed in the top-right corner, so the
// search would go on for hundreds of expansions. With a budget that has run out by the time the
// first walk has visited a few hundred cells, the search stops during the first expansion; read
// once per expansion, the clock would first be checked at the 256th.
TEST(Jps, ABudgetRunningOutDuringALongWalkStopsIt) {
  constexpr int kSide = 900;
  std::vector<std::string> rows(kSide, std::string(kSide, '.'));
  auto block = [&](int x, int y) { rows[kSide - 1 - y][x] = '#'; };  // rows are top first
  for (int y = 3; y < kSide; y += 3) block(1, y);
  for (int i = kSide - 3; i < kSide; ++i) {
    block(kSide - 3, i);
    block(i, kSide - 3);
  }
  const GridMap map = make_map(rows);
  SparseSearchSpace space;
  PlanningBudget unlimited(PlanningBudget::Clock::now(), std::chrono::microseconds(0), nullptr);
  const JpsOutcome all =
      core::detail::jps_search(map, space, {0, 0}, {kSide - 1, kSide - 1}, unlimited, nullptr);
  ASSERT_EQ(all.code, StatusCode::kNoValidPath);
  ASSERT_GT(all.expanded, 256);  // the test means something only if the search is that long
  PlanningBudget tight(PlanningBudget::Clock::now(), std::chrono::microseconds(1), nullptr);
  const JpsOutcome stopped =
      core::detail::jps_search(map, space, {0, 0}, {kSide - 1, kSide - 1}, tight, nullptr);
  EXPECT_EQ(stopped.code, StatusCode::kTimeout);
  EXPECT_LE(stopped.expanded, 2);
}

}  // namespace
}  // namespace vnsba::test
