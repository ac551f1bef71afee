// The planner registry (planner_registry.hpp): every planner is described once, and what each
// descriptor claims (its names, its capabilities and their reasons, its optimality, its paper
// configuration) is what the planner does, checked against validate() and a plain Dijkstra.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <string>

#include "core/test_support.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/core/planner_options.hpp"
#include "vnsba/core/planner_registry.hpp"

namespace vnsba::core {
namespace {

TEST(PlannerRegistry, EveryPlannerIsRegisteredOnceAndFoundByItsName) {
  const auto& planners = registered_planners();
  ASSERT_FALSE(planners.empty());
  std::set<std::string> names, paper_names;
  const std::string accepted = accepted_planner_names();
  for (const PlannerDescriptor* planner : planners) {
    const std::string name(planner->name);
    SCOPED_TRACE(name);
    EXPECT_TRUE(names.insert(name).second) << "registered twice";
    EXPECT_TRUE(paper_names.insert(std::string(planner->paper_name)).second);
    EXPECT_FALSE(planner->summary.empty());
    EXPECT_EQ(find_planner(name), planner);
    const auto kind = planner_kind_from_string(name);
    ASSERT_TRUE(kind.has_value());
    EXPECT_EQ(kind->descriptor(), planner);
    EXPECT_EQ(to_string(*kind), name);
    EXPECT_NE(accepted.find(name), std::string::npos) << accepted;
    // Its paper configuration names it and is valid as it is.
    const PlannerOptions paper = default_options(*kind);
    EXPECT_EQ(paper.planner, *kind);
    EXPECT_TRUE(validate(paper).is_ok()) << validate(paper).message;
  }
  EXPECT_EQ(all_planner_kinds().size(), planners.size());
  EXPECT_EQ(find_planner("dijkstra"), nullptr);
  // The order of the registration is the order of a map keyed by planner.
  for (size_t i = 1; i < all_planner_kinds().size(); ++i)
    EXPECT_TRUE(all_planner_kinds()[i - 1] < all_planner_kinds()[i]);
}

// A planner that lacks a capability says why, and validate() refuses options that need it with
// that reason; one that has it accepts them.
TEST(PlannerRegistry, EachCapabilityIsWhatValidateAccepts) {
  for (const PlannerDescriptor* planner : registered_planners()) {
    SCOPED_TRACE(std::string(planner->name));
    const PlannerKind kind(planner);
    struct Need {
      bool has;
      std::string_view reason;
      void (*apply)(PlannerOptions&);
      const char* key;
    };
    const Need needs[] = {
        {planner->can.long_moves, planner->can.without_long_moves,
         [](PlannerOptions& o) { o.neighborhood = Neighborhood::kEightElevenThirteen; },
         "neighborhood"},
        {planner->can.corner_cutting, planner->can.without_corner_cutting,
         [](PlannerOptions& o) { o.corner_policy = CornerPolicy::kTouch; }, "corner_policy"},
        {planner->can.costs, planner->can.without_costs,
         [](PlannerOptions& o) { o.cost_weight = 2.0; }, "cost_weight"},
    };
    for (const Need& need : needs) {
      SCOPED_TRACE(need.key);
      EXPECT_EQ(need.reason.empty(), need.has) << "a reason exactly where it is lacking";
      PlannerOptions options = default_options(kind);
      need.apply(options);
      const Status status = validate(options);
      EXPECT_EQ(status.is_ok(), need.has) << status.message;
      if (!need.has) {
        EXPECT_NE(status.message.find(need.key), std::string::npos) << status.message;
        EXPECT_NE(status.message.find(std::string(need.reason)), std::string::npos)
            << status.message;
      }
    }
  }
}

// What optimal_on_baseline claims (vnsba_plan compares such planners with the Moving AI optima)
// holds against a plain Dijkstra on random maps; the others are at least never shorter.
TEST(PlannerRegistry, APlannerCalledOptimalFindsDijkstrasCost) {
  std::mt19937 rng(46);
  for (int trial = 0; trial < 30; ++trial) {
    const auto map = test::random_shared_map(rng, 24, 18, 0.3);
    ASSERT_TRUE(map);
    const std::vector<Cell> free = test::free_cells(*map);
    if (free.size() < 2) continue;
    std::uniform_int_distribution<size_t> pick(0, free.size() - 1);
    const Cell start = free[pick(rng)], goal = free[pick(rng)];
    const double optimum = test::reference_shortest_cost(*map, start, goal, CornerPolicy::kNever);
    for (const PlannerDescriptor* planner : registered_planners()) {
      SCOPED_TRACE(std::string(planner->name) + " trial " + std::to_string(trial));
      PlannerOptions options = default_options(PlannerKind(planner));
      options.neighborhood = Neighborhood::kEight;
      options.corner_policy = CornerPolicy::kNever;
      const PlanResult r = plan_once(map, {start, goal}, options);
      if (!std::isfinite(optimum)) {
        EXPECT_EQ(r.status.code, StatusCode::kNoValidPath) << r.status.message;
        continue;
      }
      ASSERT_TRUE(r.status.is_ok()) << r.status.message;
      if (planner->can.optimal_on_baseline)
        EXPECT_NEAR(r.metrics.raw_cost_cells, optimum, 1e-6);
      else
        EXPECT_GE(r.metrics.raw_cost_cells, optimum - 1e-6);
    }
  }
}

// The options a planner owns are range-checked whichever planner runs (a request that switches
// planners keeps them), and its own rules apply to it alone.
TEST(PlannerRegistry, OwnOptionsAreCheckedForEveryPlannerAndTheirRulesForTheirOwner) {
  ASSERT_FALSE(all_own_options().empty());
  for (const OwnOption* own : all_own_options()) {
    SCOPED_TRACE(own->range->key);
    for (const PlannerKind kind : all_planner_kinds()) {
      PlannerOptions options = default_options(kind);
      options.*own->option = own->range->max * 2.0 + 1.0;
      const Status status = validate(options);
      EXPECT_FALSE(status.is_ok()) << to_string(kind);
      EXPECT_NE(status.message.find(own->range->key), std::string::npos) << status.message;
      // And make_options sets it for every planner.
      PlannerSettings settings;
      settings.*own->setting = own->range->min + 0.25;
      EXPECT_EQ(make_options(kind, settings).*own->option, own->range->min + 0.25);
    }
  }
  // VNS-BA*'s rule (omega and eta not both 0) is its own.
  for (const PlannerKind kind : all_planner_kinds()) {
    PlannerOptions options = default_options(kind);
    options.omega = 0.0;
    options.eta = 0.0;
    EXPECT_EQ(validate(options).is_ok(), kind != PlannerKind::kVnsBaStar) << to_string(kind);
  }
}

}  // namespace
}  // namespace vnsba::core
