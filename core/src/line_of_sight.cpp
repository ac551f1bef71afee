#include "vnsba/core/line_of_sight.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <cstring>

namespace vnsba::core {

namespace {

// --- Line of sight between cell centres, one line of cells at a time. ---
//
// Frame, in cells: u runs along the lines of a bit grid (GridMap::BlockedBits), v across them
// (v = line index). A shallow segment (|dy| <= |dx|) walks rows (u = x, v = y), a steep one
// columns (u = y, v = x), so that the walk visits min(|dx|, |dy|) + 1 lines and reads each
// line's cells along its words. Transposing maps the two cells beside a corner onto each other,
// so the corner policies mean the same in both frames. Line of sight is symmetric, so the
// endpoints are ordered to make du = u1 - u0 >= 0; then n = |dv| <= du. A segment going to -v
// is the mirror image, about line v0, of one going to +v (line v0 - k in place of v0 + k); the
// mirror maps cells to cells and corners to corners, so the walk below is derived for dv = +n
// and only the step from one line to the next changes sign.
//
// The segment runs from centre (u0 + 1/2, v0 + 1/2) to centre (u0 + du + 1/2, v0 + n + 1/2).
// It crosses the boundary between walk line k and line k+1 (k = 0 .. n-1) at
//   c_k = u0 + 1/2 + (k + 1/2) * du / n  =  u0 + (n + (2k+1) * du) / (2n),
// and inside line k it covers u in [c_(k-1), c_k], taking c_(-1) = u0 + 1/2 and
// c_n = u0 + du + 1/2 (the centres). Each of these intervals is at least half a cell long
// (du / n >= 1 in the middle lines, du / (2n) >= 1/2 in the first and the last).
//
// Cells of line k whose open interior the segment meets: for u strictly inside (c_(k-1), c_k)
// the segment is strictly between the line's two boundaries, so cell j counts iff its open
// interval (j, j+1) meets (c_(k-1), c_k):
//   floor(c_(k-1)) <= j <= ceil(c_k) - 1                              (open span)
// Where c_k is an integer X the segment passes exactly through a lattice corner, from cell X-1
// of line k to cell X of line k+1; the two cells beside that corner are cell X of line k and
// cell X-1 of line k+1, precisely the two cells the open spans stop short of. So
//   ceil(c_(k-1)) - 1 <= j <= floor(c_k)                              (closed span)
// is the open span plus those side cells (for a non-integer c, floor(c) = ceil(c) - 1; the
// centres at the two ends are never integers, so the first line starts at u0 and the last ends
// at u0 + du either way). Policies:
//   always: open spans all free;
//   never:  closed spans all free (every side cell of every corner free);
//   touch:  open spans all free and, at each corner, at least one of its two side cells free.
// (c_k is an integer iff 2n divides n + (2k+1) du; with g = gcd(du, n) that happens only when
// du/g and n/g are both odd, e.g. slopes 1, 1/3, 3/5, and then at every (n/g)-th boundary.)
//
// Exact and division-free per line: c_k = floor(c_k) + rest_k / (2n) with 0 <= rest_k < 2n,
// both integers, starting from floor(c_0) = u0 + (n + du) / (2n) and rest_0 = (n + du) % (2n).
// From k to k+1 the numerator grows by 2 du = (du / n) * 2n + 2 (du % n), so floor(c) grows by
// du / n and rest by 2 (du % n) < 2n, with at most one carry. c_k is an integer iff
// rest_k == 0, and then ceil(c_k) - 1 = floor(c_k) - 1; otherwise ceil(c_k) - 1 = floor(c_k).
// Coordinates are below 2^31, so 2n, rest and the first numerator n + du fit in int64.

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

// The walk derived above, for n = |dv| >= 1 and du >= n. kShortSpans: every span fits
// kShortSpanCells, which holds when du / n <= kShortSpanCells - 2 (a span covers an interval of
// at most du / n cells' length, so at most floor(du / n) + 2 cells).
template <CornerPolicy kPolicy, bool kShortSpans>
bool walk_lines_clear(const BlockedBits& lines, int32_t u0, int32_t v0, int32_t du, int32_t dv) {
  const int64_t n = dv > 0 ? dv : -int64_t{dv};
  const ptrdiff_t to_next_line =
      (dv > 0 ? 1 : -1) * static_cast<ptrdiff_t>(lines.words_per_line * sizeof(uint64_t));
  const unsigned char* line = reinterpret_cast<const unsigned char*>(lines.line(v0));
  const unsigned char* const last_line = line + n * to_next_line;
  auto blocked = [](const unsigned char* bytes, int32_t lo, int32_t hi) {
    if constexpr (kShortSpans) {
      return short_span_blocked(bytes, lo, hi);
    } else {
      return span_blocked(reinterpret_cast<const uint64_t*>(bytes), lo, hi);
    }
  };
  const int64_t two_n = 2 * n;
  const int64_t first = n + du;                                // 2n * (c_0 - u0)
  int32_t floor_c = u0 + static_cast<int32_t>(first / two_n);  // floor(c_k)
  int64_t rest = first % two_n;                                // 2n * (c_k - floor(c_k))
  const int32_t whole_step = static_cast<int32_t>(du / n);
  const int64_t rest_step = 2 * (du % n);
  int32_t lo = u0;  // first cell of the current line's span
  for (; line != last_line; line += to_next_line) {
    const bool corner = rest == 0;
    const int32_t hi = kPolicy == CornerPolicy::kNever ? floor_c : floor_c - corner;
    if (blocked(line, lo, hi)) return false;
    if (kPolicy == CornerPolicy::kTouch && corner && cell_blocked(line, floor_c) &&
        cell_blocked(line + to_next_line, floor_c - 1)) {
      return false;
    }
    lo = kPolicy == CornerPolicy::kNever ? floor_c - corner : floor_c;
    // Next crossing; the carry is data, not a branch (it follows the slope's digits).
    rest += rest_step;
    const bool carry = rest >= two_n;
    floor_c += whole_step + carry;
    rest -= carry ? two_n : 0;
  }
  return !blocked(line, lo, u0 + du);
}

template <CornerPolicy kPolicy>
bool walk_clear(const BlockedBits& lines, int32_t u0, int32_t v0, int32_t du, int32_t dv) {
  if (dv == 0) return !span_blocked(lines.line(v0), u0, u0 + du);
  const int64_t n = dv > 0 ? dv : -int64_t{dv};
  // du / n <= kShortSpanCells - 2, without a division.
  return du < (kShortSpanCells - 1) * n ? walk_lines_clear<kPolicy, true>(lines, u0, v0, du, dv)
                                        : walk_lines_clear<kPolicy, false>(lines, u0, v0, du, dv);
}

}  // namespace

namespace detail {

bool centre_segment_clear(const GridMap& map, const Cell& a, const Cell& b, CornerPolicy policy) {
  const int32_t dx = b.x - a.x, dy = b.y - a.y;
  const bool steep = std::abs(dy) > std::abs(dx);
  const BlockedBits lines = steep ? map.blocked_columns() : map.blocked_rows();
  int32_t u0 = steep ? a.y : a.x, v0 = steep ? a.x : a.y;
  int32_t du = steep ? dy : dx, dv = steep ? dx : dy;
  if (du < 0) {  // walk from b instead
    u0 += du;
    v0 += dv;
    du = -du;
    dv = -dv;
  }
  switch (policy) {
    case CornerPolicy::kNever:
      return walk_clear<CornerPolicy::kNever>(lines, u0, v0, du, dv);
    case CornerPolicy::kTouch:
      return walk_clear<CornerPolicy::kTouch>(lines, u0, v0, du, dv);
    case CornerPolicy::kAlways:
      return walk_clear<CornerPolicy::kAlways>(lines, u0, v0, du, dv);
  }
  return false;
}

bool line_of_sight_centres_scalar(const GridMap& map, const Cell& a, const Cell& b,
                                  CornerPolicy policy) {
  if (!map.in_bounds(a) || !map.in_bounds(b)) return false;
  const uint32_t at = map.padded_index(a);
  if (map.blocked_data()[at]) return false;
  const int32_t dx = b.x - a.x, dy = b.y - a.y;
  // Doubled coordinates: a centre is 1 from each boundary of its cell, a cell is 2 wide.
  const uint8_t* blocked = map.blocked_data();
  return traverse_supercover<int64_t>(blocked, map.stride(), at, a.x, a.y, b.x, b.y, 1, 1,
                                      2 * int64_t{std::abs(dx)}, 2 * int64_t{std::abs(dy)}, 2,
                                      dx > 0 ? 1 : -1, dy > 0 ? 1 : -1, policy,
                                      [blocked](uint32_t cell) { return blocked[cell] == 0; });
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

namespace {

// The supercover traversal of the segment a -> b (continuous cell coordinates), calling
// enter(padded index) for the start cell and every cell entered after it; false when an
// endpoint is outside the map or not finite, when a corner is not passable, or when enter
// returns false.
template <class Enter>
bool walk_segment(const GridMap& map, const Point2& a, const Point2& b, CornerPolicy policy,
                  Enter&& enter) {
  if (!std::isfinite(a.x()) || !std::isfinite(a.y()) || !std::isfinite(b.x()) ||
      !std::isfinite(b.y())) {
    return false;
  }
  const double fax = std::floor(a.x()), fay = std::floor(a.y());
  const double fbx = std::floor(b.x()), fby = std::floor(b.y());
  // Every cell of the traversal lies in the bounding box of the end cells, so checking the ends
  // against the map once makes the unchecked padded lookups below safe.
  if (fax < 0 || fay < 0 || fbx < 0 || fby < 0 || fax >= map.width() || fbx >= map.width() ||
      fay >= map.height() || fby >= map.height()) {
    return false;
  }
  const int32_t cx = static_cast<int32_t>(fax), cy = static_cast<int32_t>(fay);
  const uint32_t at = map.padded_index(cx, cy);
  if (!enter(at)) return false;
  const double dx = b.x() - a.x(), dy = b.y() - a.y();
  const int sx = (dx > 0) - (dx < 0), sy = (dy > 0) - (dy < 0);
  // Distance from a to the next cell boundary along each axis (in cells, >= 0). Products of
  // these are exact for cell centres and dyadic coordinates; for arbitrary reals the traversal
  // is exact up to the rounding of those products.
  const double next_x = sx > 0 ? (cx + 1 - a.x()) : (a.x() - cx);
  const double next_y = sy > 0 ? (cy + 1 - a.y()) : (a.y() - cy);
  return detail::traverse_supercover<double>(map.blocked_data(), map.stride(), at, cx, cy,
                                             static_cast<int32_t>(fbx), static_cast<int32_t>(fby),
                                             next_x, next_y, std::abs(dx), std::abs(dy), 1.0, sx,
                                             sy, policy, enter);
}

}  // namespace

bool line_of_sight(const GridMap& map, const Point2& a, const Point2& b, CornerPolicy policy) {
  const uint8_t* blocked = map.blocked_data();
  return walk_segment(map, a, b, policy, [blocked](uint32_t cell) { return blocked[cell] == 0; });
}

std::optional<double> max_cost_along(const GridMap& map, const Point2& a, const Point2& b,
                                     CornerPolicy policy) {
  const uint8_t* blocked = map.blocked_data();
  const float* costs = map.cost_data();
  float highest = 0.0f;
  const bool clear = walk_segment(map, a, b, policy, [&](uint32_t cell) {
    if (blocked[cell] != 0) return false;
    if (costs != nullptr) highest = std::max(highest, costs[cell]);
    return true;
  });
  if (!clear) return std::nullopt;
  return highest;
}

}  // namespace vnsba::core
