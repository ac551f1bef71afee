// vns_bastar: the paper's VNS-BA*. Two searches in strict alternation on the density-weighted
// heuristic p(n) with its weights omega and eta (the options only this planner reads), the
// 8-11-13 neighbourhood guided by the opposite search's current node, then polyline pruning and
// cubic-spline corner smoothing.
#include <iterator>

#include "search.hpp"
#include "vnsba/core/planner_registry.hpp"

namespace vnsba::core::planners {

namespace {  // names unique among core's files (the unity build batches them)

detail::SearchOutcome search_vns_bastar(const detail::SearchRequest& r) {
  return detail::with_move_cost(r, [](const detail::SearchRequest& r, const auto& move_cost) {
    return detail::search_density_weighted_bidirectional(
        r, move_cost, r.options.omega, r.options.eta, detail::MeetingRule::kGenerateClosedByOther);
  });
}

void configure_vns_bastar(PlannerOptions& options) {
  options.neighborhood = Neighborhood::kEightElevenThirteen;
  options.prune = true;
  options.smooth = true;
}

void check_vns_bastar_options(const PlannerOptions& options, std::vector<OptionProblem>& problems) {
  if (options.omega == 0.0 && options.eta == 0.0)
    problems.push_back({{kOmegaRange.key, kEtaRange.key},
                        "must not both be 0",
                        "found both 0, expected at least one > 0",
                        "its heuristic would vanish"});
}

constexpr OwnOption kVnsBastarOptions[] = {
    {&kOmegaRange, &PlannerSettings::omega, &PlannerOptions::omega},
    {&kEtaRange, &PlannerSettings::eta, &PlannerOptions::eta},
};

}  // namespace

extern const PlannerDescriptor vns_bastar{
    "vns_bastar",
    "VNS-BA*",
    "the paper's VNS-BA*: bidirectional, density-weighted (omega, eta), 8-11-13 moves, pruned and "
    "smoothed",
    searches_every_graph(/*exact=*/false),
    kVnsBastarOptions,
    std::size(kVnsBastarOptions),
    configure_vns_bastar,
    check_vns_bastar_options,
    search_vns_bastar,
    /*reads_obstacle_density=*/true,
};

}  // namespace vnsba::core::planners
