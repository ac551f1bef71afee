#include "vnsba/core/line_of_sight.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <utility>

namespace vnsba::core {

namespace {

// --- The one line-of-sight traversal: a supercover walk over the bit grids, line by line. ---
//
// The supercover traversal walks from the start cell to the end cell one step at a time: along x
// when the segment reaches the next x boundary first, along y when it reaches the next y
// boundary first, diagonally through the corner when both at once (then the two cells beside the
// corner count by policy). "First" compares the two boundaries' parameters cross-multiplied,
// next_x * |dy| against next_y * |dx|, where next_x / next_y is the distance from the start point
// to the boundary, growing by a cell per step.
//
// This walk takes the same steps, grouped by lines of cells: u runs along the lines of a bit grid
// (GridMap::BlockedBits), v across them (v = line index). The lines lie along the segment's major
// axis (rows for |dy| <= |dx|, u = x; columns otherwise, u = y), so a walk visits
// min(|dx|, |dy|) + 1 lines, and reads each line's span of cells by word masks instead of one
// cell at a time. Before the segment crosses into the next line it crosses every u boundary whose
// product is below that line boundary's; a tie is the corner. Swapping x and y swaps the two
// products, so the frame changes no decision.
//
// One walk, two ways of finding where the segment leaves each line. Between cell centres (the
// heuristic's and pruning's walks) the crossings are exact integers, a few additions per line
// (CentreCrossings). Between other points (continuous cell coordinates, as doubles) the walk
// tests the u boundaries one at a time, with the cell-by-cell traversal's very products and
// accumulations (PointCrossings), so every decision is that traversal's.

// The short spans below read the bit grids as bytes: cell i of a line is bit i % 8 of byte
// i / 8 of the line only when words are stored little-endian.
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "bit grids are read as bytes");

// Longest span (cells) that one unaligned 8-byte load covers from any starting cell: 64 bits
// minus up to 7 bits before the span's first cell in its byte.
constexpr int32_t kShortSpanCells = 57;

// BlockedBits::span_blocked for a span of at most kShortSpanCells cells, without a branch on the
// cells: one unaligned load of the 8 bytes from lo's byte on (past the end of a line they run into
// the next line or the grid's spare word, and bits past hi are shifted out).
inline bool short_span_blocked(const unsigned char* line, int32_t lo, int32_t hi) {
  uint64_t window;
  std::memcpy(&window, line + (lo >> 3), sizeof window);
  window >>= lo & 7;                         // cell lo is bit 0
  return (window << (63 - (hi - lo))) != 0;  // only bits 0 .. hi - lo remain
}

inline bool cell_blocked(const unsigned char* line, int32_t cell) {
  return ((line[cell >> 3] >> (cell & 7)) & 1) != 0;
}

// The walk's frame (see above): the lines, and the start and end cells in (u, v).
struct LineFrame {
  BlockedBits lines;             // rows (u = x) or columns (u = y)
  bool columns = false;          // lines are columns
  int32_t u = 0, v = 0;          // start cell
  int32_t end_u = 0, end_v = 0;  // end cell
  int su = 0, sv = 0;            // direction of travel along u and v (0: no extent)
};

// Where the segment leaves a line: the last cell it enters there, and whether it passes into the
// next line through the corner after that cell.
struct LineExit {
  int32_t cell;
  bool corner;
};

// Between two cell centres, u increasing (centre_walk orders the ends), n = |dv| >= 1 lines to
// cross: exact and division-free per line. The segment crosses line boundary k at
// c_k = u0 + 1/2 + (k + 1/2) du / n = floor(c_k) + rest_k / (2n), with 0 <= rest_k < 2n, both
// integers, starting from c_0 = u0 + (n + du) / (2n); from k to k + 1 the numerator grows by
// 2 du = (du / n) * 2n + 2 (du % n), so floor(c) grows by du / n and rest by 2 (du % n), with at
// most one carry. The cells of line k whose interiors the segment meets end at ceil(c_k) - 1;
// where c_k is an integer (rest_k == 0) the segment passes the corner at u = c_k into cell c_k
// of the next line. Coordinates are below 2^31, so 2n, rest and n + du fit in int64.
class CentreCrossings {
 public:
  CentreCrossings(int32_t u0, int64_t du, int64_t n)
      : two_n_(2 * n),
        floor_c_(u0 + static_cast<int32_t>((n + du) / (2 * n))),
        rest_((n + du) % (2 * n)),
        whole_step_(static_cast<int32_t>(du / n)),
        rest_step_(2 * (du % n)) {}

