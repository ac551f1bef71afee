#include "vnsba/core/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <utility>

#include "vnsba/core/line_of_sight.hpp"

namespace vnsba::core {

namespace {

// The index of a leg that is one of the 8 moves of a grid path or zero, 0..8 (x and y each -1, 0
// or 1); -1 for any other leg.
int unit_leg_index(const Point2& leg) {
  const auto unit = [](double v) { return v == -1.0 || v == 0.0 || v == 1.0; };
  if (!unit(leg.x()) || !unit(leg.y())) return -1;
  return static_cast<int>(leg.x() + 1.0) * 3 + static_cast<int>(leg.y() + 1.0);
}

// |heading_change_between(in, out)| for every pair of unit legs (the turns of a grid path), by
// the same function: the same numbers without an atan2 a turn.
struct UnitTurnTable {
  double change[9][9];
  UnitTurnTable() {
    for (int in = 0; in < 9; ++in)
      for (int out = 0; out < 9; ++out)
        change[in][out] = std::abs(heading_change_between(Point2(in / 3 - 1, in % 3 - 1),
                                                          Point2(out / 3 - 1, out % 3 - 1)));
  }
};

double absolute_heading_change(const Point2& in, const Point2& out) {
  static const UnitTurnTable unit_turns;
  const int from = unit_leg_index(in), to = unit_leg_index(out);
  if (from >= 0 && to >= 0) return unit_turns.change[from][to];
  return std::abs(heading_change_between(in, out));
}

}  // namespace

TurnStats turn_stats(const std::vector<Point2>& polyline) {
  TurnStats stats;
  if (polyline.size() < 3) return stats;
  Point2 in = polyline[1] - polyline[0];  // the leg into vertex i
  for (size_t i = 1; i + 1 < polyline.size(); ++i) {
    const Point2 out = polyline[i + 1] - polyline[i];
    // Straight on along equal legs (most vertices of a grid path): heading_change_between gives
    // 0 (or NaN where the legs' products overflow), no turn either way.
    if (out.x() == in.x() && out.y() == in.y()) continue;
    const double change = absolute_heading_change(in, out);
    in = out;
    if (change > kTurnEpsilonRad) {
      ++stats.turns;
      stats.total_angle_deg += change * 180.0 / M_PI;
    }
  }
  return stats;
}

std::vector<Point2> simplify_polyline(const std::vector<Point2>& polyline, double tolerance) {
  if (polyline.size() < 3) return polyline;
  std::vector<bool> keep(polyline.size(), false);
  keep.front() = keep.back() = true;
  // Iterative Douglas-Peucker: split each span at its farthest point while that is too far.
  std::vector<std::pair<size_t, size_t>> spans = {{0, polyline.size() - 1}};
  while (!spans.empty()) {
    const auto [first, last] = spans.back();
    spans.pop_back();
    double farthest = -1.0;
    size_t at = first;
    for (size_t k = first + 1; k < last; ++k) {
      const double distance = distance_to_segment(polyline[k], polyline[first], polyline[last]);
      if (distance > farthest) {
        farthest = distance;
        at = k;
      }
    }
    if (farthest > tolerance) {
      keep[at] = true;
      spans.emplace_back(first, at);
      spans.emplace_back(at, last);
    }
  }
  std::vector<Point2> out;
  for (size_t k = 0; k < polyline.size(); ++k)
    if (keep[k]) out.push_back(polyline[k]);
  return out;
}

double max_curvature(const std::vector<Point2>& polyline) {
  double most = 0.0;
  for (size_t i = 1; i + 1 < polyline.size(); ++i) {
    const double mean_length =
        ((polyline[i] - polyline[i - 1]).norm() + (polyline[i + 1] - polyline[i]).norm()) / 2.0;
    if (!(mean_length > 0.0)) continue;
    const double change = std::abs(heading_change(polyline[i - 1], polyline[i], polyline[i + 1]));
    most = std::max(most, change / mean_length);
  }
  return most;
}

}  // namespace vnsba::core

