// Independent oracles for the core tests. Nothing here calls the code under test except to read
// a cell's blocked flag, so a bug in the planners' line of sight, moves or search cannot hide.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <queue>
#include <random>
#include <string>
#include <vector>

#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/line_of_sight.hpp"

namespace vnsba::test {

using core::Cell;
using core::CornerPolicy;
using core::GridMap;
using core::Point2;

inline bool cell_free(const GridMap& map, int64_t x, int64_t y) {
  return x >= 0 && y >= 0 && x < map.width() && y < map.height() &&
         !map.blocked(static_cast<int32_t>(x), static_cast<int32_t>(y));
}

// docs/algorithm.md section 1, "Corners": a diagonal step between two side cells is allowed
// when both are free (never), one is (touch), or always.
inline bool corner_allowed(bool side_a_free, bool side_b_free, CornerPolicy policy) {
  switch (policy) {
    case CornerPolicy::kNever:
      return side_a_free && side_b_free;
    case CornerPolicy::kTouch:
      return side_a_free || side_b_free;
    case CornerPolicy::kAlways:
      return true;
  }
  return false;
}

// Dense sampling check of a segment in continuous cell coordinates: every sample point (every
// 1/`per_cell` cell) must lie in a free cell, and so must the points a hair to either side of it
// according to the corner policy (never: both sides; touch: at least one side; always: the point
// itself only). The side points catch a segment slipping through the corner of two blocked cells.
inline bool segment_clear_sampled(const GridMap& map, const Point2& a, const Point2& b,
                                  CornerPolicy policy, int per_cell = 64) {
  const Point2 d = b - a;
  const double len = d.norm();
  const int samples = std::max(2, static_cast<int>(std::ceil(len * per_cell)) + 1);
  const Point2 normal = len > 0 ? Point2(-d.y() / len, d.x() / len) : Point2(0, 0);
  constexpr double kSide = 1e-7;
  auto free_at = [&](const Point2& p) {
    return cell_free(map, static_cast<int64_t>(std::floor(p.x())),
                     static_cast<int64_t>(std::floor(p.y())));
  };
  for (int i = 0; i < samples; ++i) {
    const Point2 p = a + d * (static_cast<double>(i) / (samples - 1));
    // A point exactly on a lattice corner belongs to no single cell; corners are checked below.
    if (p.x() == std::floor(p.x()) && p.y() == std::floor(p.y())) continue;
    if (!free_at(p)) return false;
    const bool left = free_at(p + kSide * normal), right = free_at(p - kSide * normal);
    if (policy == CornerPolicy::kNever && !(left && right)) return false;
    if (policy == CornerPolicy::kTouch && !(left || right)) return false;
  }
  // A segment through an exact lattice corner is sampled there only by luck; check each corner
  // the segment passes within a hair of explicitly.
  if (policy != CornerPolicy::kAlways && d.x() != 0 && d.y() != 0) {
    const int64_t x0 = static_cast<int64_t>(std::floor(std::min(a.x(), b.x())));
    const int64_t x1 = static_cast<int64_t>(std::ceil(std::max(a.x(), b.x())));
    for (int64_t cx = x0; cx <= x1; ++cx) {
      const double t = (cx - a.x()) / d.x();
      if (t <= 0 || t >= 1) continue;
      const double cy = a.y() + t * d.y();
      if (std::abs(cy - std::round(cy)) > 1e-9) continue;
      const int64_t ry = static_cast<int64_t>(std::round(cy));
      // The four cells around the corner (cx, ry); the segment runs through two diagonal ones.
      const bool sx = d.x() > 0, sy = d.y() > 0;
      const int64_t ax = sx ? cx - 1 : cx, ay = sy ? ry : ry - 1;  // side cell: before in x
      const int64_t bx = sx ? cx : cx - 1, by = sy ? ry - 1 : ry;  // side cell: before in y
      const bool fa = cell_free(map, ax, ay), fb = cell_free(map, bx, by);
      if (policy == CornerPolicy::kNever && !(fa && fb)) return false;
      if (policy == CornerPolicy::kTouch && !(fa || fb)) return false;
    }
  }
  return true;
}

// Exact line of sight between two cell centres, by definition rather than traversal: every cell
// whose open interior the segment crosses must be free, and at every lattice corner the segment
// passes through, the two cells beside it must satisfy the corner policy. Integer arithmetic on
// doubled coordinates, O(bounding box area): for small test maps only.
inline bool reference_los_centres(const GridMap& map, Cell a, Cell b, CornerPolicy policy) {
  if (!cell_free(map, a.x, a.y) || !cell_free(map, b.x, b.y)) return false;
  const int64_t ax2 = 2 * a.x + 1, ay2 = 2 * a.y + 1;  // doubled centre coordinates
  const int64_t dx2 = 2 * int64_t{b.x - a.x}, dy2 = 2 * int64_t{b.y - a.y};
  struct Frac {
    int64_t num, den;  // den > 0
  };
  auto frac = [](int64_t num, int64_t den) { return den < 0 ? Frac{-num, -den} : Frac{num, den}; };
  auto less = [](Frac p, Frac q) { return p.num * q.den < q.num * p.den; };
  auto max_f = [&](Frac p, Frac q) { return less(p, q) ? q : p; };
  auto min_f = [&](Frac p, Frac q) { return less(p, q) ? p : q; };
  for (int64_t y = std::min(a.y, b.y); y <= std::max(a.y, b.y); ++y) {
    for (int64_t x = std::min(a.x, b.x); x <= std::max(a.x, b.x); ++x) {
      Frac lo{0, 1}, hi{1, 1};
      bool crosses = true;
      const int64_t lows[2] = {2 * x, 2 * y}, starts[2] = {ax2, ay2}, deltas[2] = {dx2, dy2};
      for (int axis = 0; axis < 2 && crosses; ++axis) {
        if (deltas[axis] == 0) {
          crosses = starts[axis] > lows[axis] && starts[axis] < lows[axis] + 2;
        } else {
          Frac t1 = frac(lows[axis] - starts[axis], deltas[axis]);
          Frac t2 = frac(lows[axis] + 2 - starts[axis], deltas[axis]);
          lo = max_f(lo, min_f(t1, t2));
          hi = min_f(hi, max_f(t1, t2));
        }
      }
      if (crosses && less(lo, hi) && !cell_free(map, x, y)) return false;
    }
  }
  if (dx2 == 0 || dy2 == 0 || policy == CornerPolicy::kAlways) return true;
  for (int64_t cx = std::min(a.x, b.x) + 1; cx <= std::max(a.x, b.x); ++cx) {
    // y2 at x = cx: ay2 + (2cx - ax2) * dy2 / dx2; a corner when that is an even integer.
    const int64_t num = (2 * cx - ax2) * dy2;
    if (num % dx2 != 0) continue;
    const int64_t y2 = ay2 + num / dx2;
    if (y2 % 2 != 0) continue;
    const int64_t cy = y2 / 2;
    const bool sx = dx2 > 0, sy = dy2 > 0;
    const bool fa = cell_free(map, sx ? cx - 1 : cx, sy ? cy : cy - 1);
    const bool fb = cell_free(map, sx ? cx : cx - 1, sy ? cy - 1 : cy);
    if (policy == CornerPolicy::kNever && !(fa && fb)) return false;
    if (policy == CornerPolicy::kTouch && !(fa || fb)) return false;
  }
  return true;
}

// Calls visit(dx, dy) for each 8-connected move from free cell (x, y) to a free cell that `policy`
// allows (a diagonal one by its two side cells: both free for never, one for touch), written
// from docs/algorithm.md section 1 rather than taken from the planner.
template <class Visit>
void for_each_oracle_move(const GridMap& map, int64_t x, int64_t y, CornerPolicy policy,
                          Visit&& visit) {
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      if ((dx == 0 && dy == 0) || !cell_free(map, x + dx, y + dy)) continue;
      if (dx != 0 && dy != 0) {
        const bool a = cell_free(map, x + dx, y), b = cell_free(map, x, y + dy);
        if (policy == CornerPolicy::kNever && !(a && b)) continue;
        if (policy == CornerPolicy::kTouch && !(a || b)) continue;
      }
      visit(dx, dy);
    }
  }
}

