// Pruning (docs/algorithm.md section 4) and corner smoothing (section 5): behaviour and a property
// test on random maps with an independent dense-sampling collision checker.
#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <random>
#include <string>
#include <vector>

#include "vnsba/core/postprocess.hpp"

namespace vnsba::core {
namespace {

GridMap map_of(const std::vector<std::string>& rows) {
  return GridMap::from_rows(rows).value();
}

GridMap empty_map(int width, int height) {
  return map_of(std::vector<std::string>(height, std::string(width, '.')));
}

bool finite(const std::vector<Point2>& points) {
  for (const Point2& p : points) {
    if (!p.allFinite()) return false;
  }
  return true;
}

// Independent of line_of_sight: walks every segment in steps of at most 0.01 cells and checks
// the cell containing each sample (out-of-map cells count as blocked).
::testing::AssertionResult dense_free(const GridMap& map, const std::vector<Point2>& points) {
  if (!finite(points)) return ::testing::AssertionFailure() << "non-finite point";
  for (size_t i = 0; i < points.size(); ++i) {
    // The last "segment" is the final point alone, so one-point inputs are checked too.
    const Point2 a = points[i], b = i + 1 < points.size() ? points[i + 1] : points[i];
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / 0.01)));
    for (int j = 0; j <= n; ++j) {
      const Point2 p = a + (b - a) * (static_cast<double>(j) / n);
      const auto x = static_cast<int32_t>(std::floor(p.x()));
      const auto y = static_cast<int32_t>(std::floor(p.y()));
      if (map.blocked(x, y)) {
        return ::testing::AssertionFailure()
               << "segment " << i << " (" << a.transpose() << ") -> (" << b.transpose()
               << ") enters blocked cell (" << x << ", " << y << ") at (" << p.transpose() << ")";
      }
    }
  }
  return ::testing::AssertionSuccess();
}

// Sum of the signed heading changes at the interior vertices.
double total_turn(const std::vector<Point2>& p) {
  double sum = 0.0;
  for (size_t i = 1; i + 1 < p.size(); ++i) sum += heading_change(p[i - 1], p[i], p[i + 1]);
  return sum;
}

double angle_between(const Point2& u, const Point2& v) {
  return std::abs(std::atan2(u.x() * v.y() - u.y() * v.x(), u.dot(v)));
}

// Shortest-hop 8-connected grid path (diagonals need both orthogonal cells free, as kNever):
// a stand-in for the planners, which are not part of this test.
std::vector<Cell> bfs_path(const GridMap& map, Cell start, Cell goal) {
  const int w = map.width();
  std::vector<int> parent(static_cast<size_t>(map.cell_count()), -1);
  auto index = [w](Cell c) { return c.y * w + c.x; };
  std::deque<Cell> queue = {start};
  parent[index(start)] = index(start);
  while (!queue.empty()) {
    const Cell c = queue.front();
    queue.pop_front();
    if (c == goal) break;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const Cell n{c.x + dx, c.y + dy};
        if ((dx == 0 && dy == 0) || map.blocked(n)) continue;
        if (dx != 0 && dy != 0 && (map.blocked(c.x + dx, c.y) || map.blocked(c.x, c.y + dy))) {
          continue;
        }
        if (parent[index(n)] != -1) continue;
        parent[index(n)] = index(c);
        queue.push_back(n);
      }
    }
  }
  if (parent[index(goal)] == -1) return {};
  std::vector<Cell> path = {goal};
  while (!(path.back() == start)) {
    const int p = parent[index(path.back())];
    path.push_back({p % w, p / w});
  }
  return {path.rbegin(), path.rend()};
}

// Checks the section 4 guarantees of a pruned path against its grid path.
void expect_valid_pruning(const GridMap& map, const std::vector<Cell>& path,
                          const std::vector<Point2>& pruned, CornerPolicy policy) {
  ASSERT_FALSE(pruned.empty());
  EXPECT_EQ(pruned.front(), cell_centre(path.front()));
  EXPECT_EQ(pruned.back(), cell_centre(path.back()));
  // A subsequence of the input's centres.
  size_t j = 0;
  for (const Point2& p : pruned) {
    while (j < path.size() && cell_centre(path[j]) != p) ++j;
    ASSERT_LT(j, path.size()) << "pruned point (" << p.transpose() << ") is not in order";
    ++j;
  }
  for (size_t i = 1; i < pruned.size(); ++i) {
    EXPECT_TRUE(line_of_sight(map, pruned[i - 1], pruned[i], policy)) << "pair " << i;
  }
  EXPECT_LE(polyline_length(pruned), polyline_length(cell_centres(path)) + 1e-9);
}

