// alternating_bidirectional_astar: the paper's "improved BA*" (Li et al. 2022), two searches on
// the density-weighted heuristic, each towards the other's current node, meeting only where one
// closes a cell the other has closed.
#include "search.hpp"
#include "vnsba/core/planner_registry.hpp"

namespace vnsba::core::planners {

namespace {  // names unique among core's files (the unity build batches them)

detail::SearchOutcome search_alternating_bidirectional_astar(const detail::SearchRequest& r) {
  return detail::with_move_cost(r, [](const detail::SearchRequest& r, const auto& move_cost) {
    const CornerPolicy policy = r.options.corner_policy;
    const detail::DensityWeightedHeuristic forward{&r.map, &r.current[1], r.goal, 1.0, 0.0, policy};
    const detail::DensityWeightedHeuristic backward{&r.map, &r.current[0], r.start,
                                                    1.0,    0.0,           policy};
    return detail::search_bidirectional(r.map, r.states, r.forward, r.backward, r.start, r.goal,
                                        r.current, forward, backward, move_cost,
                                        detail::MeetingRule::kCloseClosedByOther, r.config(),
                                        r.budget, r.expanded_forward, r.expanded_backward);
  });
}

}  // namespace

extern const PlannerDescriptor alternating_bidirectional_astar{
    "alternating_bidirectional_astar",
    "improved BA*",
    "the paper's improved BA*: two density-weighted searches, each towards the other's current "
    "node",
    {/*long_moves=*/true, /*corner_cutting=*/true, /*costs=*/true,
     /*optimal_on_baseline=*/false, "", "", ""},
    nullptr,
    0,
    baseline_configuration,
    nullptr,
    search_alternating_bidirectional_astar,
};

}  // namespace vnsba::core::planners