namespace vnsba::core {

namespace {

constexpr double kSqrt2 = 1.4142135623730950488;

// Distance from p to the square [x, x + 1] x [y, y + 1] (cells).
double distance_to_square(const Point2& p, int32_t x, int32_t y) {
  const double dx = std::max({x - p.x(), 0.0, p.x() - (x + 1)});
  const double dy = std::max({y - p.y(), 0.0, p.y() - (y + 1)});
  return std::hypot(dx, dy);
}

// Distance from the segment [a, b] to the square [x, x + 1] x [y, y + 1] (cells): 0 where the
// segment meets the square (Liang-Barsky clipping), otherwise the least of its ends' distances to
// the square and the square's corners' distances to the segment (two disjoint convex polygons are
// nearest at a vertex of one of them).
double segment_square_distance(const Point2& a, const Point2& b, int32_t x, int32_t y) {
  const Point2 ab = b - a;
  double t_in = 0.0, t_out = 1.0;
  bool meets = true;
  for (int axis = 0; axis < 2 && meets; ++axis) {
    const double low = axis == 0 ? x : y;
    const double from = a[axis], step = ab[axis];
    if (step == 0.0) {
      meets = from >= low && from <= low + 1.0;
      continue;
    }
    double t0 = (low - from) / step, t1 = (low + 1.0 - from) / step;
    if (t0 > t1) std::swap(t0, t1);
    t_in = std::max(t_in, t0);
    t_out = std::min(t_out, t1);
    meets = t_in <= t_out;
  }
  if (meets) return 0.0;
  double best = std::min(distance_to_square(a, x, y), distance_to_square(b, x, y));
  for (const int32_t cx : {x, x + 1})
    for (const int32_t cy : {y, y + 1}) best = std::min(best, distance_to_segment({cx, cy}, a, b));
  return best;
}

// The end cells of a grid path's straight run: [a, b] from a cell centre to a cell centre along
// an axis or a diagonal, both in the map; nullopt for any other segment.
std::optional<std::pair<Cell, Cell>> straight_run_cells(const GridMap& map, const Point2& a,
                                                        const Point2& b) {
  const double ax = a.x() - 0.5, ay = a.y() - 0.5, bx = b.x() - 0.5, by = b.y() - 0.5;
  for (const double coordinate : {ax, ay, bx, by})
    if (!(coordinate >= 0.0 && coordinate < 1e9 && std::floor(coordinate) == coordinate))
      return std::nullopt;
  const Cell from{static_cast<int32_t>(ax), static_cast<int32_t>(ay)};
  const Cell to{static_cast<int32_t>(bx), static_cast<int32_t>(by)};
  if (!map.in_bounds(from) || !map.in_bounds(to)) return std::nullopt;
  const int32_t dx = to.x - from.x, dy = to.y - from.y;
  if (dx != 0 && dy != 0 && std::abs(dx) != std::abs(dy)) return std::nullopt;
  return std::make_pair(from, to);
}

}  // namespace

double segment_clearance_bound(const GridMap& map, const Point2& a, const Point2& b) {
  constexpr double kHalfSqrt2 = 0.70710678118654752440;
  const auto bound_at = [&](const Point2& p) {
    if (!(p.x() >= 0.0 && p.y() >= 0.0 && p.x() < map.width() && p.y() < map.height())) return -1.0;
    const Cell cell{static_cast<int32_t>(p.x()), static_cast<int32_t>(p.y())};
    // A lower bound from the field (0 without one: then no bound); the factor undoes sqrt's
    // rounding (half an ulp).
    const double centre_distance = map.obstacle_distance_at_least(cell) * (1.0 - 1e-12);
    return centre_distance - (p - cell_centre(cell)).norm() - kHalfSqrt2;
  };
  const double bound = std::min(bound_at(a), bound_at(b)) - (b - a).norm() / 2;
  return bound < 0.0 ? -1.0 : bound;
}

bool segment_clearance_at_least(const GridMap& map, const Point2& a, const Point2& b,
                                double cells) {
  if (!(cells > 0.0)) return true;
  // Far from obstacles the distance transform answers without a scan.
  if (segment_clearance_bound(map, a, b) >= cells) return true;
  const auto clamp_x = [&](double v) {
    return static_cast<int32_t>(std::clamp(std::floor(v), -1.0, static_cast<double>(map.width())));
  };
  const auto clamp_y = [&](double v) {
    return static_cast<int32_t>(std::clamp(std::floor(v), -1.0, static_cast<double>(map.height())));
  };
  const int32_t x0 = std::max(0, clamp_x(std::min(a.x(), b.x()) - cells));
  const int32_t x1 = std::min(map.width() - 1, clamp_x(std::max(a.x(), b.x()) + cells));
  const int32_t y0 = std::max(0, clamp_y(std::min(a.y(), b.y()) - cells));
  const int32_t y1 = std::min(map.height() - 1, clamp_y(std::max(a.y(), b.y()) + cells));
  for (int32_t y = y0; y <= y1; ++y)
    for (int32_t x = x0; x <= x1; ++x)
      if (map.is_obstacle(map.layer({x, y})) && segment_square_distance(a, b, x, y) < cells)
        return false;
  return true;
}

namespace {

// Without inflation, and without blocked unknown cells that are not obstacles (none in the map, or
// unknown cells free or inflated), every blocked bit is an obstacle: the bit lines tell obstacles
// without the byte layers.
bool every_blocked_cell_is_an_obstacle(const GridMap& map) {
  return map.build_options().robot_radius <= 0.0 && !map.has_blocked_non_obstacles();
}

// Whether a blocked cell (a set bit) is an obstacle (GridMap::is_obstacle): the bit alone says so
// where every blocked cell is one, the byte layer otherwise.
class BlockedCellIsObstacle {
 public:
  explicit BlockedCellIsObstacle(const GridMap& map)
      : map_(map), every_blocked_is_obstacle_(every_blocked_cell_is_an_obstacle(map)) {}
  bool operator()(const Cell& c) const {
    return every_blocked_is_obstacle_ || map_.is_obstacle(map_.layer(c));
  }