  // u only increases: each line's span runs from its entry to its exit.
  static constexpr bool kIncreasing = true;

  LineExit next() {
    const bool corner = rest_ == 0;
    const LineExit exit{floor_c_ - corner, corner};
    // The next crossing; the carry is data, not a branch (it follows the slope's digits).
    rest_ += rest_step_;
    const bool carry = rest_ >= two_n_;
    floor_c_ += whole_step_ + carry;
    rest_ -= carry ? two_n_ : 0;
    return exit;
  }

 private:
  int64_t two_n_;
  int32_t floor_c_;
  int64_t rest_;
  int32_t whole_step_;
  int64_t rest_step_;
};

// Between any two points (continuous cell coordinates, doubles): the cell-by-cell traversal's own
// test, u boundary by u boundary. The segment reaches the next u boundary before the next line
// boundary when next_u * |dv| < next_v * |du| (its parameters cross-multiplied), both distances
// from the start point growing by a cell per boundary passed, accumulated as that traversal
// accumulates them; equality is the corner (never once the end cell's u is reached).
class PointCrossings {
 public:
  PointCrossings(const LineFrame& f, double next_u, double next_v, double extent_u, double extent_v)
      : u0_(f.u),
        su_(f.su),
        u_crossings_(std::abs(int64_t{f.end_u} - f.u)),
        boundary_u_(next_u),
        boundary_v_(next_v),
        extent_u_(extent_u),
        extent_v_(extent_v) {}

  // u may run either way.
  static constexpr bool kIncreasing = false;

  LineExit next() {
    const double line_boundary = boundary_v_ * extent_u_;
    while (crossed_u_ < u_crossings_ && boundary_u_ * extent_v_ < line_boundary) {
      ++crossed_u_;
      boundary_u_ += 1.0;
    }
    const bool corner = crossed_u_ < u_crossings_ && !(line_boundary < boundary_u_ * extent_v_);
    const int32_t cell = u0_ + su_ * static_cast<int32_t>(crossed_u_);
    if (corner) {
      ++crossed_u_;
      boundary_u_ += 1.0;
    }
    boundary_v_ += 1.0;
    return {cell, corner};
  }

