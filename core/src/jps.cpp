#include "jps.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "vnsba/core/heuristics.hpp"
#include "vnsba/core/neighborhood.hpp"

namespace vnsba::core::detail {

namespace {

// ---------------------------------------------------------------------------------------------
// Straight scans over bit lines (a row of blocked_rows() or a column of blocked_columns()).
//
// A straight jump along a line stops at the first cell p (reached through free cells) that is
// blocked or has a forced neighbour on either side line: the side cell at p is free while the
// side cell one step back (p - 1 moving forward, p + 1 moving backward) is blocked. Without
// corner cutting that side cell can then only be reached through p at no more cost (Harabor &
// Grastien 2014). A scan returns p, the first such cell; p is a jump point when it is free. The
// goal is checked by the caller (it lies on few lines).
//
// Scans read 8 bytes of each of the three lines at a time, from any byte (a window of 64 cells
// starting at a multiple of 8 cells), and decide 56 cells per window: with the scan's current
// cell shifted to bit 0 (forward) or bit 63 (backward), the next 56 cells and the cell one step
// back from each are all inside the window, so no bit carries from one window to the next. Past
// the end of a line a window reads into the next line or the grid's spare word (BlockedBits),
// never past the grid; backward windows start at the line's first byte at the lowest.
constexpr int32_t kWindowCells = 56;
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "bit lines are read as bytes");

[[gnu::always_inline]] inline uint64_t load_window(const uint64_t* line, int32_t byte) {
  uint64_t window;
  std::memcpy(&window, reinterpret_cast<const unsigned char*>(line) + byte, sizeof window);
  return window;
}

// The window of `line` for a scan from cell `from` towards higher positions (kStep = 1: bit j is
// cell from + j) or lower ones (kStep = -1: bit 63 - j is cell from - j); j = 1 .. 56 are decided
// (kDecided), j = 1 is the next cell (kNext).
template <int kStep>
[[gnu::always_inline]] inline uint64_t window_at(const uint64_t* line, int32_t from) {
  if constexpr (kStep > 0) {
    return load_window(line, from >> 3) >> (from & 7);
  } else {
    const int32_t byte = std::max((from >> 3) - 7, 0);
    return load_window(line, byte) << (63 - (from - 8 * byte));  // from - 8 * byte <= 63
  }
}
template <int kStep>
constexpr uint64_t kDecided = kStep > 0 ? ((uint64_t{1} << (kWindowCells + 1)) - 1) & ~uint64_t{1}
                                        : (~uint64_t{0} >> 1) & ~((uint64_t{1} << 7) - 1);
template <int kStep>
constexpr uint64_t kNext = kStep > 0 ? uint64_t{2} : uint64_t{1} << 62;

// The cell just past the end of the line (`length` forward, -1 backward) as a bit of the window
// from `from`, when it is among the decided cells (it counts as blocked); else 0. Backward, the
// bits below it are zeros shifted in (the window starts at the line's first byte).
template <int kStep>
[[gnu::always_inline]] inline uint64_t line_end(int32_t from, int32_t length) {
  if constexpr (kStep > 0) {
    const int32_t end = length - from;  // >= 1
    return end <= kWindowCells ? uint64_t{1} << end : 0;
  } else {
    return from < kWindowCells ? uint64_t{1} << (62 - from) : 0;
  }
}

// Cells of a side line's window that force a neighbour: free there, blocked one cell back.
template <int kStep>
[[gnu::always_inline]] inline uint64_t forced(uint64_t side) {
  return kStep > 0 ? ~side & (side << 1) : ~side & (side >> 1);
}

// How many cells after the window's own cell its first decided stop is (stop != 0).
template <int kStep>
[[gnu::always_inline]] inline int32_t first_stop(uint64_t stop) {
  return kStep > 0 ? __builtin_ctzll(stop) : __builtin_clzll(stop);
}

// The first stop after `from` on a line of `length` cells in direction kStep: the end of the line
// (`length` or -1) when nothing stops the scan before. `kSides` side lines are in the map, given
// first (a line outside the map is all blocked and never forces a neighbour).
template <int kStep, int kSides>
[[gnu::always_inline]] inline int32_t scan_line(const uint64_t* line, const uint64_t* side_a,
                                                const uint64_t* side_b, int32_t from,
                                                int32_t length) {
  for (int32_t at = from;; at += kStep * kWindowCells) {
    uint64_t stop = window_at<kStep>(line, at) | line_end<kStep>(at, length);
    if constexpr (kSides >= 1) stop |= forced<kStep>(window_at<kStep>(side_a, at));
    if constexpr (kSides >= 2) stop |= forced<kStep>(window_at<kStep>(side_b, at));
    stop &= kDecided<kStep>;
    if (stop != 0) return at + kStep * first_stop<kStep>(stop);
  }
}

// A scan from `from` along `line` (`length` cells) in direction kStep, with the side lines
// `words` before and after it where they are in the map.
template <int kStep>
[[gnu::always_inline]] inline int32_t scan(const uint64_t* line, size_t words, bool before_in_map,
                                           bool after_in_map, int32_t from, int32_t length) {
  if (before_in_map && after_in_map) {
    return scan_line<kStep, 2>(line, line - words, line + words, from, length);
  }
  if (before_in_map) return scan_line<kStep, 1>(line, line - words, nullptr, from, length);
  if (after_in_map) return scan_line<kStep, 1>(line, line + words, nullptr, from, length);
  return scan_line<kStep, 0>(line, nullptr, nullptr, from, length);
}

// The first stop of a straight jump from `from` with both side lines in the map, given the
// stop bits of its first window (`stop`: the line's own bits `own` and the forced cells, undecided
// bits included): returns its position and sets `*jump_point` when that cell is free. A stop at
// or past the end of the line (its bits there are no cells of the line) ends the jump at the end
// of the line; a window without a stop reads on.
template <int kStep>
[[gnu::always_inline]] inline int32_t first_stop_from(uint64_t stop, uint64_t own,
                                                      const uint64_t* line, const uint64_t* side_a,
                                                      const uint64_t* side_b, int32_t from,
                                                      int32_t length, bool* jump_point) {
  stop &= kDecided<kStep>;
  if (stop != 0) {
    const int32_t j = first_stop<kStep>(stop);
    const int32_t p = from + kStep * j;
    if (kStep > 0 ? p >= length : p < 0) {
      *jump_point = false;
      return kStep > 0 ? length : -1;
    }
    *jump_point = ((own >> (kStep > 0 ? j : 63 - j)) & 1) == 0;
    return p;
  }
  // No stop among the 56 cells: either the line ended among them (past its end the bits are no
  // stops, before its start zeros), or the jump reads on.
  if (kStep > 0 ? length - from <= kWindowCells : from < kWindowCells) {
    *jump_point = false;
    return kStep > 0 ? length : -1;
  }
  const int32_t p = scan_line<kStep, 2>(line, side_a, side_b, from + kStep * kWindowCells, length);
  *jump_point = (kStep > 0 ? p < length : p >= 0) && ((line[p >> 6] >> (p & 63)) & 1) == 0;
  return p;
}

// Whether `v` lies after `from` up to `stop` inclusive, in the direction kStep.
template <int kStep>
inline bool reached(int32_t v, int32_t from, int32_t stop) {
  return kStep > 0 ? v > from && v <= stop : v < from && v >= stop;
}

// Cost of a jump of (dx, dy) cells made of min(|dx|, |dy|) diagonal steps and the rest straight,
// in the step costs every search sums (exact multiples of 2^-26 cells, so equal paths tie).
inline double jump_cost(int32_t dx, int32_t dy) {
  const int32_t ax = std::abs(dx), ay = std::abs(dy);
  const int32_t diagonal = std::min(ax, ay);
  return diagonal * kStepCostDiagonal + (std::max(ax, ay) - diagonal) * kStepCostStraight;
}

inline int sign_of(int32_t v) {
  return (v > 0) - (v < 0);
}

// ---------------------------------------------------------------------------------------------
// The search.
//
// Successors of a jump point n by the direction it was reached in (from its parent):
// - the start: the four straight jumps and the four diagonal ones;
// - reached straight, e.g. east: the east jump, and for each side where the neighbour is forced
//   (north: (x, y+1) free, (x-1, y+1) blocked) the straight jump that way and the diagonal
//   between the two (north-east);
// - reached diagonally (a walk's deferred cell, see below, or the goal): both straight
//   components and the diagonal.
// A diagonal jump walks its diagonal until the next step is not allowed (its cell or a side cell
// blocked). Without corner cutting a diagonal step forces no neighbour, so only the two straight
// jumps it launches at every cell can stop it. Instead of stopping at the first cell where they
// find something (a jump point of the 2011 paper), the walk goes on and the straight jumps' ends
// become successors of n directly (2014 paper); only a long walk that has found something and
// leads away from the goal stops at such a cell, which becomes a successor itself. So the path
// between a jump point and its parent is always diagonal steps first, then straight ones
// (trace_path), the exact cells the jumps scanned, and the parent tells the direction of
// arrival: straight when |dx| != |dy|, diagonal otherwise.
class JumpPointSearch {
 public:
  JumpPointSearch(const GridMap& map, SparseSearchSpace& space, const Cell& goal,
                  PlanningBudget& budget)
      : map_(map),
        space_(space),
        budget_(budget),
        blocked_(map.blocked_data()),
        stride_(map.stride()),
        width_(map.width()),
        height_(map.height()),
        row_words_(map.blocked_rows().words_per_line),
        column_words_(map.blocked_columns().words_per_line),
        rows_(map.blocked_rows().words),
        columns_(map.blocked_columns().words),
        goal_(goal) {}