// Optimal 8-connected path cost (cells) by plain Dijkstra; infinity when unreachable.
inline double reference_shortest_cost(const GridMap& map, Cell s, Cell g, CornerPolicy policy) {
  const int64_t w = map.width(), h = map.height();
  std::vector<double> dist(static_cast<size_t>(w * h), std::numeric_limits<double>::infinity());
  using Item = std::pair<double, int64_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> open;
  dist[s.y * w + s.x] = 0;
  open.push({0.0, s.y * w + s.x});
  while (!open.empty()) {
    auto [d, i] = open.top();
    open.pop();
    if (d > dist[i]) continue;
    const int64_t x = i % w, y = i / w;
    if (x == g.x && y == g.y) return d;
    for_each_oracle_move(map, x, y, policy, [&, d = d](int dx, int dy) {
      const double nd = d + ((dx != 0 && dy != 0) ? std::sqrt(2.0) : 1.0);
      const int64_t j = (y + dy) * w + (x + dx);
      if (nd < dist[j]) {
        dist[j] = nd;
        open.push({nd, j});
      }
    });
  }
  return std::numeric_limits<double>::infinity();
}

// Component labels of the free cells under the planners' move graph (docs/algorithm.md section 1):
// 8-connected moves, a diagonal one only where `policy` lets it pass its two side cells. A
// breadth-first search over the whole grid from every unlabelled free cell, on the map's blocked
// flags alone. Row-major (index y * width + x); -1 on blocked cells.
inline std::vector<int32_t> component_labels(const GridMap& map, CornerPolicy policy) {
  const int64_t w = map.width(), h = map.height();
  std::vector<int32_t> label(static_cast<size_t>(w * h), -1);
  int32_t next = 0;
  for (int64_t seed = 0; seed < w * h; ++seed) {
    if (label[seed] >= 0 || !cell_free(map, seed % w, seed / w)) continue;
    std::queue<int64_t> open;
    label[seed] = next;
    open.push(seed);
    while (!open.empty()) {
      const int64_t i = open.front();
      open.pop();
      const int64_t x = i % w, y = i / w;
      for_each_oracle_move(map, x, y, policy, [&](int dx, int dy) {
        const int64_t j = (y + dy) * w + (x + dx);
        if (label[j] >= 0) return;
        label[j] = next;
        open.push(j);
      });
    }
    ++next;
  }
  return label;
}

