// jps: Jump Point Search (jps.hpp), optimal like A* on the 8-neighbourhood without corner
// cutting and on uniform costs, which its jump rules assume.
#include "jps.hpp"

#include "search.hpp"
#include "vnsba/core/planner_registry.hpp"

namespace vnsba::core::planners {

namespace {  // names unique among core's files (the unity build batches them)

detail::SearchOutcome search_jps(const detail::SearchRequest& r) {
  detail::JpsOutcome jps =
      detail::jps_search(r.map, r.sparse, r.start, r.goal, r.budget,
                         r.options.record_expansions ? r.expanded_forward : nullptr);
  detail::SearchOutcome out;
  out.code = jps.code;
  out.path = std::move(jps.path);
  out.expanded = jps.expanded;
  return out;
}

}  // namespace

extern const PlannerDescriptor jps{
    "jps",
    "JPS",
    "Jump Point Search: optimal like A* at a fraction of its time; 8-neighbourhood, corners never "
    "cut, uniform costs",
    {/*long_moves=*/false, /*corner_cutting=*/false, /*costs=*/false,
     /*optimal_on_baseline=*/true, "it searches the 8-neighbourhood",
     "its jump rules need both cells beside a diagonal move free",
     "its jump rules hold only on a grid of uniform costs"},
    nullptr,
    0,
    baseline_configuration,
    nullptr,
    search_jps,
};

}  // namespace vnsba::core::planners
