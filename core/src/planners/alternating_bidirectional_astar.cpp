// alternating_bidirectional_astar: the paper's "improved BA*" (Li et al. 2022), two searches on
// the density-weighted heuristic, each towards the other's current node, meeting only where one
// closes a cell the other has closed.
#include "search.hpp"
#include "vnsba/core/planner_registry.hpp"

namespace vnsba::core::planners {

namespace {  // names unique among core's files (the unity build batches them)

detail::SearchOutcome search_alternating_bidirectional_astar(const detail::SearchRequest& r) {
  return detail::with_move_cost(r, [](const detail::SearchRequest& r, const auto& move_cost) {
    return detail::search_density_weighted_bidirectional(r, move_cost, /*omega=*/1.0, /*eta=*/0.0,
                                                         detail::MeetingRule::kCloseClosedByOther);
  });
}

}  // namespace

extern const PlannerDescriptor alternating_bidirectional_astar{
    "alternating_bidirectional_astar",
    "improved BA*",
    "the paper's improved BA*: two density-weighted searches, each towards the other's current "
    "node",
    searches_every_graph(/*exact=*/false),
    nullptr,
    0,
    baseline_configuration,
    nullptr,
    search_alternating_bidirectional_astar,
    /*reads_obstacle_density=*/true,
};

}  // namespace vnsba::core::planners
