// The planners of docs/algorithm.md: VNS-BA* and its baselines, behind one interface.
//
//   auto map = std::make_shared<const GridMap>(GridMap::build(grid).value());
//   Planner planner(map);                       // allocates nothing yet
//   PlannerOptions opts = default_options(PlannerKind::kVnsBaStar);
//   PlanResult r = planner.plan({start, goal}, opts);
//   if (r.status.is_ok()) use(r.world_path);
//
// A Planner reuses its search state across queries on the same map; it is not thread-safe (one
// Planner per thread), but any number of Planners may share one GridMap. The state grows with
// what the searches touch, not with the map: nothing is committed before the first query, and a
// query commits memory only for the cells it reaches (4 KiB pages of per-cell arrays for the
// searches that step from cell to cell: 2 bytes a cell shared plus 16 bytes a cell per direction
// searched; a record per touched cell for jump point search), kept for the next query. Making
// a Planner is cheap whatever the map's size.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include "vnsba/core/budget.hpp"
#include "vnsba/core/geometry.hpp"
#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/line_of_sight.hpp"
#include "vnsba/core/metrics.hpp"
#include "vnsba/core/neighborhood.hpp"
#include "vnsba/core/planner_options.hpp"
#include "vnsba/core/status.hpp"

namespace vnsba::core {

struct PlanQuery {
  PlanQuery() = default;
  // Two constructors rather than defaulted optionals: GCC 12 at -O2 reports a defaulted
  // std::optional<Eigen::Vector2d> argument as maybe-uninitialized (a false positive that
  // -Werror turns into a build failure).
  PlanQuery(const Cell& start_cell, const Cell& goal_cell) : start(start_cell), goal(goal_cell) {}
  PlanQuery(const Cell& start_cell, const Cell& goal_cell,
            const std::optional<Point2>& start_position, const std::optional<Point2>& goal_position)
      : start(start_cell),
        goal(goal_cell),
        start_point(start_position),
        goal_point(goal_position) {}

