// bidirectional_astar: the paper's "BA*", two A* searches in strict alternation, each towards the
// other's root, meeting where one generates a cell the other has closed.
#include "search.hpp"
#include "vnsba/core/planner_registry.hpp"

namespace vnsba::core::planners {

namespace {  // names unique among core's files (the unity build batches them)

detail::SearchOutcome search_bidirectional_astar(const detail::SearchRequest& r) {
  return detail::with_move_cost(r, [](const detail::SearchRequest& r, const auto& move_cost) {
    return detail::search_bidirectional(r.map, r.states, r.forward, r.backward, r.start, r.goal,
                                        r.current, detail::OctileHeuristic{&r.goal},
                                        detail::OctileHeuristic{&r.start}, move_cost,
                                        detail::MeetingRule::kGenerateClosedByOther, r.config(),
                                        r.budget, r.expanded_forward, r.expanded_backward);
  });
}

}  // namespace

extern const PlannerDescriptor bidirectional_astar{
    "bidirectional_astar",
    "BA*",
    "the paper's BA*: two A* searches in alternation, from the start and from the goal",
    searches_every_graph(/*exact=*/false),
    nullptr,
    0,
    baseline_configuration,
    nullptr,
    search_bidirectional_astar,
};

}  // namespace vnsba::core::planners
