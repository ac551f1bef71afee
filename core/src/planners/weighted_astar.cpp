// weighted_astar: the paper's "improved A*" (Liao et al.), A* on the density-weighted heuristic
// towards the goal (omega 1, eta 0: no pull towards the start).
#include "search.hpp"
#include "vnsba/core/planner_registry.hpp"

namespace vnsba::core::planners {

namespace {  // names unique among core's files (the unity build batches them)

detail::SearchOutcome search_weighted_astar(const detail::SearchRequest& r) {
  return detail::with_move_cost(r, [](const detail::SearchRequest& r, const auto& move_cost) {
    const detail::DensityWeightedHeuristic h{&r.map, &r.goal, r.goal,
                                             1.0,    0.0,     r.options.corner_policy};
    return detail::search_unidirectional(r.map, r.states, r.forward, r.start, r.goal, h, move_cost,
                                         r.config(), r.budget, r.expanded_forward);
  });
}

}  // namespace

extern const PlannerDescriptor weighted_astar{
    "weighted_astar",
    "improved A*",
    "the paper's improved A*: A* on a heuristic weighted by the obstacle density towards the goal",
    searches_every_graph(/*exact=*/false),
    nullptr,
    0,
    baseline_configuration,
    nullptr,
    search_weighted_astar,
};

}  // namespace vnsba::core::planners