 private:
  const GridMap& map_;
  bool every_blocked_is_obstacle_;
};

// The highest u in [from, to] of a bit line whose bit is set and is_obstacle(u) holds; -1 when
// none. A word at a time: the set bits are the blocked cells, is_obstacle tells them apart.
template <class IsObstacle>
int32_t last_obstacle_in(const uint64_t* line, int32_t from, int32_t to, IsObstacle&& is_obstacle) {
  for (int32_t word = to >> 6; word >= from >> 6; --word) {
    const int32_t low = std::max(from, word << 6) & 63;
    const int32_t high = std::min(to, (word << 6) + 63) & 63;
    uint64_t bits = line[word] & (~uint64_t{0} << low) & (~uint64_t{0} >> (63 - high));
    while (bits != 0) {
      const int32_t u = (word << 6) + 63 - __builtin_clzll(bits);
      if (is_obstacle(u)) return u;
      bits &= ~(uint64_t{1} << (u & 63));
    }
  }
  return -1;
}

// The lowest u in [from, to] of a bit line that is set and an obstacle; -1 when none.
template <class IsObstacle>
int32_t first_obstacle_in(const uint64_t* line, int32_t from, int32_t to,
                          IsObstacle&& is_obstacle) {
  for (int32_t word = from >> 6; word <= to >> 6; ++word) {
    const int32_t low = std::max(from, word << 6) & 63;
    const int32_t high = std::min(to, (word << 6) + 63) & 63;
    uint64_t bits = line[word] & (~uint64_t{0} << low) & (~uint64_t{0} >> (63 - high));
    while (bits != 0) {
      const int32_t u = (word << 6) + __builtin_ctzll(bits);
      if (is_obstacle(u)) return u;
      bits &= bits - 1;
    }
  }
  return -1;
}

}  // namespace

double nearest_obstacle_distance(const GridMap& map, const Cell& c, double within) {
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  if (!map.has_obstacles() || !map.in_bounds(c)) return kInfinity;
  const BlockedCellIsObstacle obstacle(map);
  const BlockedBits rows = map.blocked_rows();
  const int64_t w = map.width(), h = map.height();
  int64_t best = std::numeric_limits<int64_t>::max();  // cells^2
  // Squares of half-width 1, 2, 4, ... around c: once the nearest obstacle found lies within the
  // half-width, no cell outside the square (all farther than it) can be nearer. Per row only the
  // nearest obstacle on each side of c.x can be the row's nearest.
  for (int64_t half = 1;; half *= 2) {
    const int32_t x0 = static_cast<int32_t>(std::max<int64_t>(0, c.x - half));
    const int32_t x1 = static_cast<int32_t>(std::min<int64_t>(w - 1, c.x + half));
    const int32_t y0 = static_cast<int32_t>(std::max<int64_t>(0, c.y - half));
    const int32_t y1 = static_cast<int32_t>(std::min<int64_t>(h - 1, c.y + half));
    for (int32_t y = y0; y <= y1; ++y) {
      const int64_t dy = y - c.y;
      if (dy * dy >= best) continue;
      const auto is_obstacle = [&](int32_t x) { return obstacle({x, y}); };
      const uint64_t* line = rows.line(y);
      if (const int32_t x = last_obstacle_in(line, x0, c.x, is_obstacle); x >= 0)
        best = std::min(best, int64_t{c.x - x} * (c.x - x) + dy * dy);
      if (c.x < x1) {
        if (const int32_t x = first_obstacle_in(line, c.x + 1, x1, is_obstacle); x >= 0)
          best = std::min(best, int64_t{x - c.x} * (x - c.x) + dy * dy);
      }
    }
    const bool whole_map = x0 == 0 && y0 == 0 && x1 == w - 1 && y1 == h - 1;
    if (best <= half * half || (whole_map && best != std::numeric_limits<int64_t>::max()))
      return std::sqrt(static_cast<double>(best));
    if (whole_map || static_cast<double>(half) >= within) return kInfinity;
  }
}

namespace {

// The polyline with each collinear run (a grid path's straight moves) as one segment.
std::vector<Point2> merge_collinear_runs(const std::vector<Point2>& polyline) {
  std::vector<Point2> vertices;
  vertices.reserve(polyline.size());
  for (const Point2& p : polyline) {
    if (vertices.size() >= 2) {
      const Point2 u = vertices.back() - vertices[vertices.size() - 2];
      const Point2 v = p - vertices.back();
      if (u.x() * v.y() - u.y() * v.x() == 0.0 && u.dot(v) > 0.0) {
        vertices.back() = p;
        continue;
      }
    }
    vertices.push_back(p);
  }
  return vertices;
}

// An upper bound of the clearance (cells) from the distance field, so that the scan's bands start
// narrow: a vertex is no farther from the nearest obstacle square than from the nearest obstacle
// centre, which is at most its distance to its cell's centre plus that centre's distance to the
// nearest obstacle centre d (the factor undoes sqrt's rounding), a read a vertex. +inf without
// the field or with every vertex beyond its saturation.
double clearance_upper_bound(const GridMap& map, const std::vector<Point2>& vertices) {
  constexpr double kSqrtRounding = 1e-12;
  double bound = std::numeric_limits<double>::infinity();
  for (const Point2& v : vertices) {
    if (!std::isfinite(v.x()) || !std::isfinite(v.y())) continue;
    const Cell c{static_cast<int32_t>(std::clamp(std::floor(v.x()), 0.0, map.width() - 1.0)),
                 static_cast<int32_t>(std::clamp(std::floor(v.y()), 0.0, map.height() - 1.0))};
    const double from_centre = (v - Point2(c.x + 0.5, c.y + 0.5)).norm();
    bound = std::min(bound,
                     map.obstacle_distance_at_most(c) * (1.0 + kSqrtRounding) + from_centre + 1e-9);
  }
  return bound;
}

// A segment as the scan sees it: (u, v) along the bit lines and across them; (x, y) for rows
// (a flat segment), (y, x) for columns (a steep one).
struct ClearanceScanFrame {
  Point2 a, b, ab;
  double length_squared;
  bool columns;
  BlockedBits bit_lines;
  int32_t line_count;
  double last_u;  // the last cell index along a line
  double a_u, a_v, ab_u, ab_v;
  double per_v;  // t per cell across the lines (0 for a segment along a line)
};

ClearanceScanFrame clearance_scan_frame(const GridMap& map, const Point2& a, const Point2& b) {
  ClearanceScanFrame f;
  f.a = a;
  f.b = b;
  f.ab = b - a;
  f.length_squared = f.ab.squaredNorm();
  f.columns = std::abs(f.ab.y()) > std::abs(f.ab.x());
  const int u_axis = f.columns ? 1 : 0, v_axis = 1 - u_axis;
  f.bit_lines = f.columns ? map.blocked_columns() : map.blocked_rows();
  f.line_count = f.columns ? map.width() : map.height();
  f.last_u = (f.columns ? map.height() : map.width()) - 1.0;
  f.a_u = a[u_axis];
  f.a_v = a[v_axis];
  f.ab_u = f.ab[u_axis];
  f.ab_v = f.ab[v_axis];
  f.per_v = f.ab_v != 0.0 ? 1.0 / f.ab_v : 0.0;
  return f;
}

// The least exact distance from segments to the obstacle squares near them, line by line from the
// map's bit lines (the blocked bits are the obstacles plus inflation and blocked unknown cells not
// inflated, which layer() tells apart): rows for a flat segment, columns for a steep one, so that
// a straight run of a grid path crosses three lines, not one a cell. A square nearer than `reach`
// to the segment has its centre within that plus sqrt 2 / 2 of it (a square's points lie within
// sqrt 2 / 2 of its centre): per line, the cells whose centres lie within that reach of the part
// of the segment in reach of the line. The result is the least distance measured, never the
// bound (which only narrows the bands).
class ClearanceScan {
 public:
  ClearanceScan(const GridMap& map, double bound) : map_(map), bound_(bound), obstacle_(map) {}