// A random map as text rows (top row first), '#' blocked.
inline std::vector<std::string> random_rows(std::mt19937& rng, int width, int height,
                                            double density) {
  std::bernoulli_distribution blocked(density);
  std::vector<std::string> rows(height, std::string(width, '.'));
  for (auto& row : rows)
    for (char& c : row) c = blocked(rng) ? '#' : '.';
  return rows;
}

constexpr CornerPolicy kAllCornerPolicies[] = {CornerPolicy::kNever, CornerPolicy::kTouch,
                                               CornerPolicy::kAlways};

// A random map of `width` x `height` cells (each blocked with probability `density`), shared
// for planners.
inline std::shared_ptr<const GridMap> random_shared_map(std::mt19937& rng, int width, int height,
                                                        double density) {
  auto built = GridMap::from_rows(random_rows(rng, width, height, density));
  return built ? std::make_shared<const GridMap>(std::move(built).value()) : nullptr;
}

inline std::vector<Cell> free_cells(const GridMap& map) {
  std::vector<Cell> out;
  for (int32_t y = 0; y < map.height(); ++y)
    for (int32_t x = 0; x < map.width(); ++x)
      if (!map.blocked(x, y)) out.push_back({x, y});
  return out;
}

inline std::string fixture_path(const std::string& name) {
  return std::string(VNSBA_FIXTURE_DIR) + "/" + name;
}

inline std::string data_path(const std::string& name) {
  return std::string(VNSBA_DATA_DIR) + "/" + name;
}