 private:
  int32_t u0_;
  int su_;
  int64_t u_crossings_;
  int64_t crossed_u_ = 0;
  double boundary_u_, boundary_v_, extent_u_, extent_v_;
};

// The walk, line by line. `span_clear(line, v, lo, hi)` decides whether cells lo..hi of line v
// (its bits at `line`) may be passed; it sees every cell the traversal enters, once. At a corner
// the two cells beside it (the next cell of this line, the same cell of the next line) are read
// from the bits and decided by kPolicy.
template <CornerPolicy kPolicy, class Crossings, class SpanClear>
bool walk_lines(const LineFrame& f, Crossings crossings, SpanClear&& span_clear) {
  const ptrdiff_t to_next_line =
      f.sv * static_cast<ptrdiff_t>(f.lines.words_per_line * sizeof(uint64_t));
  const unsigned char* line = reinterpret_cast<const unsigned char*>(f.lines.line(f.v));
  const unsigned char* const last_line = line + std::abs(int64_t{f.end_v} - f.v) * to_next_line;
  auto span = [&](int32_t v, int32_t entry, int32_t exit) {
    if constexpr (Crossings::kIncreasing) {
      return span_clear(line, v, entry, exit);
    } else {
      return span_clear(line, v, std::min(entry, exit), std::max(entry, exit));
    }
  };
  int32_t entry = f.u;  // first cell of the current line's span
  int32_t v = f.v;
  for (; line != last_line; line += to_next_line, v += f.sv) {
    const LineExit exit = crossings.next();
    if constexpr (kPolicy == CornerPolicy::kNever && Crossings::kIncreasing) {
      // Between centres (whose walks read blocked bits only), both cells beside a corner must be
      // free: they join the spans, this line's reaching the cell after the corner and the next
      // line's starting at the cell before it, with no branch.
      if (!span(v, entry, exit.cell + exit.corner)) return false;
      entry = exit.cell;
    } else {
      if (!span(v, entry, exit.cell)) return false;
      if constexpr (kPolicy != CornerPolicy::kAlways) {
        if (exit.corner &&
            !detail::corner_passable(cell_blocked(line, exit.cell + f.su),
                                     cell_blocked(line + to_next_line, exit.cell), kPolicy)) {
          return false;
        }
      }
      entry = exit.corner ? exit.cell + f.su : exit.cell;  // diagonally past the corner
    }
  }
  return span(v, entry, f.end_u);
}

template <class Crossings, class SpanClear>
bool walk_lines(const LineFrame& f, const Crossings& crossings, CornerPolicy policy,
                SpanClear&& span_clear) {
  switch (policy) {
    case CornerPolicy::kNever:
      return walk_lines<CornerPolicy::kNever>(f, crossings, span_clear);
    case CornerPolicy::kTouch:
      return walk_lines<CornerPolicy::kTouch>(f, crossings, span_clear);
    case CornerPolicy::kAlways:
      return walk_lines<CornerPolicy::kAlways>(f, crossings, span_clear);
  }
  return false;
}

// Whether cells lo..hi of a bit line are all free; kShortSpans: every span of the walk has at
// most kShortSpanCells cells, so one unaligned load reads it. A type, not a function pointer, so
// that the walk inlines it.
template <bool kShortSpans>
struct SpanFree {
  bool operator()(const unsigned char* line, int32_t, int32_t lo, int32_t hi) const {
    if constexpr (kShortSpans) {
      return !short_span_blocked(line, lo, hi);
    } else {
      return !BlockedBits::span_blocked(reinterpret_cast<const uint64_t*>(line), lo, hi);
    }
  }
};

// Whether every span of a walk fits kShortSpanCells: a line's span covers at most
// |du| / |dv| + 2 cells, and at most |du| + 2 where the segment crosses no more than one line
// boundary (|dv| < 1, in cells along the major and the minor axis).
bool spans_are_short(double major_extent, double minor_extent) {
  return major_extent < (kShortSpanCells - 2) * std::max(minor_extent, 1.0);
}

template <class Crossings>
bool line_of_sight_walk(const LineFrame& f, const Crossings& crossings, CornerPolicy policy,
                        bool short_spans) {
  return short_spans ? walk_lines(f, crossings, policy, SpanFree<true>{})
                     : walk_lines(f, crossings, policy, SpanFree<false>{});
}

// The frame between two cell centres in the map, ordered so that u increases (line of sight
// between centres is symmetric), with its crossings.
std::pair<LineFrame, CentreCrossings> centre_walk(const GridMap& map, Cell a, Cell b) {
  const bool columns = std::abs(b.y - a.y) > std::abs(b.x - a.x);
  if ((columns ? b.y - a.y : b.x - a.x) < 0) std::swap(a, b);
  LineFrame f;
  f.columns = columns;
  f.lines = columns ? map.blocked_columns() : map.blocked_rows();
  f.u = columns ? a.y : a.x;
  f.v = columns ? a.x : a.y;
  f.end_u = columns ? b.y : b.x;
  f.end_v = columns ? b.x : b.y;
  const int32_t du = f.end_u - f.u, dv = f.end_v - f.v;
  f.su = du > 0;
  f.sv = (dv > 0) - (dv < 0);
  const int64_t n = std::abs(int64_t{dv});
  // (n = 0: one line, no crossing to compute; 1 keeps the constructor's divisions defined.)
  return {f, CentreCrossings(f.u, du, n > 0 ? n : 1)};
}

// The frame of the segment a -> b (continuous cell coordinates) with its crossings; nullopt when
// an end is not finite or lies outside the map (every cell of the traversal lies in the bounding
// box of the end cells, so checking the ends once keeps every read in the map).
std::optional<std::pair<LineFrame, PointCrossings>> point_walk(const GridMap& map, const Point2& a,
                                                               const Point2& b) {
  if (!std::isfinite(a.x()) || !std::isfinite(a.y()) || !std::isfinite(b.x()) ||
      !std::isfinite(b.y())) {
    return std::nullopt;
  }
  const double fax = std::floor(a.x()), fay = std::floor(a.y());
  const double fbx = std::floor(b.x()), fby = std::floor(b.y());
  if (fax < 0 || fay < 0 || fbx < 0 || fby < 0 || fax >= map.width() || fbx >= map.width() ||
      fay >= map.height() || fby >= map.height()) {
    return std::nullopt;
  }
  const double dx = b.x() - a.x(), dy = b.y() - a.y();
  LineFrame f;
  f.columns = std::abs(dy) > std::abs(dx);
  f.lines = f.columns ? map.blocked_columns() : map.blocked_rows();
  const int u_axis = f.columns ? 1 : 0, v_axis = 1 - u_axis;
  const double du = f.columns ? dy : dx, dv = f.columns ? dx : dy;
  const double start_u = std::floor(a[u_axis]), start_v = std::floor(a[v_axis]);
  f.u = static_cast<int32_t>(start_u);
  f.v = static_cast<int32_t>(start_v);
  f.end_u = static_cast<int32_t>(std::floor(b[u_axis]));
  f.end_v = static_cast<int32_t>(std::floor(b[v_axis]));
  f.su = (du > 0) - (du < 0);
  f.sv = (dv > 0) - (dv < 0);
  // From a to the first boundary ahead, in cells (>= 0): exact for cell centres and dyadic
  // coordinates; for other reals the walk is exact up to the rounding of the products.
  const double next_u = f.su > 0 ? (start_u + 1 - a[u_axis]) : (a[u_axis] - start_u);
  const double next_v = f.sv > 0 ? (start_v + 1 - a[v_axis]) : (a[v_axis] - start_v);
  return std::make_pair(f, PointCrossings(f, next_u, next_v, std::abs(du), std::abs(dv)));
}

}  // namespace