  double best() const { return best_; }  // cells; +inf until something was measured

  // Lowers best() to the segment's distance to an obstacle square, where that is lower.
  void measure(const Point2& a, const Point2& b) {
    const ClearanceScanFrame f = clearance_scan_frame(map_, a, b);
    // Lines whose centres (v + 1/2) lie within reach of the segment's span across them.
    const double low_v = std::min(f.a_v, f.a_v + f.ab_v) - reach();
    const double high_v = std::max(f.a_v, f.a_v + f.ab_v) + reach();
    const int32_t v0 =
        static_cast<int32_t>(std::clamp(std::ceil(low_v - 0.5), 0.0, f.line_count - 1.0));
    const int32_t v1 =
        static_cast<int32_t>(std::clamp(std::floor(high_v - 0.5), -1.0, f.line_count - 1.0));
    // Most of a band in open space holds no blocked cell: a block of lines whose cells in reach
    // are all free is passed over with a word or two a line, without the line's arithmetic.
    for (int32_t first = v0; first <= v1; first += kBlockLines) {
      const int32_t last = std::min(v1, first + kBlockLines - 1);
      if (block_is_free(f, first, last)) continue;
      for (int32_t v = first; v <= last; ++v) measure_line(f, v);
    }
  }

 private:
  static constexpr double kHalfDiagonal = kSqrt2 / 2;
  static constexpr int32_t kBlockLines = 8;

