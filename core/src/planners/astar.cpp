// astar: classic A* with the octile heuristic, the optimal baseline of the paper's tables.
#include "search.hpp"
#include "vnsba/core/planner_registry.hpp"

namespace vnsba::core::planners {

namespace {  // names unique among core's files (the unity build batches them)

detail::SearchOutcome search_astar(const detail::SearchRequest& r) {
  return detail::with_move_cost(r, [](const detail::SearchRequest& r, const auto& move_cost) {
    return detail::search_unidirectional(r.map, r.states, r.forward, r.start, r.goal,
                                         detail::OctileHeuristic{&r.goal}, move_cost, r.config(),
                                         r.budget, r.expanded_forward);
  });
}

}  // namespace

extern const PlannerDescriptor astar{
    "astar",
    "A*",
    "classic A* with the octile heuristic: the cheapest grid path (optimal)",
    searches_every_graph(/*exact=*/true),
    nullptr,
    0,
    baseline_configuration,
    nullptr,
    search_astar,
};

}  // namespace vnsba::core::planners
