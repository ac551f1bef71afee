// Comparing planner options field by field, for the option tests of core and node.
#pragma once

#include <gtest/gtest.h>

#include "vnsba/core/planner_options.hpp"

namespace vnsba::test {

// Every field of PlannerOptions, so that a test fails when a field is added there but not to
// PlannerSettings and make_options (the list below must then grow too).
inline void ExpectSameOptions(const core::PlannerOptions& a, const core::PlannerOptions& b) {
  EXPECT_EQ(a.planner, b.planner);
  EXPECT_EQ(a.omega, b.omega);
  EXPECT_EQ(a.eta, b.eta);
  EXPECT_EQ(a.neighborhood, b.neighborhood);
  EXPECT_EQ(a.corner_policy, b.corner_policy);
  EXPECT_EQ(a.prune, b.prune);
  EXPECT_EQ(a.smooth, b.smooth);
  EXPECT_EQ(a.smoothing_distance, b.smoothing_distance);
  EXPECT_EQ(a.sample_step, b.sample_step);
  EXPECT_EQ(a.max_planning_time.count(), b.max_planning_time.count());
  EXPECT_EQ(a.record_expansions, b.record_expansions);
  EXPECT_EQ(a.compute_length_ratio, b.compute_length_ratio);
  EXPECT_EQ(a.cost_weight, b.cost_weight);
  EXPECT_EQ(a.goal_tolerance, b.goal_tolerance);
  EXPECT_EQ(a.start_tolerance, b.start_tolerance);
  EXPECT_EQ(a.smoother, b.smoother);
  EXPECT_EQ(a.smoother_smoothness, b.smoother_smoothness);
  EXPECT_EQ(a.smoother_closeness, b.smoother_closeness);
  EXPECT_EQ(a.smoother_cost, b.smoother_cost);
  EXPECT_EQ(a.smoother_iterations, b.smoother_iterations);
}

}  // namespace vnsba::test