  double reach() const { return std::min(best_, bound_) + kHalfDiagonal + 1e-9; }  // cells

  Cell cell_at(const ClearanceScanFrame& f, int32_t v, int32_t u) const {
    return f.columns ? Cell{v, u} : Cell{u, v};
  }

  std::optional<std::pair<double, double>> line_span(const ClearanceScanFrame& f, int32_t v,
                                                     double r) const;
  bool block_is_free(const ClearanceScanFrame& f, int32_t first, int32_t last) const;
  void measure_line(const ClearanceScanFrame& f, int32_t v);
  void consider(const ClearanceScanFrame& f, int32_t v, int32_t u);

  const GridMap& map_;
  double bound_;  // cells: an upper bound of the result
  BlockedCellIsObstacle obstacle_;
  double best_ = std::numeric_limits<double>::infinity();
};

// The cells of line v (as u, unclipped to the map: [first, last]) whose centres lie within r of
// the part of the segment within r of the line's centres across the lines; nullopt when no part
// is. As v moves one way both ends move one way (that part of a straight segment slides along
// it), and the cells only grow with r.
std::optional<std::pair<double, double>> ClearanceScan::line_span(const ClearanceScanFrame& f,
                                                                  int32_t v, double r) const {
  const double centre_v = v + 0.5;
  // The part of the segment within r of this line's centres across the lines, as t.
  double t0 = 0.0, t1 = 1.0;
  if (f.ab_v != 0.0) {
    t0 = (centre_v - r - f.a_v) * f.per_v;
    t1 = (centre_v + r - f.a_v) * f.per_v;
    if (t0 > t1) std::swap(t0, t1);
    t0 = std::max(t0, 0.0);
    t1 = std::min(t1, 1.0);
    if (t0 > t1) return std::nullopt;
  } else if (std::abs(f.a_v - centre_v) > r) {
    return std::nullopt;
  }
  const double ua = f.a_u + t0 * f.ab_u, ub = f.a_u + t1 * f.ab_u;
  return std::pair{std::ceil(std::min(ua, ub) - r - 0.5), std::floor(std::max(ua, ub) + r - 0.5)};
}

// Whether no cell that measure_line could look at on lines first..last is blocked: every line's
// cells lie within the first and the last line's together (line_span moves one way; the reach
// only shrinks as distances are measured). Unsure (false) where either end line has none.
bool ClearanceScan::block_is_free(const ClearanceScanFrame& f, int32_t first, int32_t last) const {
  const double r = reach();
  const auto first_span = line_span(f, first, r);
  const auto last_span = line_span(f, last, r);
  if (!first_span || !last_span) return false;
  const double low = std::max(std::min(first_span->first, last_span->first), 0.0);
  const double high = std::min(std::max(first_span->second, last_span->second), f.last_u);
  if (low > high) return true;  // beside the map
  const int32_t u0 = static_cast<int32_t>(low), u1 = static_cast<int32_t>(high);
  for (int32_t v = first; v <= last; ++v)
    if (BlockedBits::span_blocked(f.bit_lines.line(v), u0, u1)) return false;
  return true;
}

// Line v of the band: the cells within reach of the part of the segment in reach of the line.
void ClearanceScan::measure_line(const ClearanceScanFrame& f, int32_t v) {
  const auto span = line_span(f, v, reach());
  if (!span) return;
  const auto [first, last] = *span;
  if (last < 0.0 || first > f.last_u) return;
  const int32_t u0 = static_cast<int32_t>(std::max(first, 0.0));
  const int32_t u1 = static_cast<int32_t>(std::min(last, f.last_u));
  // Most lines of a path's band hold no blocked cell at all: one or two words say so.
  const uint64_t* line = f.bit_lines.line(v);
  if (!BlockedBits::span_blocked(line, u0, u1)) return;
  const double centre_v = v + 0.5;
  // Along a line the distance from the segment to square u is convex in u (the distance
  // between two convex sets as one slides), least at u_near: the square the segment meets
  // on the line's centre, or, where it stays on one side of it, the square nearest its end
  // nearest the line (on or straight beside that end). So only the nearest obstacle on each
  // side of u_near can be the line's nearest.
  const double t_near = f.ab_v != 0.0 ? std::clamp((centre_v - f.a_v) * f.per_v, 0.0, 1.0) : 0.0;
  const int32_t u_near = static_cast<int32_t>(std::clamp(
      std::floor(f.a_u + t_near * f.ab_u), static_cast<double>(u0), static_cast<double>(u1)));
  const auto is_obstacle = [&](int32_t u) { return obstacle_(cell_at(f, v, u)); };
  if (const int32_t u = last_obstacle_in(line, u0, u_near, is_obstacle); u >= 0) consider(f, v, u);
  if (u_near < u1) {
    if (const int32_t u = first_obstacle_in(line, u_near + 1, u1, is_obstacle); u >= 0)
      consider(f, v, u);
  }
}

// The obstacle square of cell u of line v, measured when its centre lies within reach.
void ClearanceScan::consider(const ClearanceScanFrame& f, int32_t v, int32_t u) {
  const Cell c = cell_at(f, v, u);
  const Point2 centre(c.x + 0.5, c.y + 0.5);
  const double t = f.length_squared > 0.0
                       ? std::clamp((centre - f.a).dot(f.ab) / f.length_squared, 0.0, 1.0)
                       : 0.0;
  // No square is nearer to the segment than its centre less sqrt 2 / 2.
  const double within = reach();
  if ((f.a + t * f.ab - centre).squaredNorm() >= within * within) return;
  best_ = std::min(best_, segment_square_distance(f.a, f.b, c.x, c.y));
}

// Half a cell is as near as a straight run of a grid path gets to an obstacle square when it
// has line of sight without cutting a corner: it crosses only unblocked cells, and where it
// passes a cell corner both cells beside it are unblocked, so every blocked square lies at
// least half a cell across or beyond it.
constexpr double kStraightRunFloor = 0.5;  // cells

// The reach of the first scan without a bound from the distance field (cells): most grid paths
// pass within a cell or two of an obstacle, and a reach that finds none costs a few words a line.
constexpr double kFirstScanReachCells = 1.5;

// The clearance (cells) of a grid path that passes an obstacle side on, without a scan: when
// every segment of the path (collinear runs merged) is a straight run from cell centre to cell
// centre with line of sight that cuts no corner, none is nearer than kStraightRunFloor to an
// obstacle square, so a square measured at that distance or less from one of them is the least
// distance of all. Such a square is looked for where a run of cell centres comes half a cell
// from a square: beside an axis run (the bit lines on either side of its cells) and beside or
// beyond either end of any run. Most grid paths (a JPS path turns at the obstacles that force
// its jump points) pass one within a few words of bits. The runs are fed one by one; no answer
// (the scan measures then) when one is not such a run or no such square lies beside them.
class ClearanceBesideObstacle {
 public:
  explicit ClearanceBesideObstacle(const GridMap& map) : map_(map), obstacle_(map) {}