  // Expands `node` (at `cell`, its record `record`): adds its successors, or stops at the goal
  // (goal_reached()).
  void expand(uint32_t record, uint32_t node, const Cell& cell) {
    node_ = node;
    cell_ = cell;
    g_ = space_.g_of(record);
    const uint32_t parent = space_.parent_of(record);
    if (parent == SparseSearchSpace::kNoParent) {
      jump_straight<1, 0>() && jump_straight<-1, 0>() && jump_straight<0, 1>() &&
          jump_straight<0, -1>() && jump_diagonal<1, 1>() && jump_diagonal<-1, 1>() &&
          jump_diagonal<1, -1>() && jump_diagonal<-1, -1>();
      return;
    }
    const Cell from = map_.cell_of(parent);
    const int32_t dx = cell.x - from.x, dy = cell.y - from.y;
    const int32_t ax = std::abs(dx), ay = std::abs(dy);
    if (ax > ay) {
      dx > 0 ? expand_straight<1, 0>() : expand_straight<-1, 0>();
    } else if (ay > ax) {
      dy > 0 ? expand_straight<0, 1>() : expand_straight<0, -1>();
    } else if (dy > 0) {
      dx > 0 ? expand_diagonal<1, 1>() : expand_diagonal<-1, 1>();
    } else {
      dx > 0 ? expand_diagonal<1, -1>() : expand_diagonal<-1, -1>();
    }
  }

