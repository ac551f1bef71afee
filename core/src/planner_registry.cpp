#include "vnsba/core/planner_registry.hpp"

#include <algorithm>

namespace vnsba::core {

namespace {

// The registration: one line per planner, in the order of the paper's tables (jps, ours, last).
// Each descriptor lives in core/src/planners/<name>.cpp.
#define VNSBA_REGISTERED_PLANNERS(PLANNER) \
  PLANNER(astar)                           \
  PLANNER(weighted_astar)                  \
  PLANNER(bidirectional_astar)             \
  PLANNER(alternating_bidirectional_astar) \
  PLANNER(vns_bastar)                      \
  PLANNER(jps)

}  // namespace

namespace planners {
#define VNSBA_DECLARE_PLANNER(name) extern const PlannerDescriptor name;
VNSBA_REGISTERED_PLANNERS(VNSBA_DECLARE_PLANNER)
#undef VNSBA_DECLARE_PLANNER
}  // namespace planners

void baseline_configuration(PlannerOptions& options) {
  options.neighborhood = Neighborhood::kEight;
  options.prune = false;
  options.smooth = false;
}

const std::vector<const PlannerDescriptor*>& registered_planners() {
#define VNSBA_LIST_PLANNER(name) &planners::name,
  static const std::vector<const PlannerDescriptor*> all = {
      VNSBA_REGISTERED_PLANNERS(VNSBA_LIST_PLANNER)};
#undef VNSBA_LIST_PLANNER
  return all;
}

const std::vector<const OwnOption*>& all_own_options() {
  static const std::vector<const OwnOption*> all = [] {
    std::vector<const OwnOption*> out;
    for (const PlannerDescriptor* planner : registered_planners())
      for (size_t i = 0; i < planner->own_option_count; ++i) {
        const OwnOption* own = &planner->own_options[i];
        const bool seen = std::any_of(out.begin(), out.end(), [&](const OwnOption* other) {
          return std::string_view(other->range->key) == own->range->key;
        });
        if (!seen) out.push_back(own);
      }
    return out;
  }();
  return all;
}

const PlannerDescriptor* find_planner(std::string_view name) {
  for (const PlannerDescriptor* planner : registered_planners())
    if (planner->name == name) return planner;
  return nullptr;
}

}  // namespace vnsba::core