// ---------------------------------------------------------------------------------------------
// Pruning

TEST(PrunePath, EmptyAndSingleCell) {
  const GridMap map = empty_map(4, 4);
  EXPECT_TRUE(prune_path(map, {}, CornerPolicy::kNever).empty());
  const auto one = prune_path(map, {{2, 1}}, CornerPolicy::kNever);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0], cell_centre({2, 1}));
}

TEST(PrunePath, DiagonalAndStaircaseOnEmptyMapPruneToEndpoints) {
  const GridMap map = empty_map(20, 20);
  std::vector<Cell> diagonal, staircase = {{0, 0}};
  for (int i = 0; i < 12; ++i) diagonal.push_back({i, i});
  for (int i = 0; i < 8; ++i) {  // alternating straight and diagonal steps
    const Cell last = staircase.back();
    staircase.push_back(i % 2 == 0 ? Cell{last.x + 1, last.y} : Cell{last.x + 1, last.y + 1});
  }
  for (const auto& path : {diagonal, staircase}) {
    const auto pruned = prune_path(map, path, CornerPolicy::kNever);
    ASSERT_EQ(pruned.size(), 2u);
    expect_valid_pruning(map, path, pruned, CornerPolicy::kNever);
  }
}

TEST(PrunePath, CollinearPointsDisappear) {
  const GridMap map = empty_map(12, 3);
  std::vector<Cell> path;
  for (int x = 0; x < 12; ++x) path.push_back({x, 1});
  const auto pruned = prune_path(map, path, CornerPolicy::kNever);
  ASSERT_EQ(pruned.size(), 2u);
  EXPECT_EQ(pruned[0], cell_centre({0, 1}));
  EXPECT_EQ(pruned[1], cell_centre({11, 1}));
}

TEST(PrunePath, LShapeAroundWallKeepsExactlyTheCorner) {
  // The block fills the lower right, so the only turning point is the top-left cell (0, 4).
  // clang-format off
  const GridMap map = map_of({".....",
                              ".####",
                              ".####",
                              ".####",
                              ".####"});
  // clang-format on
  const std::vector<Cell> path = {{0, 0}, {0, 1}, {0, 2}, {0, 3}, {0, 4},
                                  {1, 4}, {2, 4}, {3, 4}, {4, 4}};
  const auto pruned = prune_path(map, path, CornerPolicy::kNever);
  ASSERT_EQ(pruned.size(), 3u);
  EXPECT_EQ(pruned[1], cell_centre({0, 4}));
  expect_valid_pruning(map, path, pruned, CornerPolicy::kNever);
}

TEST(PrunePath, InvalidStepsTerminateAndKeepEndpoints) {
  // (1, 0) is blocked: the "path" jumps over it. Pruning must not loop and keeps both ends.
  // clang-format off
  const GridMap map = map_of({"...",
                              ".#."});
  // clang-format on
  const auto jump = prune_path(map, {{0, 0}, {2, 0}}, CornerPolicy::kNever);
  ASSERT_EQ(jump.size(), 2u);
  EXPECT_EQ(jump[0], cell_centre({0, 0}));
  EXPECT_EQ(jump[1], cell_centre({2, 0}));
  const auto from_blocked = prune_path(map, {{1, 0}, {1, 1}, {2, 1}}, CornerPolicy::kNever);
  EXPECT_EQ(from_blocked.front(), cell_centre({1, 0}));
  EXPECT_EQ(from_blocked.back(), cell_centre({2, 1}));
}

// ---------------------------------------------------------------------------------------------
// Smoothing

TEST(SmoothPath, FewerThanThreePointsAreReturnedUnchanged) {
  const GridMap map = empty_map(8, 8);
  const std::vector<Point2> none, one = {{1.5, 1.5}}, two = {{1.5, 1.5}, {6.5, 4.5}};
  EXPECT_EQ(smooth_path(map, none, {}), none);
  EXPECT_EQ(smooth_path(map, one, {}), one);
  EXPECT_EQ(smooth_path(map, two, {}), two);
}