 private:
  bool blocked_at(int dx, int dy) const { return blocked_[node_ + dy * stride_ + dx] != 0; }
  const uint64_t* row_line(int32_t y) const { return rows_ + static_cast<size_t>(y) * row_words_; }
  const uint64_t* column_line(int32_t x) const {
    return columns_ + static_cast<size_t>(x) * column_words_;
  }

  // Reached moving (kDx, kDy), one of them 0: go on, and turn towards each side whose neighbour
  // is forced (free beside this cell, blocked beside the one before): the straight jump that way
  // and the diagonal between it and the direction of travel.
  template <int kDx, int kDy>
  void expand_straight() {
    if (!jump_straight<kDx, kDy>()) return;
    constexpr int kLeftX = -kDy, kLeftY = kDx;  // the two sides: (kLeftX, kLeftY) and minus it
    if (!blocked_at(kLeftX, kLeftY) && blocked_at(kLeftX - kDx, kLeftY - kDy)) {
      if (!jump_straight<kLeftX, kLeftY>() || !jump_diagonal<kDx + kLeftX, kDy + kLeftY>()) return;
    }
    if (!blocked_at(-kLeftX, -kLeftY) && blocked_at(-kLeftX - kDx, -kLeftY - kDy)) {
      jump_straight<-kLeftX, -kLeftY>() && jump_diagonal<kDx - kLeftX, kDy - kLeftY>();
    }
  }

  template <int kSx, int kSy>
  void expand_diagonal() {
    jump_straight<kSx, 0>() && jump_straight<0, kSy>() && jump_diagonal<kSx, kSy>();
  }

  // The straight jump (kDx, kDy) from the node being expanded: adds the jump point it finds, or
  // the goal when the goal comes first, as a successor. Like every jump, returns false once the
  // goal is reached (the expansion stops there), true otherwise.
  template <int kDx, int kDy>
  bool jump_straight() {
    const int32_t x = cell_.x, y = cell_.y;
    if constexpr (kDy == 0) {
      const int32_t p = scan<kDx>(row_line(y), row_words_, y > 0, y + 1 < height_, x, width_);
      if (goal_.y == y && reached<kDx>(goal_.x, x, p)) return add_goal();
      if (blocked_[node_ + (p - x)] == 0) add_successor({p, y});
    } else {
      const int32_t p = scan<kDy>(column_line(x), column_words_, x > 0, x + 1 < width_, y, height_);
      if (goal_.x == x && reached<kDy>(goal_.y, y, p)) return add_goal();
      if (blocked_[node_ + (p - y) * stride_] == 0) add_successor({x, p});
    }
    return true;
  }

