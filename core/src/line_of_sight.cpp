#include "vnsba/core/line_of_sight.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <type_traits>

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
// Two kinds of numbers, one walk. Between cell centres (the heuristic's and pruning's walks)
// coordinates are doubled into integers (a centre is 1 from each boundary of its cell, a cell 2
// wide): the products are exact (below 2^31 for maps of at most 2^28 cells), and the walk jumps
// the u boundaries that certainly lie before the next line boundary and tests only the last one
// or two. With q = floor(|du| / |dv|): the segment crosses line boundary k at the u offset
// (k + 1/2) |du| / |dv| from the start centre, u boundary i lies at offset i + 1/2, so the first
// line holds at least floor(q / 2) of them (the last at floor(q / 2) - 1/2, below the crossing)
// and every later line at least q - 1 (an open interval q or more long, also after a corner).
// For other points (continuous cell coordinates, as doubles) it steps the u boundaries one at a
// time, accumulating next_u exactly as the cell-by-cell traversal does, so every product, and so
// every decision, is that traversal's.

// The short spans below read the bit grids as bytes: cell i of a line is bit i % 8 of byte
// i / 8 of the line only when words are stored little-endian.
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "bit grids are read as bytes");

constexpr uint64_t kAllBits = ~uint64_t{0};
// Longest span (cells) that one unaligned 8-byte load covers from any starting cell: 64 bits
// minus up to 7 bits before the span's first cell in its byte.
constexpr int32_t kShortSpanCells = 57;

// Whether any of cells lo..hi (inclusive, 0 <= lo <= hi < line length) of a bit line is blocked.
inline bool span_blocked(const uint64_t* line, int32_t lo, int32_t hi) {
  const int32_t first = lo >> 6, last = hi >> 6;           // word indices
  const uint64_t from_lo = kAllBits << (lo & 63);          // bits lo % 64 .. 63
  const uint64_t up_to_hi = kAllBits >> (63 - (hi & 63));  // bits 0 .. hi % 64
  if (first == last) return (line[first] & from_lo & up_to_hi) != 0;
  if ((line[first] & from_lo) != 0) return true;
  for (int32_t w = first + 1; w < last; ++w)
    if (line[w] != 0) return true;
  return (line[last] & up_to_hi) != 0;
}

// The same for a span of at most kShortSpanCells cells, without a branch on the cells: one
// unaligned load of the 8 bytes from lo's byte on (past the end of a line they run into the next
// line or the grid's spare word, and bits past hi are shifted out).
inline bool short_span_blocked(const unsigned char* line, int32_t lo, int32_t hi) {
  uint64_t window;
  std::memcpy(&window, line + (lo >> 3), sizeof window);
  window >>= lo & 7;                         // cell lo is bit 0
  return (window << (63 - (hi - lo))) != 0;  // only bits 0 .. hi - lo remain
}

inline bool cell_blocked(const unsigned char* line, int32_t cell) {
  return ((line[cell >> 3] >> (cell & 7)) & 1) != 0;
}

// The walk's frame and numbers (see above).
template <class Number>
struct LineWalk {
  BlockedBits lines;              // rows (u = x) or columns (u = y)
  bool columns = false;           // lines are columns
  int32_t u = 0, v = 0;           // start cell
  int32_t end_u = 0, end_v = 0;   // end cell
  int su = 0, sv = 0;             // direction of travel along u and v (0: no extent)
  Number next_u{}, next_v{};      // from the start point to the first boundary ahead along u / v
  Number extent_u{}, extent_v{};  // |b - a| along u / v
  Number unit{};                  // a cell's width
};

// Whether any of cells lo..hi (lo <= hi) of a bit line is blocked, by the cheaper load.
inline bool line_span_blocked(const unsigned char* line, int32_t lo, int32_t hi) {
  return hi - lo < kShortSpanCells ? short_span_blocked(line, lo, hi)
                                   : span_blocked(reinterpret_cast<const uint64_t*>(line), lo, hi);
}

// The walk. `span_clear(line, v, lo, hi)` decides whether cells lo..hi of line v (its bits at
// `line`) may be passed; it sees every cell the traversal enters, once. The cells beside a corner
// are read from the bits and decided by kPolicy.
template <CornerPolicy kPolicy, class Number, class SpanClear>
bool walk_lines(const LineWalk<Number>& w, SpanClear&& span_clear) {
  const ptrdiff_t to_next_line =
      w.sv * static_cast<ptrdiff_t>(w.lines.words_per_line * sizeof(uint64_t));
  const unsigned char* line = reinterpret_cast<const unsigned char*>(w.lines.line(w.v));
  const int64_t line_crossings = std::abs(int64_t{w.end_v} - w.v);
  const int64_t u_crossings = std::abs(int64_t{w.end_u} - w.u);
  int64_t crossed_u = 0;         // u boundaries crossed so far
  Number boundary_u = w.next_u;  // to the next u boundary: next_u + crossed_u * unit
  Number boundary_v = w.next_v;  // to the next line boundary
  // Integers: u boundaries that certainly lie before the first line boundary, and between two
  // later ones (see above).
  int64_t sure_in_first_line = 0, sure_per_line = 0;
  if constexpr (std::is_integral_v<Number>) {
    if (w.extent_v > 0) {
      const int64_t q = w.extent_u / w.extent_v;
      sure_in_first_line = q / 2;
      sure_per_line = std::max<int64_t>(0, q - 1);
    }
  }
  int32_t entry = w.u;  // first cell of the current line's span
  int32_t v = w.v;
  for (int64_t k = 0; k < line_crossings; ++k) {
    if constexpr (std::is_integral_v<Number>) {
      const int64_t jump =
          std::min(k == 0 ? sure_in_first_line : sure_per_line, u_crossings - crossed_u);
      crossed_u += jump;
      boundary_u += jump * w.unit;
    }
    // The u boundaries the segment reaches before this line boundary.
    const Number line_boundary = boundary_v * w.extent_u;
    while (crossed_u < u_crossings && boundary_u * w.extent_v < line_boundary) {
      ++crossed_u;
      boundary_u += w.unit;
    }
    // Both at once (never once the end cell's u is reached): the corner.
    const bool corner = crossed_u < u_crossings && !(line_boundary < boundary_u * w.extent_v);
    const int32_t exit = w.u + w.su * static_cast<int32_t>(crossed_u);
    if (!span_clear(line, v, std::min(entry, exit), std::max(entry, exit))) return false;
    if (corner) {
      if constexpr (kPolicy != CornerPolicy::kAlways) {
        if (!detail::corner_passable(cell_blocked(line, exit + w.su),
                                     cell_blocked(line + to_next_line, exit), kPolicy)) {
          return false;
        }
      }
      ++crossed_u;
      boundary_u += w.unit;
    }
    entry = w.u + w.su * static_cast<int32_t>(crossed_u);
    line += to_next_line;
    v += w.sv;
    boundary_v += w.unit;
  }
  return span_clear(line, v, std::min(entry, w.end_u), std::max(entry, w.end_u));
}