TEST(SmoothPath, RepeatedPointsGiveNoNaN) {
  const GridMap map = empty_map(12, 12);
  const std::vector<Point2> in = {{1.5, 1.5}, {1.5, 1.5}, {8.5, 1.5}, {8.5, 1.5},
                                  {8.5, 1.5}, {8.5, 9.5}, {8.5, 9.5}};
  const auto out = smooth_path(map, in, {});
  ASSERT_TRUE(finite(out));
  EXPECT_EQ(out.front(), in.front());
  EXPECT_EQ(out.back(), in.back());
  EXPECT_TRUE(dense_free(map, out));
}

TEST(SmoothPath, CollinearWaypointIsKept) {
  const GridMap map = empty_map(12, 4);
  const std::vector<Point2> in = {{0.5, 1.5}, {5.5, 1.5}, {11.5, 1.5}};
  EXPECT_EQ(smooth_path(map, in, {}), in);
}

// The corner A -> T -> B on an open map, smoothed with `options`: every section 5 property.
void expect_smooth_corner(const Point2& a, const Point2& t, const Point2& b,
                          const SmoothingOptions& options = {}) {
  const GridMap map = empty_map(24, 24);
  const double corner = heading_change(a, t, b);
  const double d = std::min({options.smoothing_distance, (t - a).norm() / 4, (b - t).norm() / 4});
  const auto out = smooth_path(map, {a, t, b}, options);
  ASSERT_TRUE(finite(out));
  ASSERT_GT(out.size(), 4u) << "the corner was not smoothed";
  EXPECT_EQ(out.front(), a);
  EXPECT_EQ(out.back(), b);
  EXPECT_TRUE(dense_free(map, out));

  // The replacement runs from P1 (on leg A-T, 2d before T) to P4 (on leg T-B, 2d after T).
  const Point2 p1 = t + 2 * d * (a - t).normalized(), p4 = t + 2 * d * (b - t).normalized();
  EXPECT_LT((out[1] - p1).norm(), 1e-9);
  EXPECT_LT((out[out.size() - 2] - p4).norm(), 1e-9);
  // The spline interpolates P2 and P3 (d from T on each leg), and they are among the samples.
  for (const Point2& knot :
       {Point2(t + d * (a - t).normalized()), Point2(t + d * (b - t).normalized())}) {
    bool found = false;
    for (const Point2& p : out) found = found || (p - knot).norm() < 1e-9;
    EXPECT_TRUE(found) << "knot (" << knot.transpose() << ") missing";
  }
  for (size_t i = 1; i + 1 < out.size(); ++i) {
    EXPECT_LE((out[i] - t).norm(), 2 * d + 1e-9) << "sample " << i << " leaves the corner";
    EXPECT_GT((out[i] - t).norm(), 1e-3) << "the spline must not pass through T";
  }
  for (size_t i = 2; i + 1 < out.size(); ++i) {
    EXPECT_LE((out[i] - out[i - 1]).norm(), options.sample_step + 1e-9) << "gap before " << i;
  }

  // Tangent continuity: the first and last spline segments follow the straight legs.
  EXPECT_LT(angle_between(out[2] - out[1], t - a), std::abs(corner) / 10);
  EXPECT_LT(angle_between(out[out.size() - 2] - out[out.size() - 3], b - t), std::abs(corner) / 10);

  // The curve turns by exactly the corner's angle, spread over many small turns.
  EXPECT_NEAR(total_turn(out), corner, 1e-6);
  for (size_t i = 1; i + 1 < out.size(); ++i) {
    const double turn = heading_change(out[i - 1], out[i], out[i + 1]);
    EXPECT_LE(std::abs(turn), std::abs(corner) / 4) << "vertex " << i;
    // Interpolating P2 and P3 with C2 continuity forces a slight counter-turn (an inflection)
    // between P1 and P2 and between P3 and P4; between P2 and P3 the curve turns one way only.
    if (turn * corner < 0) {
      EXPECT_GT((out[i] - t).norm(), d - 1e-9) << "counter-turn at vertex " << i;
    }
  }
  EXPECT_LT(polyline_length(out), polyline_length({a, t, b}));
}

TEST(SmoothPath, RightAngleOnEmptyMap) {
  expect_smooth_corner({2.5, 2.5}, {14.5, 2.5}, {14.5, 14.5});  // horizontal, then up
}

TEST(SmoothPath, VerticalToHorizontalCorner) {
  // x is constant along the first leg: the paper's y = S(x) cannot describe it.
  expect_smooth_corner({3.5, 18.5}, {3.5, 4.5}, {17.5, 4.5});
  expect_smooth_corner({9.5, 2.5}, {9.5, 15.5}, {2.5, 15.5});  // up, then left (a left turn)
}