  // Walks the diagonal (kSx, kSy) from the node being expanded while each step is allowed (the
  // cell and both side cells free), launching the two straight jumps at every cell reached. One
  // window of each of the six lines through and beside the cell (its row and column, and the
  // rows and columns on either side) decides both jumps' first 56 cells and the next step; only
  // longer jumps read on. The jump points found wait in a small buffer, so that the walk keeps
  // its state in registers.
  template <int kSx, int kSy>
  bool jump_diagonal() {
    if (blocked_at(kSx, 0) || blocked_at(0, kSy) || blocked_at(kSx, kSy)) return true;
    const ptrdiff_t row_step = kSy * static_cast<ptrdiff_t>(row_words_);
    const ptrdiff_t column_step = kSx * static_cast<ptrdiff_t>(column_words_);
    const int32_t width = width_, height = height_;
    const Cell goal = goal_;
    int32_t x = cell_.x + kSx, y = cell_.y + kSy;
    // The goal's x when the goal lies ahead on this diagonal, else a column the walk never visits.
    const int32_t to_goal_x = (goal.x - cell_.x) * kSx, to_goal_y = (goal.y - cell_.y) * kSy;
    const int32_t goal_x_on_diagonal = to_goal_x > 0 && to_goal_x == to_goal_y ? goal.x : -2;
    // Cells of the diagonal whose row and column ahead (y + kSy, x + kSx) are both in the map:
    // the walk reads their windows without a check; the last cell, at the map's edge, only has
    // its straight jumps left (the step from it leaves the map).
    const int32_t inner_cells = std::min(kSx > 0 ? width - 1 - x : x, kSy > 0 ? height - 1 - y : y);
    const uint64_t* row = row_line(y);
    const uint64_t* column = column_line(x);
    // Entries a step can add: the two straight jumps' ends (or the goal) and the deferred cell.
    constexpr int kAddedPerStep = 3;
    constexpr int kBuffer = 16;
    static_assert(kBuffer >= 2 * kAddedPerStep, "the flush below must leave room for a step");
    constexpr int32_t kDeferAfterCells = 25;  // cells walked; see the end of the loop
    JumpPoint found[kBuffer];
    int count = 0;
    for (int32_t k = 0; k < inner_cells; ++k) {
      // One walk can cross the whole map, each of its cells scanning two whole lines: the budget
      // is polled per cell walked (a counter; the clock every 256 calls), not only per expansion,
      // so a timeout or cancel is seen within a few hundred microseconds on any map. An
      // expired walk stops; the search loop then returns the budget's code.
      if (budget_.poll() != StatusCode::kOk) {
        add_successors(found, count);
        return true;
      }
      if (x == goal_x_on_diagonal) return add_goal();
      const uint64_t row_own = window_at<kSx>(row, x);
      const uint64_t row_ahead = window_at<kSx>(row + row_step, x);
      const uint64_t column_own = window_at<kSy>(column, y);
      const bool x_free = (row_own & kNext<kSx>) == 0;     // (x + kSx, y)
      const bool y_free = (column_own & kNext<kSy>) == 0;  // (x, y + kSy)
      if (x_free) {
        const uint64_t stop =
            row_own | forced<kSx>(window_at<kSx>(row - row_step, x)) | forced<kSx>(row_ahead);
        bool jump_point;
        const int32_t p = first_stop_from<kSx>(stop, row_own, row, row - row_step, row + row_step,
                                               x, width, &jump_point);
        if (goal.y == y && reached<kSx>(goal.x, x, p)) return add_goal();
        if (jump_point) {
          found[count++] = found_at(p, y);
        }
      }
      if (y_free) {
        const uint64_t column_ahead = window_at<kSy>(column + column_step, y);
        const uint64_t stop = column_own | forced<kSy>(window_at<kSy>(column - column_step, y)) |
                              forced<kSy>(column_ahead);
        bool jump_point;
        const int32_t p = first_stop_from<kSy>(stop, column_own, column, column - column_step,
                                               column + column_step, y, height, &jump_point);
        if (goal.x == x && reached<kSy>(goal.y, y, p)) return add_goal();
        if (jump_point) {
          found[count++] = found_at(x, p);
        }
      }
      // The next diagonal cell (x + kSx, y + kSy) is on the row ahead.
      if (!x_free || !y_free || (row_ahead & kNext<kSx>) != 0) {
        add_successors(found, count);
        return true;
      }
      // A long walk that has found jump points and now leads away from the goal (the next step
      // brings it no nearer in x or in y, so f grows) stops here, and this cell becomes a jump
      // point as in the 2011 paper: the rest of the walk waits until its f is the least, which
      // on open ground it rarely becomes. Short walks (rooms, corridors) go on: there the jump
      // point would soon be expanded anyway, and pushing it costs more than the walk.
      if (k + 1 >= kDeferAfterCells && count > 0 &&
          ((goal.x - x) * kSx <= 0 || (goal.y - y) * kSy <= 0)) {
        found[count++] = found_at(x, y);
        add_successors(found, count);
        return true;
      }
      if (count > kBuffer - kAddedPerStep) {
        add_successors(found, count);
        count = 0;
      }
      x += kSx;
      y += kSy;
      row += row_step;
      column += column_step;
    }
    add_successors(found, count);
    // The cell at the map's edge (the walk got there): its straight jumps along the edge.
    if (x == goal_x_on_diagonal) return add_goal();
    return jump_along_row<kSx>(x, y) && jump_along_column<kSy>(x, y);
  }