  // The run of cell centres from `from` to `to` (in the map, along an axis or a diagonal, or one
  // cell); false, and no answer, when it has no line of sight without cutting a corner.
  bool add_run(const Cell& from, const Cell& to) {
    if (!line_of_sight(map_, from, to, CornerPolicy::kNever)) return false;
    if (touching_ > kStraightRunFloor) look_beside(from, to);
    return true;
  }

  // The clearance of the runs fed, when they are all such runs and one passes an obstacle side on.
  std::optional<double> clearance() const {
    if (touching_ <= kStraightRunFloor) return touching_;
    return std::nullopt;
  }

 private:
  // From the bit rows, which the search has just read (the byte layers only where inflation or
  // blocked unknown cells may share the blocked bits).
  bool is_obstacle_cell(int32_t x, int32_t y) const {
    return map_.in_bounds(x, y) && rows_.blocked(y, x) && obstacle_({x, y});
  }

  void look_beside(const Cell& from, const Cell& to) {
    const Point2 a = cell_centre(from), b = cell_centre(to);
    const auto measure = [&](int32_t x, int32_t y) {
      touching_ = std::min(touching_, segment_square_distance(a, b, x, y));
    };
    // Beside or beyond the ends: the four side neighbours of each end cell.
    for (const Cell& end : {from, to}) {
      for (const auto& [dx, dy] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}})
        if (is_obstacle_cell(end.x + dx, end.y + dy)) measure(end.x + dx, end.y + dy);
      if (touching_ <= kStraightRunFloor) return;
    }
    if (from.x != to.x && from.y != to.y) return;  // a diagonal run's inner cells cut no corner
    // Beside an axis run: its cells' span on the bit lines either side of it (rows for a flat
    // run, columns for a steep one), a word or two each.
    const bool columns = from.x == to.x;
    const BlockedBits lines = columns ? map_.blocked_columns() : map_.blocked_rows();
    const int32_t v = columns ? from.x : from.y;
    const int32_t line_count = columns ? map_.width() : map_.height();
    const int32_t u0 = columns ? std::min(from.y, to.y) : std::min(from.x, to.x);
    const int32_t u1 = columns ? std::max(from.y, to.y) : std::max(from.x, to.x);
    for (const int32_t side : {v - 1, v + 1}) {
      if (side < 0 || side >= line_count) continue;
      const auto is_obstacle = [&](int32_t u) {
        return obstacle_(columns ? Cell{side, u} : Cell{u, side});
      };
      if (const int32_t u = first_obstacle_in(lines.line(side), u0, u1, is_obstacle); u >= 0) {
        columns ? measure(side, u) : measure(u, side);
        if (touching_ <= kStraightRunFloor) return;
      }
    }
  }