  Cell start;  // may lie outside the map (refused, or moved by start_tolerance; see below)
  Cell goal;   // likewise, with goal_tolerance
  // The requested positions in continuous cell coordinates, each inside its cell (floor of the
  // point = the cell, also for a goal outside the map; anything else is INVALID_REQUEST naming
  // the field). Tolerance picks the free cell whose centre is nearest to them (docs/algorithm.md
  // section 8); unset, the cells' centres.
  std::optional<Point2> start_point;
  std::optional<Point2> goal_point;
};

// The start and goal a plan uses: the query's, or where start_tolerance / goal_tolerance moved
// them (docs/algorithm.md section 8).
struct Endpoints {
  Cell start;
  Cell goal;
  bool start_adjusted = false;
  bool goal_adjusted = false;
  double start_moved_m = 0.0;  // metres from the requested point to the used cell's centre
  double goal_moved_m = 0.0;   // (0 when not adjusted)
  // Where the path begins and ends, continuous cell coordinates: the requested point (the query's
  // start_point / goal_point, else its cell's centre), or the used cell's centre where a
  // tolerance moved it.
  Point2 start_point = Point2::Zero();
  Point2 goal_point = Point2::Zero();
};

struct PlanResult {
  Status status;
  // Where the search started and ended (also on failures after the endpoints were resolved).
  Endpoints endpoints;
  PlannerKind planner = PlannerKind::kVnsBaStar;
  // The grid path from start to goal, one cell per search step (steps up to 2 cells long with
  // the 8-11-13 neighbourhood). Empty unless status is OK.
  std::vector<Cell> raw_path;
  // Turning points after pruning, continuous cell coordinates: cell centres between the exact
  // ends, endpoints.start_point first and endpoints.goal_point last (join_exact_ends: the first
  // and last centres stay only where the segment past them would lack line of sight or cost
  // more). With pruning off, the raw path's centres between the exact ends. The polyline turns
  // are counted on.
  std::vector<Point2> waypoints;
  // The final path in continuous cell coordinates (after smoothing where it is on): it begins at
  // endpoints.start_point and ends at endpoints.goal_point exactly (the requested points, or the
  // used cells' centres where a tolerance moved them; docs/algorithm.md section 8).
  std::vector<Point2> path;
  // The final path in world coordinates (metres).
  std::vector<Eigen::Vector2d> world_path;
  // Closed cells of each search, in expansion order, when record_expansions is on. A
  // unidirectional planner fills only the forward list.
  std::vector<Cell> expanded_forward;
  std::vector<Cell> expanded_backward;
  // Where a bidirectional search met (the generated neighbour closed by the other search).
  std::optional<Cell> meeting_cell;
  Metrics metrics;
};

// What Planner::plan checks before it searches: the options, then start and goal inside the
// map and on free cells, each moved within its tolerance where it is not (the start only when
// inflation alone blocks it). The message names the field at fault, the layer that blocks it
// (occupied, unknown, inflation), and the requested point in metres with the cell it falls in.
//
// Tolerance (docs/algorithm.md section 8) picks the free cell nearest the requested point (centre
// distance, ties to the lower row-major index) within the tolerance *that the other endpoint can
// reach* under the planner's moves (8-connected, diagonals by corner_policy; the 8-11-13 moves
// reach no other cell): a free speck sealed inside a wall is never chosen while a reachable free
// cell lies within the tolerance. The start is resolved first: with a free goal, the nearest start
// candidate connected to the goal; with a goal that must move too, the nearest start candidate
// connected to any free cell within goal_tolerance of the goal; then the goal, the nearest
// candidate the start used can reach. GOAL_OCCUPIED / GOAL_OUTSIDE_MAP / START_OCCUPIED when no
// free cell lies within the tolerance; NO_VALID_PATH, saying that free cells were there but
// unreachable, when some do but none connects.
//
// Cost: nothing beyond the checks when no endpoint moves. Otherwise a flood alternating between
// the candidate and the other endpoint (see reachability.hpp): a sealed speck costs its own size,
// a reachable candidate about the cells between the two; over all candidates each cell is visited
// at most twice. It needs 2 bytes per map cell it reaches: the Planner's own search words; this
// free function reserves them when an endpoint moves (committed where the flood goes). `budget`
// (may be null) is polled throughout: TIMEOUT / CANCELED when it runs out.
Expected<Endpoints> resolve_endpoints(const GridMap& map, const PlanQuery& query,
                                      const PlannerOptions& options,
                                      PlanningBudget* budget = nullptr);
// resolve_endpoints' verdict without the reachability of moved endpoints (which only the plan
// finds out, as it finds out whether start and goal connect): the cheap checks a request can get
// before it waits for a planner, O(the cells out to the nearest free one).
Status check_query(const GridMap& map, const PlanQuery& query, const PlannerOptions& options);

class Planner {
 public:
  // Allocates the search arrays for `map` (see above).
  explicit Planner(std::shared_ptr<const GridMap> map);
  ~Planner();
  Planner(Planner&&) noexcept;
  Planner& operator=(Planner&&) noexcept;
  Planner(const Planner&) = delete;
  Planner& operator=(const Planner&) = delete;

  // Builds what `options`' planner reads of the map beyond its cells, once per map (the obstacle
  // density table of VNS-BA* and the improved BA*: 4 bytes a cell, tens of milliseconds at
  // 4096 x 4096), so that no query pays for it; nothing for the other planners. Optional: the
  // first query builds what was not prepared. Thread-safe on a shared map.
  void prepare(const PlannerOptions& options) const;

  // Never throws for bad input: every failure comes back as PlanResult::status, and every
  // status, failures included, reports the real planning time and the nodes expanded.
  // `cancel`, when given, and options.max_planning_time are polled throughout: search, pruning
  // and smoothing. Raising the flag yields CANCELED, running out of time TIMEOUT.
  PlanResult plan(const PlanQuery& query, const PlannerOptions& options,
                  const std::atomic<bool>* cancel = nullptr);

  const GridMap& map() const { return *map_; }
  const std::shared_ptr<const GridMap>& shared_map() const { return map_; }

  // Bytes of search state committed now (the pages of per-cell arrays the queries so far have
  // written, the jump point records and the open lists): 0 before the first query. O(pages
  // reserved), for reports, not per query.
  size_t search_state_bytes() const;
  // The bytes one direction's search state holds now (the most of any direction; pages are kept
  // across queries, so this is its high-water mark), divided by the map's cell count.
  double peak_bytes_per_cell_per_direction() const;

 private:
  struct Impl;
  std::shared_ptr<const GridMap> map_;
  std::unique_ptr<Impl> impl_;
};

// Convenience for one-off queries (allocates the search state on each call).
PlanResult plan_once(std::shared_ptr<const GridMap> map, const PlanQuery& query,
                     const PlannerOptions& options);

}  // namespace vnsba::core