template <class Number, class SpanClear>
bool walk_lines(const LineWalk<Number>& w, CornerPolicy policy, SpanClear&& span_clear) {
  switch (policy) {
    case CornerPolicy::kNever:
      return walk_lines<CornerPolicy::kNever>(w, span_clear);
    case CornerPolicy::kTouch:
      return walk_lines<CornerPolicy::kTouch>(w, span_clear);
    case CornerPolicy::kAlways:
      return walk_lines<CornerPolicy::kAlways>(w, span_clear);
  }
  return false;
}

// Line of sight by the bits alone.
inline bool span_free(const unsigned char* line, int32_t, int32_t lo, int32_t hi) {
  return !line_span_blocked(line, lo, hi);
}

// The frame between two cell centres in the map, on doubled integer coordinates.
LineWalk<int64_t> centre_walk(const GridMap& map, const Cell& a, const Cell& b) {
  const int32_t dx = b.x - a.x, dy = b.y - a.y;
  LineWalk<int64_t> w;
  w.columns = std::abs(dy) > std::abs(dx);
  w.lines = w.columns ? map.blocked_columns() : map.blocked_rows();
  const int32_t du = w.columns ? dy : dx, dv = w.columns ? dx : dy;
  w.u = w.columns ? a.y : a.x;
  w.v = w.columns ? a.x : a.y;
  w.end_u = w.u + du;
  w.end_v = w.v + dv;
  w.su = (du > 0) - (du < 0);
  w.sv = (dv > 0) - (dv < 0);
  w.next_u = 1;
  w.next_v = 1;
  w.extent_u = 2 * int64_t{std::abs(du)};
  w.extent_v = 2 * int64_t{std::abs(dv)};
  w.unit = 2;
  return w;
}

// The frame of the segment a -> b (continuous cell coordinates); nullopt when an end is not
// finite or lies outside the map (every cell of the traversal lies in the bounding box of the
// end cells, so checking the ends once keeps every read in the map).
std::optional<LineWalk<double>> point_walk(const GridMap& map, const Point2& a, const Point2& b) {
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
  LineWalk<double> w;
  w.columns = std::abs(dy) > std::abs(dx);
  w.lines = w.columns ? map.blocked_columns() : map.blocked_rows();
  const int u_axis = w.columns ? 1 : 0, v_axis = 1 - u_axis;
  const double du = w.columns ? dy : dx, dv = w.columns ? dx : dy;
  const double start_u = std::floor(a[u_axis]), start_v = std::floor(a[v_axis]);
  w.u = static_cast<int32_t>(start_u);
  w.v = static_cast<int32_t>(start_v);
  w.end_u = static_cast<int32_t>(std::floor(b[u_axis]));
  w.end_v = static_cast<int32_t>(std::floor(b[v_axis]));
  w.su = (du > 0) - (du < 0);
  w.sv = (dv > 0) - (dv < 0);
  // In cells, >= 0: exact for cell centres and dyadic coordinates; for other reals the walk is
  // exact up to the rounding of the products.
  w.next_u = w.su > 0 ? (start_u + 1 - a[u_axis]) : (a[u_axis] - start_u);
  w.next_v = w.sv > 0 ? (start_v + 1 - a[v_axis]) : (a[v_axis] - start_v);
  w.extent_u = std::abs(du);
  w.extent_v = std::abs(dv);
  w.unit = 1.0;
  return w;
}

}  // namespace

namespace detail {

bool centre_segment_clear(const GridMap& map, const Cell& a, const Cell& b, CornerPolicy policy) {
  return walk_lines(centre_walk(map, a, b), policy, span_free);
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
  return walk && walk_lines(*walk, policy, span_free);
}

std::optional<double> max_cost_along(const GridMap& map, const Point2& a, const Point2& b,
                                     CornerPolicy policy) {
  const auto walk = point_walk(map, a, b);
  if (!walk) return std::nullopt;
  const float* costs = map.cost_data();
  float highest = 0.0f;
  const bool columns = walk->columns;
  const bool clear =
      walk_lines(*walk, policy, [&](const unsigned char* line, int32_t v, int32_t lo, int32_t hi) {
        if (line_span_blocked(line, lo, hi)) return false;
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