  const GridMap& map_;
  BlockedBits rows_ = map_.blocked_rows();
  BlockedCellIsObstacle obstacle_;
  double touching_ = std::numeric_limits<double>::infinity();  // cells: the least measured
};

// ClearanceBesideObstacle on the segments of `vertices` (collinear runs merged).
std::optional<double> clearance_beside_obstacle(const GridMap& map,
                                                const std::vector<Point2>& vertices) {
  if (vertices.size() < 2) return std::nullopt;
  ClearanceBesideObstacle beside(map);
  for (size_t i = 1; i < vertices.size(); ++i) {
    const auto run = straight_run_cells(map, vertices[i - 1], vertices[i]);
    if (!run || !beside.add_run(run->first, run->second)) return std::nullopt;
  }
  return beside.clearance();
}

// The least distance (cells) from the segments of `vertices` to the obstacle squares, exact when
// it is at most `bound`; above it (a distance measured within the bands, or +inf) otherwise: the
// scan measures only the squares within reach of min(bound, the least distance so far).
double scan_clearance(const GridMap& map, const std::vector<Point2>& vertices, double bound) {
  ClearanceScan scan(map, bound);
  const Point2& first = vertices.front();
  if (vertices.size() == 1 && std::isfinite(first.x()) && std::isfinite(first.y()))
    scan.measure(first, first);
  // Once a distance of kStraightRunFloor or less has been measured, straight runs with line of
  // sight cannot lower it and are not measured (a grid path touches a wall early and has
  // hundreds of runs); the result is the same.
  for (size_t i = 1; i < vertices.size(); ++i) {
    const Point2& a = vertices[i - 1];
    const Point2& b = vertices[i];
    if (!std::isfinite((b - a).norm())) continue;  // not a path a planner makes
    if (scan.best() <= kStraightRunFloor) {
      const auto run = straight_run_cells(map, a, b);
      if (run && line_of_sight(map, run->first, run->second, CornerPolicy::kNever)) continue;
    }
    scan.measure(a, b);
  }
  return scan.best();
}