TEST(SmoothPath, ObliqueAndSharpCorners) {
  expect_smooth_corner({2.5, 2.5}, {12.5, 2.5}, {20.5, 7.5});   // gentle
  expect_smooth_corner({2.5, 2.5}, {12.5, 12.5}, {4.5, 14.5});  // sharp, about 120 degrees
  expect_smooth_corner({20.5, 3.5}, {4.5, 9.5}, {21.5, 12.5});  // very sharp
  SmoothingOptions fine;
  fine.sample_step = 0.05;
  fine.smoothing_distance = 2.5;
  expect_smooth_corner({2.5, 2.5}, {14.5, 2.5}, {14.5, 14.5}, fine);
}

TEST(SmoothPath, KinkAtTheJoinVanishesWithFinerSampling) {
  const GridMap map = empty_map(24, 24);
  const std::vector<Point2> in = {{2.5, 2.5}, {14.5, 2.5}, {14.5, 14.5}};
  auto kink = [&](double step) {
    SmoothingOptions options;
    options.sample_step = step;
    const auto out = smooth_path(map, in, options);
    return angle_between(out[2] - out[1], in[1] - in[0]);
  };
  EXPECT_LT(kink(0.05), kink(0.25));
  EXPECT_LT(kink(0.01), kink(0.05));
  EXPECT_LT(kink(0.01), 0.01);
}

TEST(SmoothPath, NeighbouringCornersDoNotOverlap) {
  // A zigzag with short legs: d is capped at a quarter of each leg, so each corner's curve
  // stays in its own half of every leg and the path's total turn is unchanged.
  const GridMap map = empty_map(24, 24);
  const std::vector<Point2> in = {{1.5, 1.5}, {5.5, 1.5},  {5.5, 3.5},  {9.5, 3.5},
                                  {9.5, 5.5}, {20.5, 5.5}, {20.5, 20.5}};
  const auto out = smooth_path(map, in, {});
  ASSERT_TRUE(finite(out));
  EXPECT_GT(out.size(), in.size() * 3);
  EXPECT_TRUE(dense_free(map, out));
  EXPECT_NEAR(total_turn(out), total_turn(in), 1e-6);
  // Monotone progress along x and y: overlapping curves would double back.
  for (size_t i = 1; i < out.size(); ++i) {
    EXPECT_GT(out[i].x() - out[i - 1].x() + out[i].y() - out[i - 1].y(), 0.0) << "point " << i;
  }
}

TEST(SmoothPath, NarrowCorridorCornerShrinksOrStaysSharp) {
  // A one-cell-wide L corridor: the full-size curve cuts the blocked inside cell (8, 3).
  // clang-format off
  const GridMap map = map_of({"############",
                              "############",
                              "#########.##",
                              "#########.##",
                              "#########.##",
                              "#########.##",
                              "#########.##",
                              "#########.##",
                              "#########.##",
                              "##........##",
                              "############",
                              "############"});
  // clang-format on
  const std::vector<Point2> in = {{2.5, 2.5}, {9.5, 2.5}, {9.5, 9.5}};
  ASSERT_TRUE(dense_free(map, in));

  SmoothingOptions no_retry;
  no_retry.max_halvings = 0;
  EXPECT_EQ(smooth_path(map, in, no_retry), in) << "the unhalved curve must be rejected";

  const auto out = smooth_path(map, in, {});
  EXPECT_GT(out.size(), 3u) << "a halved curve fits inside the corridor";
  EXPECT_TRUE(dense_free(map, out));
  EXPECT_EQ(out.front(), in.front());
  EXPECT_EQ(out.back(), in.back());
}

TEST(SmoothPath, CornerHuggingAnObstacle) {
  // The path runs right, then up, tight around the obstacle (10..11, 5) inside the turn; the
  // cell (13, 3) diagonally outside the turn is blocked too.
  std::vector<std::string> rows(18, std::string(15, '.'));
  auto block = [&rows](int x, int y) { rows[rows.size() - 1 - y][x] = '#'; };
  block(10, 5);
  block(11, 5);
  block(13, 3);
  const GridMap map = map_of(rows);
  const std::vector<Point2> in = {{0.5, 4.5}, {12.5, 4.5}, {12.5, 16.5}};
  ASSERT_TRUE(dense_free(map, in));
  SmoothingOptions wide;
  wide.smoothing_distance = 3.0;
  for (int halvings : {0, 3}) {
    wide.max_halvings = halvings;
    const auto out = smooth_path(map, in, wide);
    EXPECT_TRUE(out == in || out.size() > 3u);
    EXPECT_TRUE(dense_free(map, out)) << halvings << " halvings";
    for (size_t i = 1; i < out.size(); ++i) {
      EXPECT_TRUE(line_of_sight(map, out[i - 1], out[i], CornerPolicy::kNever)) << "segment " << i;
    }
    // Without the obstacle the full-size curve is accepted; with it, it is not.
    if (halvings == 0) {
      EXPECT_EQ(out, in) << "the full-size curve cuts cell (11, 5)";
      EXPECT_GT(smooth_path(empty_map(15, 18), in, wide).size(), 3u);
    } else {
      EXPECT_GT(out.size(), 3u) << "a halved curve clears the obstacle";
    }
  }
}