namespace detail {

bool centre_segment_clear(const GridMap& map, const Cell& a, const Cell& b, CornerPolicy policy) {
  const auto [frame, crossings] = centre_walk(map, a, b);
  return line_of_sight_walk(
      frame, crossings, policy,
      spans_are_short(frame.end_u - frame.u, std::abs(frame.end_v - frame.v)));
}

}  // namespace detail

std::string_view to_string(CornerPolicy policy) {
  switch (policy) {
    case CornerPolicy::kNever:
      return "never";
    case CornerPolicy::kTouch:
      return "touch";
    case CornerPolicy::kAlways:
      return "always";
  }
  return "never";
}

std::optional<CornerPolicy> corner_policy_from_string(std::string_view name) {
  if (name == "never") return CornerPolicy::kNever;
  if (name == "touch") return CornerPolicy::kTouch;
  if (name == "always") return CornerPolicy::kAlways;
  return std::nullopt;
}

bool line_of_sight(const GridMap& map, const Point2& a, const Point2& b, CornerPolicy policy) {
  const auto walk = point_walk(map, a, b);
  const double dx = std::abs(b.x() - a.x()), dy = std::abs(b.y() - a.y());
  return walk && line_of_sight_walk(walk->first, walk->second, policy,
                                    spans_are_short(std::max(dx, dy), std::min(dx, dy)));
}

std::optional<double> max_cost_along(const GridMap& map, const Point2& a, const Point2& b,
                                     CornerPolicy policy) {
  const auto walk = point_walk(map, a, b);
  if (!walk) return std::nullopt;
  const float* costs = map.cost_data();
  float highest = 0.0f;
  const bool columns = walk->first.columns;
  const bool clear = walk_lines(
      walk->first, walk->second, policy,
      [&](const unsigned char* line, int32_t v, int32_t lo, int32_t hi) {
        if (BlockedBits::span_blocked(reinterpret_cast<const uint64_t*>(line), lo, hi))
          return false;
        if (costs != nullptr)
          for (int32_t u = lo; u <= hi; ++u)
            highest =
                std::max(highest, costs[columns ? map.padded_index(v, u) : map.padded_index(u, v)]);
        return true;
      });
  if (!clear) return std::nullopt;
  return highest;
}

}  // namespace vnsba::core