// The farthest any point of the map's rectangle lies from a finite vertex (cells): a scan of that
// reach measures every obstacle square. -1 without a finite vertex.
double farthest_map_point(const GridMap& map, const std::vector<Point2>& vertices) {
  double farthest = -1.0;
  for (const Point2& v : vertices) {
    if (!std::isfinite(v.x()) || !std::isfinite(v.y())) continue;
    farthest =
        std::max(farthest, std::hypot(std::max(std::abs(v.x()), std::abs(v.x() - map.width())),
                                      std::max(std::abs(v.y()), std::abs(v.y() - map.height()))));
  }
  return farthest;
}

// clearance_beside_obstacle of the cells' centres, on a path of unit moves (each step to one of
// the 8 neighbours), found run by run without making the polyline; nullopt for any other path.
// Its runs are merge_collinear_runs': a unit step continues the run when it is the run's step.
std::optional<double> grid_path_clearance_beside_obstacle(const GridMap& map,
                                                          const std::vector<Cell>& cells) {
  if (cells.size() < 2) return std::nullopt;
  ClearanceBesideObstacle beside(map);
  size_t run_start = 0;  // the index of the run's first cell
  // The run's step; before the first, none a step can equal, so that the first step is checked.
  int32_t run_dx = 2, run_dy = 2;
  // Each run is checked and fed when the next begins, the last one after the loop.
  const auto end_run = [&](size_t last) { return beside.add_run(cells[run_start], cells[last]); };
  for (size_t i = 1; i < cells.size(); ++i) {
    const int32_t dx = cells[i].x - cells[i - 1].x, dy = cells[i].y - cells[i - 1].y;
    if (dx == run_dx && dy == run_dy) continue;
    if (dx < -1 || dx > 1 || dy < -1 || dy > 1 || (dx == 0 && dy == 0)) return std::nullopt;
    if (i > 1) {
      if (!end_run(i - 1)) return std::nullopt;
      run_start = i - 1;
    }
    run_dx = dx;
    run_dy = dy;
  }
  if (!end_run(cells.size() - 1)) return std::nullopt;
  return beside.clearance();
}

// path_clearance_cells on `vertices` (collinear runs merged), by scans of the bit lines.
double scanned_clearance(const GridMap& map, const std::vector<Point2>& vertices) {
  if (const double bound = clearance_upper_bound(map, vertices); std::isfinite(bound))
    return scan_clearance(map, vertices, bound);
  // Without a bound from the field: scans of growing reach, each narrow while it measures nothing
  // (a few words a line), until one measures a distance; that distance bounds the last scan.
  const double farthest = farthest_map_point(map, vertices);
  if (farthest < 0.0) return std::numeric_limits<double>::infinity();
  for (double bound = kFirstScanReachCells;; bound *= 4) {
    const double measured = scan_clearance(map, vertices, bound);
    if (measured <= bound || bound > farthest) return measured;
    if (std::isfinite(measured)) return scan_clearance(map, vertices, measured);
  }
}

}  // namespace

double path_clearance_cells(const GridMap& map, const std::vector<Point2>& polyline) {
  if (polyline.empty() || map.cell_count() == 0 || !map.has_obstacles())
    return std::numeric_limits<double>::infinity();
  const std::vector<Point2> vertices = merge_collinear_runs(polyline);
  if (const std::optional<double> beside = clearance_beside_obstacle(map, vertices)) return *beside;
  return scanned_clearance(map, vertices);
}

double grid_path_clearance_cells(const GridMap& map, const std::vector<Cell>& cells) {
  if (cells.empty() || map.cell_count() == 0 || !map.has_obstacles())
    return std::numeric_limits<double>::infinity();
  if (const std::optional<double> beside = grid_path_clearance_beside_obstacle(map, cells))
    return *beside;
  return scanned_clearance(map, merge_collinear_runs(cell_centres(cells)));
}

}  // namespace vnsba::core