// Checks a path cell by cell without the code under test (only the map's blocked flags): it
// runs from start to goal, every cell is in the map and free, consecutive cells are distinct
// 8-neighbours, and a diagonal step has both side cells free. `length` gets the polyline length
// of the cell centres (cells).
inline ::testing::AssertionResult valid_grid_path(const GridMap& map, const std::vector<Cell>& path,
                                                  Cell start, Cell goal, double* length) {
  if (path.empty()) return ::testing::AssertionFailure() << "empty path";
  if (path.front() != start) return ::testing::AssertionFailure() << "does not begin at start";
  if (path.back() != goal) return ::testing::AssertionFailure() << "does not end at goal";
  int64_t straight = 0, diagonal = 0;
  for (size_t i = 0; i < path.size(); ++i) {
    const Cell c = path[i];
    if (!cell_free(map, c.x, c.y)) {
      return ::testing::AssertionFailure()
             << "cell " << i << " (" << c.x << ", " << c.y << ") is blocked or outside";
    }
    if (i == 0) continue;
    const Cell p = path[i - 1];
    const int dx = c.x - p.x, dy = c.y - p.y;
    if (std::abs(dx) > 1 || std::abs(dy) > 1 || (dx == 0 && dy == 0)) {
      return ::testing::AssertionFailure()
             << "step " << i << " (" << p.x << ", " << p.y << ") -> (" << c.x << ", " << c.y
             << ") is not a move to an 8-neighbour";
    }
    if (dx != 0 && dy != 0) {
      if (!cell_free(map, p.x + dx, p.y) || !cell_free(map, p.x, p.y + dy)) {
        return ::testing::AssertionFailure() << "step " << i << " (" << p.x << ", " << p.y
                                             << ") -> (" << c.x << ", " << c.y << ") cuts a corner";
      }
      ++diagonal;
    } else {
      ++straight;
    }
  }
  *length = static_cast<double>(straight) + static_cast<double>(diagonal) * std::sqrt(2.0);
  return ::testing::AssertionSuccess();
}

// Exact distance between the segments [p, q] and [r, s] (cells): 0 where they cross, otherwise
// the least distance of an end of one to the other (written apart from the metric's own
// geometry, which measures against squares through clipping and corners).
inline double point_segment_distance(const Point2& p, const Point2& a, const Point2& b) {
  const Point2 ab = b - a;
  const double l2 = ab.squaredNorm();
  const double t = l2 > 0.0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}
inline double cross(const Point2& u, const Point2& v) {
  return u.x() * v.y() - u.y() * v.x();
}
inline double segment_segment_distance(const Point2& p, const Point2& q, const Point2& r,
                                       const Point2& s) {
  const double d1 = cross(q - p, r - p), d2 = cross(q - p, s - p);
  const double d3 = cross(s - r, p - r), d4 = cross(s - r, q - r);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
    return 0.0;
  return std::min({point_segment_distance(p, r, s), point_segment_distance(q, r, s),
                   point_segment_distance(r, p, q), point_segment_distance(s, p, q)});
}
// Exact distance from a polyline to the square of cell c (an oracle of path clearance): 0 where a
// vertex lies in it, else the least distance of a segment to its four sides.
inline double polyline_square_distance(const std::vector<Point2>& polyline, const Cell& c) {
  const Point2 corners[4] = {{c.x + 0.0, c.y + 0.0},
                             {c.x + 1.0, c.y + 0.0},
                             {c.x + 1.0, c.y + 1.0},
                             {c.x + 0.0, c.y + 1.0}};
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < polyline.size(); ++i) {
    const Point2& a = polyline[i];
    if (a.x() >= c.x && a.x() <= c.x + 1.0 && a.y() >= c.y && a.y() <= c.y + 1.0) return 0.0;
    const Point2& b = polyline[std::min(i + 1, polyline.size() - 1)];
    for (int k = 0; k < 4; ++k)
      best = std::min(best, segment_segment_distance(a, b, corners[k], corners[(k + 1) % 4]));
  }
  return best;
}

}  // namespace vnsba::test
