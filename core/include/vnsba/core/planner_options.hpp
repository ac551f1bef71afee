// Which planner runs, with which options, and the one way to build those options from what a
// user configured (a config file, a command line, a benchmark's setup).
//
//   PlannerSettings configured;                 // only what the user set; the rest stays unset
//   configured.prune = false;
//   PlannerOptions astar = make_options(PlannerKind::kAStar, configured);
//   PlannerOptions vns = make_options(PlannerKind::kVnsBaStar, configured);  // prune still off
//
// The node (its config and every per-request planner override), vnsba_plan and vnsba_bench build
// their options through make_options only: switching planners keeps every configured setting,
// and only the settings nobody configured follow the new planner's paper configuration.
#pragma once

#include <chrono>
#include <cmath>
#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "vnsba/core/line_of_sight.hpp"
#include "vnsba/core/neighborhood.hpp"
#include "vnsba/core/status.hpp"

namespace vnsba::core {

struct PlannerDescriptor;  // planner_registry.hpp

// The planners this code names: each is defined in core/src/planners/<name>.cpp and listed in
// core/src/planner_registry.cpp. A planner no code names needs no entry here.
namespace planners {
extern const PlannerDescriptor astar;                // classic A*, octile heuristic, optimal
extern const PlannerDescriptor weighted_astar;       // the paper's "improved A*" (Liao et al.)
extern const PlannerDescriptor bidirectional_astar;  // the paper's "BA*"
extern const PlannerDescriptor alternating_bidirectional_astar;  // "improved BA*" (Li 2022)
extern const PlannerDescriptor vns_bastar;                       // the paper's VNS-BA*
extern const PlannerDescriptor jps;  // Jump Point Search: optimal like A* at a fraction of its
                                     // time; 8-neighbourhood and corner_policy never only
}  // namespace planners

// Which planner: a handle on its registered descriptor (planner_registry.hpp), compared by
// identity. Default-constructed it names no planner, which validate() refuses.
class PlannerKind {
 public:
  constexpr PlannerKind() = default;
  constexpr explicit PlannerKind(const PlannerDescriptor* descriptor) : descriptor_(descriptor) {}
  // nullptr for the default-constructed kind.
  const PlannerDescriptor* descriptor() const { return descriptor_; }

  friend bool operator==(PlannerKind a, PlannerKind b) { return a.descriptor_ == b.descriptor_; }
  friend bool operator!=(PlannerKind a, PlannerKind b) { return !(a == b); }
  // In registration order (the paper's table order), so that maps keyed by planner list them so.
  friend bool operator<(PlannerKind a, PlannerKind b);

  static const PlannerKind kAStar;
  static const PlannerKind kWeightedAStar;
  static const PlannerKind kBidirectionalAStar;
  static const PlannerKind kAlternatingBidirectionalAStar;
  static const PlannerKind kVnsBaStar;
  static const PlannerKind kJps;

 private:
  const PlannerDescriptor* descriptor_ = nullptr;
};
inline constexpr PlannerKind PlannerKind::kAStar{&planners::astar};
inline constexpr PlannerKind PlannerKind::kWeightedAStar{&planners::weighted_astar};
inline constexpr PlannerKind PlannerKind::kBidirectionalAStar{&planners::bidirectional_astar};
inline constexpr PlannerKind PlannerKind::kAlternatingBidirectionalAStar{
    &planners::alternating_bidirectional_astar};
inline constexpr PlannerKind PlannerKind::kVnsBaStar{&planners::vns_bastar};
inline constexpr PlannerKind PlannerKind::kJps{&planners::jps};

// The planner's name ("unknown" for the default-constructed kind); test output prints it too.
std::string_view to_string(PlannerKind kind);
std::ostream& operator<<(std::ostream& out, PlannerKind kind);
// Whether a planner searches with these moves (its PlannerCapabilities): jps only with the
// 8-neighbourhood and corner policy never (its jump rules are those of that graph); every other
// planner with all of them. validate() refuses the rest.
bool supports(PlannerKind kind, Neighborhood neighborhood);
bool supports(PlannerKind kind, CornerPolicy policy);
// Whether a planner plans with cell costs (cost_weight > 0): every planner but jps, whose
// symmetry pruning holds only where every move of a kind costs the same.
bool supports_costs(PlannerKind kind);
std::optional<PlannerKind> planner_kind_from_string(std::string_view name);
// All planners, in the paper's table order.
const std::vector<PlannerKind>& all_planner_kinds();

// The range of a numeric option: the one place validate(), the node's config, request overrides
// and the tools read it from. Every range keeps a plan's memory and time bounded (a sample_step
// of 1e-6 cells asked for billions of spline samples).
struct OptionRange {
  const char* key;   // the option's name, as in the config file
  const char* unit;  // "cells", "seconds", or "" for a plain number
  double min;
  double max;
  bool min_excluded;  // (min, max] instead of [min, max]

