// The planners by name: each one is a PlannerDescriptor, defined in its own file under
// core/src/planners/ (its search, its paper configuration, the options it owns and how it checks
// them, and the words the docs and messages use for it), and listed once in
// core/src/planner_registry.cpp. Everything that offers a choice of planner (validate(), the
// node's config and requests, vnsba_plan, vnsba_bench) reads this list: a new planner is one new
// file and one line there.
//
//   for (const PlannerDescriptor* planner : registered_planners())
//     std::printf("%s: %s\n", planner->name.data(), planner->summary.data());
//   const PlannerDescriptor* jps = find_planner("jps");  // nullptr for an unknown name
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "vnsba/core/planner_options.hpp"

namespace vnsba::core {

namespace detail {
struct SearchRequest;  // search.hpp: what one search is given
struct SearchOutcome;  // search.hpp: what it finds
}  // namespace detail

// What a planner searches with beyond the paper's baseline graph (the 8-neighbourhood, corners
// never cut, every move of a kind the same cost). validate() and the node's config refuse options
// a planner does not support, with the planner's own reason.
struct PlannerCapabilities {
  bool long_moves;      // the 8-11-13 neighbourhood
  bool corner_cutting;  // corner_policy touch and always
  bool costs;           // cost_weight > 0 (section 8 of the algorithm)
  // Finds a shortest path on the baseline graph (the published optima of the Moving AI
  // benchmark are lengths on it).
  bool optimal_on_baseline;
  // Why the planner lacks a capability, in the words a message gives after the planner's name
  // ("jps (its jump rules ...)"); empty where it has it.
  std::string_view without_long_moves;
  std::string_view without_corner_cutting;
  std::string_view without_costs;
};

// A planner that searches every graph the options can ask for: both neighbourhoods, every corner
// policy, cell costs. `exact`: it also finds the shortest path on the baseline graph.
constexpr PlannerCapabilities searches_every_graph(bool exact) {
  return {true, true, true, exact, "", "", ""};
}

// A numeric option only some planners read: the range (its key and unit) and the setting it
// fills. The node's config reads the key under `planner:` and checks the range.
struct OwnOption {
  const OptionRange* range;
  std::optional<double> PlannerSettings::*setting;
  double PlannerOptions::*option;
};

// A problem with options only this planner checks, in the two forms messages take: validate()'s
// "omega and eta must not both be 0 for vns_bastar (its heuristic would vanish)" (keys, rule)
// and the config's "planner.omega, planner.eta: found both 0, expected at least one > 0 for
// vns_bastar (its heuristic would vanish)" (keys, found_expected).
struct OptionProblem {
  std::vector<std::string_view> keys;
  std::string rule;            // "must not both be 0"
  std::string found_expected;  // "found both 0, expected at least one > 0"
  std::string why;             // "its heuristic would vanish"
};

struct PlannerDescriptor {
  std::string_view name;        // planner.name, a request's planner, --planner, file names
  std::string_view paper_name;  // as the paper's tables call it ("VNS-BA*")
  std::string_view summary;     // one line for --help and the docs
  PlannerCapabilities can;
  const OwnOption* own_options;  // own_option_count of them (nullptr when none)
  size_t own_option_count;
  // The paper's configuration of this planner, written over PlannerOptions{} (the planner field
  // already set).
  void (*paper_configuration)(PlannerOptions& options);
  // Checks the options only this planner reads, beyond their ranges (may be nullptr). The ranges
  // of every planner's own options are checked whichever planner runs (a request that switches
  // planners keeps them).
  void (*check_own_options)(const PlannerOptions& options, std::vector<OptionProblem>& problems);
  // The search between two free cells of the map; Planner::plan does the rest (endpoints,
  // pruning, smoothing).
  detail::SearchOutcome (*search)(const detail::SearchRequest& request);
  // Whether the search reads the map's obstacle density (GridMap::blocked_in_rect, whose table
  // the first reader builds): Planner::prepare builds it before the first query.
  bool reads_obstacle_density = false;
};

// The paper's configuration of its baselines (A*, improved A*, BA*, improved BA*) and of jps:
// the 8-neighbourhood and the raw path, neither pruned nor smoothed.
void baseline_configuration(PlannerOptions& options);

// Every planner, in the paper's table order (jps last).
const std::vector<const PlannerDescriptor*>& registered_planners();
// Every registered planner's own options, once per key (two planners may share one), in
// registration order: what validate() range-checks, make_options() sets and the node's config
// reads, whichever planner runs.
const std::vector<const OwnOption*>& all_own_options();
// The planner of that name, nullptr when there is none.
const PlannerDescriptor* find_planner(std::string_view name);

}  // namespace vnsba::core