  // The straight jumps from the diagonal's cell (x, y) at the map's edge, where the lines ahead
  // may be outside: with the bounds checks the walk's inner cells do without.
  template <int kSx>
  bool jump_along_row(int32_t x, int32_t y) {
    if (map_.blocked(x + kSx, y)) return true;
    const int32_t p = scan<kSx>(row_line(y), row_words_, y > 0, y + 1 < height_, x, width_);
    if (goal_.y == y && reached<kSx>(goal_.x, x, p)) return add_goal();
    if (!map_.blocked(p, y)) add_successor({p, y});
    return true;
  }
  template <int kSy>
  bool jump_along_column(int32_t x, int32_t y) {
    if (map_.blocked(x, y + kSy)) return true;
    const int32_t p = scan<kSy>(column_line(x), column_words_, x > 0, x + 1 < width_, y, height_);
    if (goal_.x == x && reached<kSy>(goal_.y, y, p)) return add_goal();
    if (!map_.blocked(x, p)) add_successor({x, p});
    return true;
  }

  // A jump point found by a diagonal walk, with its padded index and its record looked up when
  // it was found: the lookup, a likely cache miss, then overlaps the rest of the walk instead of
  // stalling add_successor (the cells one expansion finds are all distinct, so none of them gets
  // a record in between, and records keep their numbers). No default member initialisers: the
  // walk's buffer is not zeroed.
  struct JumpPoint {
    int32_t x, y;
    uint32_t index;
    uint32_t record;
  };
  JumpPoint found_at(int32_t x, int32_t y) const {
    const uint32_t index = map_.padded_index(x, y);
    return {x, y, index, space_.find(index)};
  }
  void add_successors(const JumpPoint* found, int count) {
    for (int i = 0; i < count; ++i) {
      add_successor({found[i].x, found[i].y}, found[i].index, found[i].record);
    }
  }
  // The goal, reached by a jump from the node being expanded. Every jump costs the octile distance
  // between its ends, so the goal's g is g(n) + octile(n, goal) = f(n), the least f on the open
  // list (in exact step costs): no path to it is shorter (octile is consistent), and the search
  // can stop here. Before, it stopped when the goal was popped, which came next (at equal f the
  // larger g goes first, and only the goal has g = f), with this same g and parent; the path and
  // the expansion count (the goal counts as expanded) are as before, minus the rest of this
  // expansion and that pop.
  bool add_goal() {
    add_successor(goal_);
    goal_reached_ = true;
    return false;
  }

 public:
  bool goal_reached() const { return goal_reached_; }

 private:
  void add_successor(const Cell& to) {
    const uint32_t index = map_.padded_index(to);
    add_successor(to, index, space_.find(index));
  }