  bool contains(double v) const {
    return std::isfinite(v) && (min_excluded ? v > min : v >= min) && v <= max;
  }
  // "a number of cells in [0.05, 10]" (what a config error message expects).
  std::string describe() const;
};
inline constexpr OptionRange kOmegaRange{"omega", "", 0.0, 1e6, false};
inline constexpr OptionRange kEtaRange{"eta", "", 0.0, 1e6, false};
inline constexpr OptionRange kSmoothingDistanceRange{"smoothing_distance", "cells", 0.0, 1e6, true};
// Spline samples at most this far apart: at 0.05 cells a corner of d cells gives about 90 d
// samples, so a path never holds more than a few dozen points per cell of its length.
inline constexpr OptionRange kSampleStepRange{"sample_step", "cells", 0.05, 10.0, false};
// 0 means unlimited.
inline constexpr OptionRange kMaxPlanningTimeRange{"max_planning_time", "seconds", 0.0, 3600.0,
                                                   false};
// The relax smoother (postprocess.hpp relax_path). Each iteration moves every interior point by
// smoothness * (the sum of its neighbours - 2 * itself), closeness * (where the planned path had
// it - itself) and smoother_cost * cost_weight * (minus the cost gradient, per cell). smoothness
// 0.5 puts a point at its neighbours' middle; above it the move is over-relaxed (successive
// over-relaxation), which straightens long stretches in fewer iterations, and 2 * smoothness +
// closeness must stay below 2 (validate() checks the sum) or each iteration overshoots further.
inline constexpr OptionRange kSmootherSmoothnessRange{"smoother_smoothness", "", 0.0, 0.99, true};
inline constexpr OptionRange kSmootherClosenessRange{"smoother_closeness", "", 0.0, 1.0, false};
inline constexpr OptionRange kSmootherCostRange{"smoother_cost", "", 0.0, 100.0, false};
// Whole iterations over the path; each costs a few short line-of-sight and clearance checks per
// point that moves.
inline constexpr OptionRange kSmootherIterationsRange{"smoother_iterations", "", 1.0, 10000.0,
                                                      false};

// Move cost = length * (1 + cost_weight * c), c in [0, 1) (docs/algorithm.md section 8); 0 = the
// paper's binary grid. 100 already makes a cell of cost 0.99 a hundred times dearer than free.
inline constexpr OptionRange kCostWeightRange{"cost_weight", "", 0.0, 1000.0, false};
// How far the planner may move a blocked goal or start (docs/algorithm.md section 8); 0 = exact.
// The nearest free cell is searched in a disc of this radius, so it stays small.
inline constexpr OptionRange kToleranceRange{"tolerance", "metres", 0.0, 100.0, false};

// The path smoother after pruning and the paper's corner smoothing.
enum class PathSmoother {
  kNone,   // "none": the path of sections 4 and 5 as it is (the paper)
  kRelax,  // "relax": relax_path (postprocess.hpp), cost-aware, clearance never lowered
};
std::string_view to_string(PathSmoother smoother);
std::optional<PathSmoother> path_smoother_from_string(std::string_view name);

struct PlannerOptions {
  PlannerKind planner = PlannerKind::kVnsBaStar;
  // VNS-BA*'s own options (planners/vns_bastar.cpp), which the other planners do not read.
  double omega = 0.5;  // weight of dist(n, opposite_current) in p(n); kOmegaRange
  double eta = 0.5;    // weight of dist(n, opposite_start) in p(n); kEtaRange
  Neighborhood neighborhood = Neighborhood::kEightElevenThirteen;
  CornerPolicy corner_policy = CornerPolicy::kNever;
  bool prune = true;                // polyline pruning (section 4)
  bool smooth = true;               // cubic-spline corner smoothing (section 5); needs prune
                                    // or works on the raw path's corners when prune is off
  double smoothing_distance = 1.5;  // cells, kSmoothingDistanceRange
  double sample_step = 0.25;        // cells, kSampleStepRange
  // Wall-clock budget of one plan() call (budget.hpp says which phases it stops); zero means
  // unlimited (at most kMaxPlanningTimeRange; negative is refused).
  std::chrono::microseconds max_planning_time{0};
  bool record_expansions = false;  // fill PlanResult::expanded_* (for debug pictures)
  // Also run optimal A* on the same query to fill Metrics::length_ratio (costs a second search).
  bool compute_length_ratio = false;
  // docs/algorithm.md section 8; every "off" value (0) gives the binary behaviour of sections 1-7.
  double cost_weight = 0.0;      // kCostWeightRange
  double goal_tolerance = 0.0;   // metres, kToleranceRange: plan to the nearest free cell within
                                 // this of a blocked (or outside) goal
  double start_tolerance = 0.0;  // metres, kToleranceRange: likewise for a start blocked by
                                 // inflation only
  // The relax smoother (kNone: the paper's path, unchanged). Weights and iterations: the
  // kSmoother*Range entries above.
  PathSmoother smoother = PathSmoother::kNone;
  double smoother_smoothness = 0.9;
  double smoother_closeness = 0.0;
  double smoother_cost = 0.1;
  int smoother_iterations = 10;
};

// The planner `planner.name: auto` runs, chosen by measurement (`vnsba_bench costs`, the table
// "Choosing the cost-aware planner of auto"): jps, the fastest exact planner, wherever it can plan
// with these options (uniform costs: cost_weight 0; the 8-neighbourhood; corner_policy never);
// otherwise kCostAwareChoice: with pruning, smoothing and relax, BA* took 0.92 of A*'s time per
// query (median) on the demo's routes and the OctoMap slices and 0.83 on the Moving AI maps
// (0.67-0.98 per map class), for paths of 0.999 A*'s length and 0.98-1.00 its turning. A*'s
// search stays the one that finds the cheapest grid path (the only optimal one); the relax
// smoother may trade that cost for a straighter path (it is not checked against it).
inline constexpr PlannerKind kCostAwareChoice = PlannerKind::kBidirectionalAStar;
PlannerKind recommended_planner(double cost_weight, Neighborhood neighborhood,
                                CornerPolicy corner_policy);

// The paper's configuration of each planner: VNS-BA* with the 8-11-13 neighbourhood, pruning
// and smoothing; the baselines with the 8-neighbourhood and no post-processing.
PlannerOptions default_options(PlannerKind kind);

// Checks ranges and finiteness; the message names the option at fault.
Status validate(const PlannerOptions& options);

// A cost_weight configured for every planner, applied to one that plans on uniform costs only:
// sets it to 0 and returns true (the caller says so), false when nothing changed. How the node
// plans a request that picks jps on a node with costs, and how the benchmarks run jps beside the
// cost-aware planners.
bool drop_unsupported_costs(PlannerOptions& options);

// What a user configured, field by field: every PlannerOptions field except the planner itself,
// unset (std::nullopt) where the user left it to the planner's paper configuration. Units and
// ranges as in PlannerOptions; make_options does not check them (validate() and Planner::plan
// do).
struct PlannerSettings {
  std::optional<double> omega;
  std::optional<double> eta;
  std::optional<Neighborhood> neighborhood;
  std::optional<CornerPolicy> corner_policy;
  std::optional<bool> prune;
  std::optional<bool> smooth;
  std::optional<double> smoothing_distance;  // cells
  std::optional<double> sample_step;         // cells
  std::optional<std::chrono::microseconds> max_planning_time;
  std::optional<bool> record_expansions;
  std::optional<bool> compute_length_ratio;
  std::optional<double> cost_weight;
  std::optional<double> goal_tolerance;   // metres
  std::optional<double> start_tolerance;  // metres
  std::optional<PathSmoother> smoother;
  std::optional<double> smoother_smoothness;
  std::optional<double> smoother_closeness;
  std::optional<double> smoother_cost;
  std::optional<int> smoother_iterations;
};

// The options of a run: default_options(kind), then every setting that is set.
PlannerOptions make_options(PlannerKind kind, const PlannerSettings& settings);

// The name of that choice wherever a planner is named (planner.name, a request's planner, a Nav2
// planner_id, --planner), and every name a planner field accepts, for messages:
// "auto, astar, weighted_astar, ...".
inline constexpr std::string_view kAutoPlannerName = "auto";
std::string accepted_planner_names();

// What `planner.name: auto` adds to what a user configured: pruning and smoothing on unless set
// (jps and astar have them off in the paper's configuration; auto was measured with them on).
PlannerSettings with_auto_defaults(PlannerSettings settings);
// The options of an auto run: recommended_planner for the cost_weight and moves the settings give
// (a planner that supports them all decides those), with_auto_defaults.
PlannerOptions make_auto_options(const PlannerSettings& settings);

}  // namespace vnsba::core
