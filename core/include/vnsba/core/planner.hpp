// The planners of ALGORITHM.md: VNS-BA* and its baselines, behind one interface.
//
//   auto map = std::make_shared<const GridMap>(GridMap::build(grid).value());
//   Planner planner(map);                       // allocates search state once for this map
//   PlannerOptions opts = default_options(PlannerKind::kVnsBaStar);
//   PlanResult r = planner.plan({start, goal}, opts);
//   if (r.status.is_ok()) use(r.world_path);
//
// A Planner reuses its flat search arrays across queries on the same map; it is not
// thread-safe (one Planner per thread), but any number of Planners may share one GridMap.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include "vnsba/core/geometry.hpp"
#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/line_of_sight.hpp"
#include "vnsba/core/metrics.hpp"
#include "vnsba/core/neighborhood.hpp"
#include "vnsba/core/status.hpp"

namespace vnsba::core {

enum class PlannerKind {
  kAStar,                          // "astar": classic A*, octile heuristic, optimal
  kWeightedAStar,                  // "weighted_astar": the paper's "improved A*" (Liao et al.)
  kBidirectionalAStar,             // "bidirectional_astar": the paper's "BA*"
  kAlternatingBidirectionalAStar,  // "alternating_bidirectional_astar": "improved BA*" (Li 2022)
  kVnsBaStar,                      // "vns_bastar": the paper's VNS-BA*
};

std::string_view to_string(PlannerKind kind);
std::optional<PlannerKind> planner_kind_from_string(std::string_view name);
// All planners, in the paper's table order.
const std::vector<PlannerKind>& all_planner_kinds();

struct PlannerOptions {
  PlannerKind planner = PlannerKind::kVnsBaStar;
  double omega = 0.5;  // weight of dist(n, opposite_current) in p(n); [0, 1e6], finite
  double eta = 0.5;    // weight of dist(n, opposite_start) in p(n); [0, 1e6], finite
  Neighborhood neighborhood = Neighborhood::kEightElevenThirteen;
  CornerPolicy corner_policy = CornerPolicy::kNever;
  bool prune = true;                // polyline pruning (section 4)
  bool smooth = true;               // cubic-spline corner smoothing (section 5); needs prune
                                    // or works on the raw path's corners when prune is off
  double smoothing_distance = 1.5;  // cells, > 0
  double sample_step = 0.25;        // cells, in (0, 10]
  // Wall-clock budget for search plus post-processing; zero or negative means unlimited.
  std::chrono::microseconds max_planning_time{0};
  bool record_expansions = false;  // fill PlanResult::expanded_* (for debug pictures)
  // Also run optimal A* on the same query to fill Metrics::length_ratio (costs a second search).
  bool compute_length_ratio = false;
};

// The paper's configuration of each planner: VNS-BA* with the 8-11-13 neighbourhood, pruning
// and smoothing; the baselines with the 8-neighbourhood and no post-processing.
PlannerOptions default_options(PlannerKind kind);

// Checks ranges and finiteness; the message names the option at fault.
Status validate(const PlannerOptions& options);

struct PlanQuery {
  Cell start;
  Cell goal;
};

struct PlanResult {
  Status status;
  PlannerKind planner = PlannerKind::kVnsBaStar;
  // The grid path from start to goal, one cell per search step (steps up to 2 cells long with
  // the 8-11-13 neighbourhood). Empty unless status is OK.
  std::vector<Cell> raw_path;
  // Turning points after pruning, continuous cell coordinates (cell centres); equal to the raw
  // path's centres when pruning is off.
  std::vector<Point2> waypoints;
  // The final path in continuous cell coordinates (after smoothing where it is on).
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

class Planner {
 public:
  explicit Planner(std::shared_ptr<const GridMap> map);
  ~Planner();
  Planner(Planner&&) noexcept;
  Planner& operator=(Planner&&) noexcept;
  Planner(const Planner&) = delete;
  Planner& operator=(const Planner&) = delete;

  // Never throws for bad input: every failure comes back as PlanResult::status. `cancel`, when
  // given, is polled during the search; raising it yields CANCELED.
  PlanResult plan(const PlanQuery& query, const PlannerOptions& options,
                  const std::atomic<bool>* cancel = nullptr);

  const GridMap& map() const { return *map_; }
  const std::shared_ptr<const GridMap>& shared_map() const { return map_; }

  // Bytes held by the search state (per-cell arrays of both directions plus heaps), measured
  // from the containers' capacities. Grows lazily: a unidirectional planner never allocates the
  // backward direction.
  size_t search_state_bytes() const;
  // The most bytes of search state ever held by one direction, divided by the map's cell count.
  double peak_bytes_per_cell_per_direction() const;

 private:
  struct Impl;
  std::shared_ptr<const GridMap> map_;
  std::unique_ptr<Impl> impl_;
};

// Convenience for one-off queries (allocates search state each call).
PlanResult plan_once(std::shared_ptr<const GridMap> map, const PlanQuery& query,
                     const PlannerOptions& options);

}  // namespace vnsba::core