  // Opens `to` with the node being expanded as its parent, or lowers its g; closed cells hold
  // their final g already (octile is consistent on the jump graph, whose edges cost the octile
  // distance between their ends).
  // `record` is m's record (SparseSearchSpace::kNoRecord when unseen).
  void add_successor(const Cell& to, uint32_t m, uint32_t record) {
    if (record == SparseSearchSpace::kNoRecord) {
      const double g = g_ + jump_cost(to.x - cell_.x, to.y - cell_.y);
      space_.push(m, g, g + octile(to, goal_), node_);
      return;
    }
    if (space_.closed(record)) return;
    const double g = g_ + jump_cost(to.x - cell_.x, to.y - cell_.y);
    if (g < space_.g_of(record)) space_.update(record, g, g + octile(to, goal_), node_);
  }

  const GridMap& map_;
  SparseSearchSpace& space_;
  PlanningBudget& budget_;
  const uint8_t* blocked_;  // padded, 1 = blocked (GridMap::blocked_data)
  int32_t stride_, width_, height_;
  size_t row_words_, column_words_;  // words per line of the two bit grids
  const uint64_t* rows_;
  const uint64_t* columns_;
  Cell goal_;
  bool goal_reached_ = false;
  // The node being expanded.
  uint32_t node_ = 0;
  Cell cell_;
  double g_ = 0.0;
};

// The cells from the root to `node`: between each jump point and its parent, the diagonal steps
// first and then the straight ones, as the jumps walked them.
std::vector<Cell> trace_path(const GridMap& map, const SparseSearchSpace& space, uint32_t node) {
  size_t cells = 1;
  for (uint32_t n = node; space.parent(n) != SparseSearchSpace::kNoParent; n = space.parent(n)) {
    const Cell a = map.cell_of(space.parent(n)), b = map.cell_of(n);
    cells += static_cast<size_t>(std::max(std::abs(b.x - a.x), std::abs(b.y - a.y)));
  }
  // Filled from its end (the goal) back to the root, in place: no growth checks, no reversal.
  std::vector<Cell> path(cells);
  size_t at = cells;
  uint32_t n = node;
  Cell walk = map.cell_of(n);
  for (uint32_t parent = space.parent(n); parent != SparseSearchSpace::kNoParent;
       n = parent, parent = space.parent(n)) {
    const Cell from = map.cell_of(parent);
    const int32_t dx = walk.x - from.x, dy = walk.y - from.y;
    const int32_t ax = std::abs(dx), ay = std::abs(dy);
    const int sx = sign_of(dx), sy = sign_of(dy);
    const int32_t diagonal = std::min(ax, ay);
    // Backwards from the jump point: first the straight leg, then the diagonal one.
    const int straight_x = ax > ay ? sx : 0, straight_y = ay > ax ? sy : 0;
    for (int32_t i = diagonal; i < std::max(ax, ay); ++i) {
      path[--at] = walk;
      walk.x -= straight_x;
      walk.y -= straight_y;
    }
    for (int32_t i = 0; i < diagonal; ++i) {
      path[--at] = walk;
      walk.x -= sx;
      walk.y -= sy;
    }
  }
  path[--at] = walk;
  return path;
}

}  // namespace

JpsOutcome jps_search(const GridMap& map, SparseSearchSpace& space, const Cell& start,
                      const Cell& goal, PlanningBudget& budget, std::vector<Cell>* expanded_cells) {
  JpsOutcome out;
  if (map.blocked(start) || map.blocked(goal)) {
    out.code = StatusCode::kInternalError;
    return out;
  }
  space.begin_query();
  const uint32_t goal_index = map.padded_index(goal);
  JumpPointSearch search(map, space, goal, budget);
  space.push(map.padded_index(start), 0.0, octile(start, goal), SparseSearchSpace::kNoParent);
  while (!space.empty()) {
    if (const StatusCode code = budget.poll(); code != StatusCode::kOk) {
      out.code = code;
      return out;
    }
    const uint32_t record = space.pop();
    const uint32_t n = space.cell_of(record);
    ++out.expanded;
    const Cell cell = map.cell_of(n);
    if (expanded_cells != nullptr) expanded_cells->push_back(cell);
    if (n == goal_index) {
      out.code = StatusCode::kOk;
      out.path = trace_path(map, space, n);
      return out;
    }
    search.expand(record, n, cell);
    if (search.goal_reached()) {
      ++out.expanded;
      if (expanded_cells != nullptr) expanded_cells->push_back(goal);
      out.code = StatusCode::kOk;
      out.path = trace_path(map, space, goal_index);
      return out;
    }
  }
  return out;
}

}  // namespace vnsba::core::detail
