// Goal and start tolerance (docs/algorithm.md section 8), internal: the free cells near a requested
// point in order of distance, and which of them the other endpoint can reach.
//
// Reachability is judged under the planner's moves: 8-connected moves, a diagonal one subject to
// the options' corner_policy (MotionValidator::for_each_move with the 8-neighbourhood, the one
// rule). The 8-11-13 neighbourhood reaches nothing more: its extra moves exist only when all 8
// neighbours are free, and each ends in a cell that a straight move from one of those free
// neighbours also reaches ((2, 0) from (1, 0), (2, 1) and (1, 2) from (1, 1), (2, 2) from
// whichever of (2, 1) and (1, 2) the corner policy needed free, or from (1, 1) diagonally under
// `always`). Jump point search plans on the 8-neighbourhood with corner_policy never. The moves
// are symmetric (a diagonal move and its reverse test the same two side cells), so "connected" is
// an equivalence: free cells fall into components, and a cell is reachable exactly when it shares
// the start's.
#pragma once

#include <cstdint>
#include <optional>
#include <queue>
#include <vector>

#include "search_space.hpp"
#include "vnsba/core/budget.hpp"
#include "vnsba/core/geometry.hpp"
#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/line_of_sight.hpp"

namespace vnsba::core::detail {

// The free cells whose centres lie within `radius_cells` of `point` (continuous cell coordinates;
// may lie outside the map), in order of centre distance, ties to the lower row-major index: the
// order in which tolerance prefers them. Lazy: rings of cells around the point are added only as
// far as the cells handed out need, so taking the first few costs about the area out to them,
// not the area of the whole tolerance (which may be thousands of cells across).
class NearestFreeCells {
 public:
  NearestFreeCells(const GridMap& map, const Point2& point, double radius_cells);

  // The next cell in that order; nullopt when none is left within the radius.
  std::optional<Cell> next();

 private:
  struct Entry {
    double squared;  // squared centre distance, cells^2
    int32_t y, x;    // row-major order breaks ties
    bool operator>(const Entry& o) const {
      if (squared != o.squared) return squared > o.squared;
      return y != o.y ? y > o.y : x > o.x;
    }
  };
  void add_ring();

  const GridMap& map_;
  Point2 point_;
  double radius_squared_ = 0.0;
  // The map cells whose centres may lie within the radius (inclusive bounds); empty when
  // xa_ > xb_. Rings are Chebyshev rings around centre_, clipped to this box.
  int32_t xa_ = 0, xb_ = -1, ya_ = 0, yb_ = -1;
  Cell centre_;
  int32_t ring_ = -1;  // the last ring added
  bool rings_done_ = true;
  // Entries of rings added so far; one is handed out once no later ring can hold a nearer one,
  // i.e. once its squared distance is below bound_squared_.
  double bound_squared_ = 0.0;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> heap_;
};

// How a probe of candidates against anchors ended.
struct ReachOutcome {
  std::optional<Cell> cell;  // the first candidate an anchor reaches; nullopt when none does
  int64_t candidates = 0;    // candidates taken from the enumeration (all of them without one)
  StatusCode code = StatusCode::kOk;  // kTimeout / kCanceled when the budget ran out first
};

// The first cell of `candidates` (in their order) connected to any of `anchors` (padded indices of
// free cells). Each candidate is tested by a bidirectional flood: one cell expanded from the
// candidate, then one from the anchors, alternately, until they meet (connected) or the
// candidate's side runs out of cells (a component of its own: a sealed speck exhausts in as many
// steps as it has cells). Nothing is forgotten between candidates: the anchors' flood goes on
// where it stopped, and the cells of an exhausted candidate flood stay marked, so a later
// candidate in the same sealed component is refused at once; once the anchors' flood has run out,
// its marks answer every remaining candidate at once. All floods together visit each cell at most
// twice. `states` is the planner's per-cell word array (one new query's epoch: no allocation when
// it is already sized for the map); the budget, when given, is polled once per cell expanded.
ReachOutcome first_reachable(const GridMap& map, CornerPolicy policy, CellStates& states,
                             PlanningBudget* budget, const std::vector<uint32_t>& anchors,
                             NearestFreeCells& candidates);

}  // namespace vnsba::core::detail