TEST(SmoothPath, NonPositiveSampleStepLeavesThePathAlone) {
  const GridMap map = empty_map(12, 12);
  const std::vector<Point2> in = {{1.5, 1.5}, {8.5, 1.5}, {8.5, 9.5}};
  SmoothingOptions options;
  options.sample_step = 0.0;
  EXPECT_EQ(smooth_path(map, in, options), in);
  options.sample_step = std::nan("");
  EXPECT_EQ(smooth_path(map, in, options), in);
}

// ---------------------------------------------------------------------------------------------
// Property test: random maps, pruned grid paths and random visible-waypoint walks.

TEST(PostprocessProperty, SmoothedPathsNeverEnterBlockedCells) {
  std::mt19937 rng(20240607);
  auto uniform = [&rng](double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng);
  };
  auto pick = [&rng](size_t n) { return std::uniform_int_distribution<size_t>(0, n - 1)(rng); };
  const CornerPolicy policy = CornerPolicy::kNever;
  int with_corners = 0, smoothed = 0;

  auto check_smoothing = [&](const GridMap& map, const std::vector<Point2>& in) {
    SmoothingOptions options;
    if (rng() % 2 == 0) {
      options.smoothing_distance = uniform(0.3, 3.0);
      options.sample_step = uniform(0.05, 0.5);
      options.max_halvings = static_cast<int>(rng() % 5);
    }
    ASSERT_TRUE(dense_free(map, in)) << "test bug: the input itself is not free";
    const auto out = smooth_path(map, in, options);
    ASSERT_TRUE(finite(out));
    ASSERT_FALSE(out.empty());
    EXPECT_EQ(out.front(), in.front());
    EXPECT_EQ(out.back(), in.back());
    ASSERT_TRUE(dense_free(map, out)) << map.width() << "x" << map.height();
    if (in.size() >= 3) ++with_corners;
    if (out.size() > in.size()) ++smoothed;
  };

  for (int trial = 0; trial < 2000; ++trial) {
    const int w = 8 + static_cast<int>(rng() % 33), h = 8 + static_cast<int>(rng() % 33);
    const double density = uniform(0.0, 0.4);
    std::vector<std::string> rows(h, std::string(w, '.'));
    for (auto& row : rows) {
      for (char& c : row) c = uniform(0.0, 1.0) < density ? '#' : '.';
    }
    const GridMap map = map_of(rows);
    std::vector<Cell> free_cells;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        if (map.free({x, y})) free_cells.push_back({x, y});
      }
    }
    if (free_cells.size() < 2) continue;

    // A shortest grid path, pruned, then smoothed.
    const auto path =
        bfs_path(map, free_cells[pick(free_cells.size())], free_cells[pick(free_cells.size())]);
    if (!path.empty()) {
      const auto pruned = prune_path(map, path, policy);
      expect_valid_pruning(map, path, pruned, policy);
      check_smoothing(map, pruned);
    }

    // A random walk of mutually visible waypoints.
    std::vector<Cell> walk = {free_cells[pick(free_cells.size())]};
    const size_t target = 2 + rng() % 7;
    for (int tries = 0; tries < 200 && walk.size() < target; ++tries) {
      const Cell next = free_cells[pick(free_cells.size())];
      if (!(next == walk.back()) && line_of_sight(map, walk.back(), next, policy)) {
        walk.push_back(next);
      }
    }
    check_smoothing(map, cell_centres(walk));
    if (HasFatalFailure()) return;
  }
  // Not vacuous: many inputs had corners, and a good share of those were actually smoothed.
  EXPECT_GT(with_corners, 1000);
  EXPECT_GT(smoothed, with_corners / 4);
}

}  // namespace
}  // namespace vnsba::core
