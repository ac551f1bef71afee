#include "vnsba/core/planner.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "reachability.hpp"
#include "search.hpp"
#include "search_space.hpp"
#include "vnsba/core/budget.hpp"
#include "vnsba/core/heuristics.hpp"
#include "vnsba/core/planner_registry.hpp"
#include "vnsba/core/postprocess.hpp"

namespace vnsba::core {

namespace {

using detail::CellStates;
using detail::SearchOutcome;
using detail::SearchSpace;
using detail::SparseSearchSpace;
using Clock = PlanningBudget::Clock;

std::string describe(const Cell& c) {
  return "(" + std::to_string(c.x) + ", " + std::to_string(c.y) + ")";
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Planner.

// The search state of every planner, none of it allocated before a query uses it
// (search_space.hpp): a unidirectional search never touches `backward`, jump point search only
// `sparse`, and the dense arrays commit only the pages a query writes.
struct Planner::Impl {
  CellStates states;
  SearchSpace forward{&states, 0};
  SearchSpace backward{&states, 1};
  SparseSearchSpace sparse;
  Cell current[2];

  // The registered planner's search (planner_registry.hpp), on free, distinct endpoints.
  SearchOutcome run(const GridMap& map, const PlanQuery& q, const PlannerOptions& o,
                    PlanningBudget& budget, std::vector<Cell>* rec_f, std::vector<Cell>* rec_b) {
    const detail::SearchRequest request{map,     states, forward, backward, sparse, current,
                                        q.start, q.goal, o,       budget,   rec_f,  rec_b};
    return o.planner.descriptor()->search(request);
  }
};

Planner::Planner(std::shared_ptr<const GridMap> map)
    : map_(std::move(map)), impl_(std::make_unique<Impl>()) {}
Planner::~Planner() = default;

void Planner::prepare(const PlannerOptions& options) const {
  const PlannerDescriptor* planner = options.planner.descriptor();
  if (map_ && map_->cell_count() > 0 && planner != nullptr && planner->reads_obstacle_density)
    map_->build_density_table();
}
Planner::Planner(Planner&&) noexcept = default;
namespace {

std::string metres(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3f", v);
  return text;
}

// "goal (1.230, 4.560) m, in cell (24, 91)": a requested point (continuous cell coordinates) in
// metres, and the cell it falls in (or, outside the map, would).
std::string describe_point(const GridMap& map, const char* which, const Point2& point,
                           const Cell& c) {
  const Eigen::Vector2d w = map.grid_to_world(point);
  return std::string(which) + " (" + metres(w.x()) + ", " + metres(w.y()) + ") m, in cell " +
         describe(c);
}

// "(1.225, 4.575) m, cell (24, 91)": a cell by its centre in metres.
std::string describe_centre(const GridMap& map, const Cell& c) {
  const Eigen::Vector2d w = map.cell_centre_world(c);
  return "(" + metres(w.x()) + ", " + metres(w.y()) + ") m, cell " + describe(c);
}

// Why a cell in the map is blocked, naming the layer (docs/algorithm.md section 8).
std::string why_blocked(const GridMap& map, const Cell& c) {
  const GridBuildOptions& o = map.build_options();
  switch (map.layer(c)) {
    case CellLayer::kOccupied:
      return "is in an occupied cell (map value >= occupied_threshold " +
             std::to_string(o.occupied_threshold) + ")";
    case CellLayer::kUnknown:
      return "is in an unknown cell (map value -1, and allow_unknown is false)";
    case CellLayer::kInflated:
      return "is blocked by inflation: its centre is " +
             // Exact from a local search (within the radius, a few words); rounded to float as
             // the distance field of earlier versions stored it, so the message reads the same.
             metres(static_cast<float>(nearest_obstacle_distance(map, c)) * map.resolution()) +
             " m from the nearest obstacle, within robot_radius " + metres(o.robot_radius) + " m";
    case CellLayer::kFree:
      break;
  }
  return "is free";
}

// Whether `from` and `to` would connect if the blocked unknown cells were free: a flood over the
// cells that are free or unknown (occupied and inflated ones stay blocked), 8-connected, a
// diagonal step only between two such orthogonal neighbours (corners never cut: it may miss a
// connection a corner_policy allows, never find one the planner lacks otherwise). Only for a
// failed plan's message, on a map with blocked unknown cells: O(the cells reached), polling
// `budget` (false once it has run out).
bool connected_through_unknown(const GridMap& map, const Cell& from, const Cell& to,
                               PlanningBudget& budget) {
  if (!map.has_blocked_unknown()) return false;
  const int32_t w = map.width(), h = map.height();
  auto passable = [&](int32_t x, int32_t y) {
    if (x < 0 || y < 0 || x >= w || y >= h) return false;
    const CellLayer layer = map.layer({x, y});
    return layer == CellLayer::kFree || layer == CellLayer::kUnknown;
  };
  if (!passable(from.x, from.y) || !passable(to.x, to.y)) return false;
  std::vector<bool> seen(static_cast<size_t>(w) * static_cast<size_t>(h), false);
  std::vector<Cell> stack = {from};
  seen[static_cast<size_t>(from.y) * w + from.x] = true;
  while (!stack.empty()) {
    if (budget.poll() != StatusCode::kOk) return false;
    const Cell c = stack.back();
    stack.pop_back();
    if (c == to) return true;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int32_t x = c.x + dx, y = c.y + dy;
        if ((dx == 0 && dy == 0) || !passable(x, y)) continue;
        if (dx != 0 && dy != 0 &&
            !detail::corner_passable(!passable(c.x + dx, c.y), !passable(c.x, c.y + dy),
                                     CornerPolicy::kNever))
          continue;
        const size_t i = static_cast<size_t>(y) * w + x;
        if (seen[i]) continue;
        seen[i] = true;
        stack.push_back({x, y});
      }
  }
  return false;
}

// The message of a plan that ran out of its budget at `stage` ("while pruning the path").
std::string budget_message(StatusCode code, const PlannerOptions& options, const char* stage) {
  if (code == StatusCode::kCanceled) return std::string("planning canceled ") + stage;
  return "max_planning_time of " + std::to_string(options.max_planning_time.count()) +
         " us elapsed " + stage;
}

// A requested point must lie in its cell: the tolerance measures from it, and the path begins or
// ends there (docs/algorithm.md section 8).
Status check_point(const char* field, const std::optional<Point2>& point, const Cell& cell) {
  if (!point) return Status::ok();
  if (point->allFinite() && std::floor(point->x()) == cell.x && std::floor(point->y()) == cell.y)
    return Status::ok();
  char text[160];
  std::snprintf(text, sizeof text,
                "%s (%.17g, %.17g) cells must be finite and lie in cell (%d, %d)", field,
                point->x(), point->y(), cell.x, cell.y);
  return Status::error(StatusCode::kInvalidRequest, text);
}

// Where a plan's endpoints lie (docs/algorithm.md section 8): each requested cell, or, where it is
// blocked (the start: only by inflation) or outside the map (the goal), the nearest free cell
// within its tolerance that the other endpoint reaches. The steps report in the order of sections
// 1-7: start outside, goal outside, start blocked, goal blocked; then the floods that choose
// reachable cells.
class EndpointResolver {
 public:
  EndpointResolver(const GridMap& map, const PlanQuery& query, const PlannerOptions& options)
      : map_(map),
        query_(query),
        options_(options),
        start_tolerance_cells_(metres_to_cells(options.start_tolerance, map.resolution())),
        goal_tolerance_cells_(metres_to_cells(options.goal_tolerance, map.resolution())),
        requested_start_(query.start_point.value_or(cell_centre(query.start))),
        requested_goal_(query.goal_point.value_or(cell_centre(query.goal))) {
    out_.start = query.start;
    out_.goal = query.goal;
    out_.start_point = requested_start_;
    out_.goal_point = requested_goal_;
  }

  // Both endpoints in the map and free, or a free cell within tolerance of each that is blocked
  // or outside; an error naming the first that has none.
  Status find_free_cells() {
    if (Status s = check_inside(); !s.is_ok()) return s;
    if (Status s = find_start(); !s.is_ok()) return s;
    return find_goal();
  }

  // check_query's endpoints: the nearest free cells taken as they are (reachability unchecked).
  Endpoints nearest() {
    if (nearest_start_) use_start(*nearest_start_);
    if (nearest_goal_) use_goal(*nearest_goal_);
    return out_;
  }

  // The endpoints a plan uses: each moved endpoint the first candidate the other one reaches, by
  // floods over `states` that poll `budget`.
  Expected<Endpoints> reachable(CellStates& states, PlanningBudget* budget) {
    if (move_start_) {
      if (Status s = reach_start(states, budget); !s.is_ok()) return s;
    }
    if (move_goal_) {
      if (Status s = reach_goal(states, budget); !s.is_ok()) return s;
    }
    return out_;
  }

 private:
  detail::NearestFreeCells start_candidates() const {
    return detail::NearestFreeCells(map_, requested_start_, start_tolerance_cells_);
  }
  detail::NearestFreeCells goal_candidates() const {
    return detail::NearestFreeCells(map_, requested_goal_, goal_tolerance_cells_);
  }

  std::string outside(const char* which, const Cell& c) const {
    return std::string(which) + " " + describe(c) + " is outside the map (" +
           std::to_string(map_.width()) + " x " + std::to_string(map_.height()) + " cells)";
  }
  std::string start_blocked() const {
    return describe_point(map_, "start", requested_start_, query_.start) + ", " +
           why_blocked(map_, query_.start);
  }
  std::string goal_blocked() const {
    return goal_inside_ ? describe_point(map_, "goal", requested_goal_, query_.goal) + ", " +
                              why_blocked(map_, query_.goal)
                        : outside("goal", query_.goal);
  }
  // "3 free cells lie within goal_tolerance 0.300 m (the nearest (1.225, 4.575) m, cell (24, 91))"
  std::string free_within(int64_t count, const char* key, double tolerance,
                          const Cell& nearest) const {
    return std::to_string(count) + (count == 1 ? " free cell lies" : " free cells lie") +
           " within " + key + " " + metres(tolerance) + " m (the nearest " +
           describe_centre(map_, nearest) + ")";
  }
  Status stopped(StatusCode code, const char* stage) const {
    return Status::error(code, budget_message(code, options_, stage));
  }

  void use_start(const Cell& c) {
    out_.start = c;
    out_.start_adjusted = true;
    out_.start_point = cell_centre(c);
    out_.start_moved_m = (out_.start_point - requested_start_).norm() * map_.resolution();
  }
  void use_goal(const Cell& c) {
    out_.goal = c;
    out_.goal_adjusted = true;
    out_.goal_point = cell_centre(c);
    out_.goal_moved_m = (out_.goal_point - requested_goal_).norm() * map_.resolution();
  }

  Status check_inside();
  Status find_start();
  Status find_goal();
  Status reach_start(CellStates& states, PlanningBudget* budget);
  Status reach_goal(CellStates& states, PlanningBudget* budget);

  const GridMap& map_;
  const PlanQuery& query_;
  const PlannerOptions& options_;
  double start_tolerance_cells_;
  double goal_tolerance_cells_;
  Point2 requested_start_;  // continuous cell coordinates
  Point2 requested_goal_;
  Endpoints out_;
  bool goal_inside_ = false;
  bool move_start_ = false;
  bool move_goal_ = false;
  std::optional<Cell> nearest_start_;  // the first free candidate, when the endpoint moves
  std::optional<Cell> nearest_goal_;
};

// A start outside the map is final. Without goal_tolerance so is a goal outside, and it is
// reported before a blocked start, in the order of sections 1-7: start outside, goal outside,
// start blocked, goal blocked.
Status EndpointResolver::check_inside() {
  if (!map_.in_bounds(query_.start))
    return Status::error(StatusCode::kStartOutsideMap, outside("start", query_.start));
  goal_inside_ = map_.in_bounds(query_.goal);
  if (!goal_inside_ && !(goal_tolerance_cells_ > 0.0))
    return Status::error(StatusCode::kGoalOutsideMap, outside("goal", query_.goal));
  return Status::ok();
}

// The start: moved only out of inflation (a robot standing in an obstacle has a real problem).
Status EndpointResolver::find_start() {
  move_start_ = map_.blocked(query_.start);
  if (!move_start_) return Status::ok();
  const bool inflation = map_.layer(query_.start) == CellLayer::kInflated;
  if (inflation) nearest_start_ = start_candidates().next();
  if (nearest_start_) return Status::ok();
  std::string message = start_blocked();
  if (inflation && options_.start_tolerance > 0.0)
    message += "; no free cell within start_tolerance " + metres(options_.start_tolerance) + " m";
  return Status::error(StatusCode::kStartOccupied, message);
}

// The goal: moved out of any blocked cell, or into the map, within goal_tolerance.
Status EndpointResolver::find_goal() {
  move_goal_ = !goal_inside_ || map_.blocked(query_.goal);
  if (!move_goal_) return Status::ok();
  nearest_goal_ = goal_candidates().next();
  if (nearest_goal_) return Status::ok();
  const std::string within =
      options_.goal_tolerance > 0.0
          ? "; no free cell within goal_tolerance " + metres(options_.goal_tolerance) + " m"
          : "";
  return Status::error(goal_inside_ ? StatusCode::kGoalOccupied : StatusCode::kGoalOutsideMap,
                       goal_blocked() + within);
}

// The start first, towards the goal or, when the goal moves too, towards any free cell within
// goal_tolerance of it (the goal is then chosen among those the start reaches).
Status EndpointResolver::reach_start(CellStates& states, PlanningBudget* budget) {
  std::vector<uint32_t> anchors;
  if (move_goal_) {
    for (auto goals = goal_candidates(); const auto c = goals.next();)
      anchors.push_back(map_.padded_index(*c));
  } else {
    anchors.push_back(map_.padded_index(query_.goal));
  }
  auto candidates = start_candidates();
  const detail::ReachOutcome reach =
      detail::first_reachable(map_, options_.corner_policy, states, budget, anchors, candidates);
  if (reach.code != StatusCode::kOk)
    return stopped(reach.code, "while choosing a start within start_tolerance");
  if (!reach.cell) {
    const std::string goal_side =
        move_goal_ ? "any of the " + std::to_string(anchors.size()) +
                         " free cells within goal_tolerance " + metres(options_.goal_tolerance) +
                         " m of the " + describe_point(map_, "goal", requested_goal_, query_.goal)
                   : "the " + describe_point(map_, "goal", requested_goal_, query_.goal);
    return Status::error(StatusCode::kNoValidPath,
                         start_blocked() + "; " +
                             free_within(reach.candidates, "start_tolerance",
                                         options_.start_tolerance, *nearest_start_) +
                             ", but none of them connects to " + goal_side);
  }
  use_start(*reach.cell);
  return Status::ok();
}

// The goal, among its candidates, the first the (used) start reaches.
Status EndpointResolver::reach_goal(CellStates& states, PlanningBudget* budget) {
  auto candidates = goal_candidates();
  const detail::ReachOutcome reach = detail::first_reachable(
      map_, options_.corner_policy, states, budget, {map_.padded_index(out_.start)}, candidates);
  if (reach.code != StatusCode::kOk)
    return stopped(reach.code, "while choosing a goal within goal_tolerance");
  if (!reach.cell) {
    const std::string start_used =
        out_.start_adjusted ? "the start used " + describe_centre(map_, out_.start)
                            : "the " + describe_point(map_, "start", requested_start_, out_.start);
    return Status::error(StatusCode::kNoValidPath,
                         goal_blocked() + "; " +
                             free_within(reach.candidates, "goal_tolerance",
                                         options_.goal_tolerance, *nearest_goal_) +
                             ", but none of them is reachable from " + start_used +
                             ": they are sealed off from it");
  }
  use_goal(*reach.cell);
  return Status::ok();
}

// resolve_endpoints, and with `states` null check_query: the reachability of moved endpoints is
// then not checked (the nearest free cells are taken as they are).
Expected<Endpoints> resolve(const GridMap& map, const PlanQuery& query,
                            const PlannerOptions& options, CellStates* states,
                            PlanningBudget* budget) {
  if (Status s = validate(options); !s.is_ok()) return s;
  if (Status s = check_point("start_point", query.start_point, query.start); !s.is_ok()) return s;
  if (Status s = check_point("goal_point", query.goal_point, query.goal); !s.is_ok()) return s;
  EndpointResolver resolver(map, query, options);
  if (Status s = resolver.find_free_cells(); !s.is_ok()) return s;
  if (states == nullptr) return resolver.nearest();
  return resolver.reachable(*states, budget);
}

}  // namespace

Expected<Endpoints> resolve_endpoints(const GridMap& map, const PlanQuery& query,
                                      const PlannerOptions& options, PlanningBudget* budget) {
  // The flood's words are allocated only when an endpoint moves (begin_query sizes them).
  CellStates states;
  return resolve(map, query, options, &states, budget);
}

Status check_query(const GridMap& map, const PlanQuery& query, const PlannerOptions& options) {
  const Expected<Endpoints> endpoints = resolve(map, query, options, nullptr, nullptr);
  return endpoints ? Status::ok() : endpoints.error();
}

Planner& Planner::operator=(Planner&&) noexcept = default;

size_t Planner::search_state_bytes() const {
  return impl_->states.bytes() + impl_->forward.bytes() + impl_->backward.bytes() +
         impl_->sparse.bytes();
}

double Planner::peak_bytes_per_cell_per_direction() const {
  if (!map_ || map_->cell_count() == 0) return 0.0;
  const size_t direction =
      std::max({impl_->forward.bytes(), impl_->backward.bytes(), impl_->sparse.bytes()});
  return static_cast<double>(direction) / static_cast<double>(map_->cell_count());
}

namespace {

// Whether `path` is exactly the centres of `cells`, point by point.
bool is_cell_centres(const std::vector<Point2>& path, const std::vector<Cell>& cells) {
  if (path.size() != cells.size()) return false;
  for (size_t i = 0; i < path.size(); ++i) {
    const Point2 centre = cell_centre(cells[i]);
    // Coordinate by coordinate: Eigen's != on whole points costs several times as much.
    if (path[i].x() != centre.x() || path[i].y() != centre.y()) return false;
  }
  return true;
}

// What a search that ended without a path means: no connection (and whether unknown cells close
// the way), the budget run out, or a state no search ends in.
Status search_failure(const GridMap& map, const SearchOutcome& outcome, const Endpoints& endpoints,
                      const PlannerOptions& options, PlanningBudget& budget) {
  switch (outcome.code) {
    case StatusCode::kOk:
      return Status::ok();
    case StatusCode::kNoValidPath:
      return Status::error(
          outcome.code,
          "no path from " + describe_point(map, "start", endpoints.start_point, endpoints.start) +
              " to " + describe_point(map, "goal", endpoints.goal_point, endpoints.goal) +
              ": they are not connected" +
              (connected_through_unknown(map, endpoints.start, endpoints.goal, budget)
                   ? "; unknown cells close the way (with allow_unknown true they would connect)"
                   : ""));
    case StatusCode::kTimeout:
    case StatusCode::kCanceled:
      return Status::error(outcome.code,
                           budget_message(outcome.code, options, "before a path was found"));
    default:
      return Status::error(StatusCode::kInternalError, "search ended in an unexpected state");
  }
}

// Sections 4, 5 and 7 on result.raw_path: pruning (with pruning on), the exact ends, the turns the
// smoothing starts from, and the corner splines (with smooth on) into result.path.
// `path_cost_weight`: the cost weight the search used (0 on a map without costs).
Status prune_and_smooth(const GridMap& map, const Endpoints& endpoints,
                        const PlannerOptions& options, double path_cost_weight,
                        PlanningBudget& budget, PlanResult& result) {
  std::vector<Point2> raw_centres = cell_centres(result.raw_path);
  result.metrics.raw_cost_cells = polyline_length(raw_centres);
  result.waypoints = options.prune ? prune_path(map, result.raw_path, options.corner_policy,
                                                &budget, path_cost_weight)
                                   : std::move(raw_centres);
  if (budget.expired())
    return Status::error(budget.state(),
                         budget_message(budget.state(), options, "while pruning the path"));
  // The requested start and goal exactly, or the cells' centres where a tolerance moved them
  // (docs/algorithm.md section 8); turns, length and clearance are those of this path.
  result.waypoints =
      join_exact_ends(map, std::move(result.waypoints), endpoints.start_point, endpoints.goal_point,
                      options.corner_policy, path_cost_weight, options.prune);
  // Turns of the polyline smoothing starts from (docs/algorithm.md section 7).
  const TurnStats turns = turn_stats(result.waypoints);
  result.metrics.turns = turns.turns;
  result.metrics.turn_angle_deg = turns.total_angle_deg;
  if (!options.smooth) {
    result.path = result.waypoints;
    return Status::ok();
  }
  SmoothingOptions smoothing;
  smoothing.smoothing_distance = options.smoothing_distance;
  smoothing.sample_step = options.sample_step;
  smoothing.corner_policy = options.corner_policy;
  smoothing.cost_weight = path_cost_weight;
  result.path = smooth_path(map, result.waypoints, smoothing, &budget);
  if (budget.expired())
    return Status::error(budget.state(),
                         budget_message(budget.state(), options, "while smoothing the path"));
  return Status::ok();
}

// The relax smoother on result.path (options.smoother relax): the relaxed path replaces it only
// when its clearance is no lower. Sets `clearance_cells` to the final path's clearance (cells).
Status relax_stage(const GridMap& map, const PlannerOptions& options, double path_cost_weight,
                   PlanningBudget& budget, PlanResult& result,
                   std::optional<double>& clearance_cells) {
  RelaxOptions relax;
  relax.smoothness = options.smoother_smoothness;
  relax.closeness = options.smoother_closeness;
  relax.cost = options.smoother_cost;
  relax.cost_weight = path_cost_weight;
  relax.iterations = options.smoother_iterations;
  relax.corner_policy = options.corner_policy;
  // The unrelaxed path's clearance (cells) is the floor; the relaxed path replaces it only when
  // its own, measured the same way, is no lower (not even by rounding).
  const double floor = path_clearance_cells(map, result.path);
  // relax_path measures each segment alone; a margin far below any distance that matters
  // keeps its rounding from putting the whole path a last bit under the floor.
  constexpr double kRoundingMarginCells = 1e-9;
  std::vector<Point2> relaxed =
      relax_path(map, result.path, relax, floor + kRoundingMarginCells, &budget);
  if (budget.expired())
    return Status::error(budget.state(),
                         budget_message(budget.state(), options, "while relaxing the path"));
  const double relaxed_clearance = path_clearance_cells(map, relaxed);
  if (relaxed_clearance < floor) {
    clearance_cells = floor;
    return Status::ok();
  }
  result.path = std::move(relaxed);
  clearance_cells = relaxed_clearance;
  // The relaxed path follows a curve: its turns are the corners of that curve (metrics.hpp).
  const TurnStats corners =
      turn_stats(simplify_polyline(result.path, kRelaxedCornerToleranceCells));
  result.metrics.turns = corners.turns;
  result.metrics.turn_angle_deg = corners.total_angle_deg;
  return Status::ok();
}

}  // namespace

PlanResult Planner::plan(const PlanQuery& query, const PlannerOptions& options,
                         const std::atomic<bool>* cancel) {
  const Clock::time_point started = Clock::now();
  PlanResult result;
  result.planner = options.planner;
  // Every outcome, failures included, reports the time spent and the nodes expanded so far.
  auto stop_clock = [&] {
    result.metrics.planning_time_us =
        std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - started).count();
  };
  auto fail = [&](Status status) {
    result.status = std::move(status);
    stop_clock();
    return result;
  };
  if (!map_ || map_->cell_count() == 0)
    return fail(Status::error(StatusCode::kInvalidMap, "no map to plan on"));
  const GridMap& map = *map_;
  // One budget for the tolerance's floods, search, pruning and smoothing.
  PlanningBudget budget(started, options.max_planning_time, cancel);
  // The search words serve the tolerance's floods first (no allocation).
  const Expected<Endpoints> endpoints = resolve(map, query, options, &impl_->states, &budget);
  if (!endpoints) return fail(endpoints.error());
  result.endpoints = *endpoints;
  const PlanQuery resolved{endpoints->start, endpoints->goal};
  SearchOutcome outcome;
  if (resolved.start == resolved.goal) {
    outcome.code = StatusCode::kOk;
    outcome.path = {resolved.start};
  } else {
    const Clock::time_point search_started = Clock::now();
    outcome = impl_->run(map, resolved, options, budget, &result.expanded_forward,
                         &result.expanded_backward);
    result.metrics.search_time_us =
        std::chrono::duration<double, std::micro>(Clock::now() - search_started).count();
  }
  result.metrics.expanded = outcome.expanded;
  result.meeting_cell = outcome.meeting;
  if (Status s = search_failure(map, outcome, *endpoints, options, budget); !s.is_ok())
    return fail(std::move(s));
  result.raw_path = std::move(outcome.path);
  // Pruning and smoothing weigh costs as the search did (docs/algorithm.md section 8).
  const double path_cost_weight = map.has_costs() ? options.cost_weight : 0.0;
  if (Status s = prune_and_smooth(map, *endpoints, options, path_cost_weight, budget, result);
      !s.is_ok())
    return fail(std::move(s));
  std::optional<double> clearance_cells;  // of result.path, when the smoother measured it
  if (options.smoother == PathSmoother::kRelax) {
    if (Status s = relax_stage(map, options, path_cost_weight, budget, result, clearance_cells);
        !s.is_ok())
      return fail(std::move(s));
  }
  result.world_path.resize(result.path.size());  // Eigen leaves the points uninitialised
  for (size_t i = 0; i < result.path.size(); ++i)
    result.world_path[i] = map.grid_to_world(result.path[i]);
  // A final path that is the grid path's cell centres (no pruning, smoothing or moved ends: jps
  // and astar as the paper runs them) has the length raw_cost_cells measured already, the same
  // points summed in the same order; comparing them costs a fraction of summing them again.
  const bool path_is_grid_path = is_cell_centres(result.path, result.raw_path);
  result.metrics.length_cells =
      path_is_grid_path ? result.metrics.raw_cost_cells : polyline_length(result.path);
  result.metrics.length_m = result.metrics.length_cells * map.resolution();
  result.status = Status::ok();
  stop_clock();
  // After the clock, like the reference search below: a measurement of the result.
  if (!clearance_cells) {
    clearance_cells = path_is_grid_path ? grid_path_clearance_cells(map, result.raw_path)
                                        : path_clearance_cells(map, result.path);
  }
  result.metrics.clearance_m = *clearance_cells * map.resolution();

  // After the clock has stopped: the reference search is not part of the planning time. It has
  // no time budget but honours the cancel flag (a canceled reference leaves the ratio NaN).
  if (options.compute_length_ratio) {
    PlannerOptions optimal = default_options(PlannerKind::kAStar);
    optimal.corner_policy = options.corner_policy;
    PlanningBudget cancel_only(Clock::now(), std::chrono::microseconds{0}, cancel);
    const SearchOutcome best = impl_->run(map, resolved, optimal, cancel_only, nullptr, nullptr);
    if (best.code == StatusCode::kOk) {
      const double best_cost = polyline_length(cell_centres(best.path));
      result.metrics.length_ratio = best_cost > 0.0 ? result.metrics.length_cells / best_cost : 1.0;
    }
  }
  return result;
}

PlanResult plan_once(std::shared_ptr<const GridMap> map, const PlanQuery& query,
                     const PlannerOptions& options) {
  Planner planner(std::move(map));
  return planner.plan(query, options);
}

}  // namespace vnsba::core
