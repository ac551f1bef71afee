// Planner options: names, the paper configurations, and make_options, the one function that turns
// what a user configured into the options of a run.
#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include "core/options_support.hpp"
#include "vnsba/core/planner_options.hpp"

namespace vnsba::core {
namespace {

using std::chrono::microseconds;
using test::ExpectSameOptions;

// One setting: how to set it, and what it does to a planner's options. Each value differs from
// every planner's paper configuration where the field does not depend on the planner; the
// planner-dependent ones (neighborhood, prune, smooth) are listed with both values.
struct OneSetting {
  std::string name;
  std::function<void(PlannerSettings&)> set;
  std::function<void(PlannerOptions&)> expect;
};

std::vector<OneSetting> every_setting() {
  return {
      {"omega", [](auto& s) { s.omega = 2.0; }, [](auto& o) { o.omega = 2.0; }},
      {"eta", [](auto& s) { s.eta = 3.0; }, [](auto& o) { o.eta = 3.0; }},
      {"neighborhood 8", [](auto& s) { s.neighborhood = Neighborhood::kEight; },
       [](auto& o) { o.neighborhood = Neighborhood::kEight; }},
      {"neighborhood 8-11-13", [](auto& s) { s.neighborhood = Neighborhood::kEightElevenThirteen; },
       [](auto& o) { o.neighborhood = Neighborhood::kEightElevenThirteen; }},
      {"corner_policy", [](auto& s) { s.corner_policy = CornerPolicy::kTouch; },
       [](auto& o) { o.corner_policy = CornerPolicy::kTouch; }},
      {"prune false", [](auto& s) { s.prune = false; }, [](auto& o) { o.prune = false; }},
      {"prune true", [](auto& s) { s.prune = true; }, [](auto& o) { o.prune = true; }},
      {"smooth false", [](auto& s) { s.smooth = false; }, [](auto& o) { o.smooth = false; }},
      {"smooth true", [](auto& s) { s.smooth = true; }, [](auto& o) { o.smooth = true; }},
      {"smoothing_distance", [](auto& s) { s.smoothing_distance = 2.5; },
       [](auto& o) { o.smoothing_distance = 2.5; }},
      {"sample_step", [](auto& s) { s.sample_step = 0.5; }, [](auto& o) { o.sample_step = 0.5; }},
      {"max_planning_time", [](auto& s) { s.max_planning_time = microseconds(250000); },
       [](auto& o) { o.max_planning_time = microseconds(250000); }},
      {"record_expansions", [](auto& s) { s.record_expansions = true; },
       [](auto& o) { o.record_expansions = true; }},
      {"compute_length_ratio", [](auto& s) { s.compute_length_ratio = true; },
       [](auto& o) { o.compute_length_ratio = true; }},
      {"smoother", [](auto& s) { s.smoother = PathSmoother::kRelax; },
       [](auto& o) { o.smoother = PathSmoother::kRelax; }},
      {"smoother_smoothness", [](auto& s) { s.smoother_smoothness = 0.5; },
       [](auto& o) { o.smoother_smoothness = 0.5; }},
      {"smoother_closeness", [](auto& s) { s.smoother_closeness = 0.3; },
       [](auto& o) { o.smoother_closeness = 0.3; }},
      {"smoother_cost", [](auto& s) { s.smoother_cost = 4.0; },
       [](auto& o) { o.smoother_cost = 4.0; }},
      {"smoother_iterations", [](auto& s) { s.smoother_iterations = 77; },
       [](auto& o) { o.smoother_iterations = 77; }},
  };
}

TEST(PlannerOptions, NothingConfiguredIsThePapersConfiguration) {
  for (PlannerKind kind : all_planner_kinds()) {
    SCOPED_TRACE(std::string(to_string(kind)));
    ExpectSameOptions(make_options(kind, {}), default_options(kind));
  }
}

TEST(PlannerOptions, EachSettingChangesOnlyItsField) {
  for (PlannerKind kind : all_planner_kinds()) {
    for (const OneSetting& one : every_setting()) {
      SCOPED_TRACE(std::string(to_string(kind)) + ", " + one.name);
      PlannerSettings settings;
      one.set(settings);
      PlannerOptions expected = default_options(kind);
      one.expect(expected);
      ExpectSameOptions(make_options(kind, settings), expected);
    }
  }
}

// The configured planner and every other one as an override: each configured field is kept,
// every other field is the chosen planner's paper configuration.
TEST(PlannerOptions, AnOverrideKeepsEveryConfiguredFieldAndTakesTheRestFromItsPlanner) {
  // Subsets of settings (as a config file would give them): none, each alone, every pair of
  // neighbours in the list, all of them with each planner-dependent value.
  const std::vector<OneSetting> all = every_setting();
  std::vector<std::vector<size_t>> subsets = {{}};
  for (size_t i = 0; i < all.size(); ++i) subsets.push_back({i});
  for (size_t i = 0; i + 1 < all.size(); ++i) subsets.push_back({i, i + 1});
  for (const bool vns_values : {false, true}) {
    std::vector<size_t> everything;
    for (size_t i = 0; i < all.size(); ++i) {
      const bool vns_only = all[i].name == "neighborhood 8-11-13" || all[i].name == "prune true" ||
                            all[i].name == "smooth true";
      const bool baseline_only = all[i].name == "neighborhood 8" || all[i].name == "prune false" ||
                                 all[i].name == "smooth false";
      if ((vns_values && !baseline_only) || (!vns_values && !vns_only)) everything.push_back(i);
    }
    subsets.push_back(everything);
  }
  for (const auto& subset : subsets) {
    PlannerSettings configured;
    std::string names;
    for (size_t i : subset) {
      all[i].set(configured);
      names += all[i].name + "; ";
    }
    for (PlannerKind kind : all_planner_kinds()) {
      SCOPED_TRACE("override " + std::string(to_string(kind)) + " with " + names);
      PlannerOptions expected = default_options(kind);
      for (size_t i : subset) all[i].expect(expected);
      ExpectSameOptions(make_options(kind, configured), expected);
    }
  }
}

TEST(PlannerOptions, MakeOptionsLeavesRangeChecksToValidate) {
  PlannerSettings settings;
  settings.omega = 0.0;
  settings.eta = 0.0;
  // Legal for A* (it ignores the weights), refused for VNS-BA* (its heuristic would vanish).
  EXPECT_TRUE(validate(make_options(PlannerKind::kAStar, settings)).is_ok());
  const Status vns = validate(make_options(PlannerKind::kVnsBaStar, settings));
  EXPECT_FALSE(vns.is_ok());
  EXPECT_NE(vns.message.find("omega and eta"), std::string::npos) << vns.message;
  settings.sample_step = 11.0;
  EXPECT_NE(validate(make_options(PlannerKind::kAStar, settings)).message.find("sample_step"),
            std::string::npos);
}

TEST(PlannerOptions, NamesRoundTrip) {
  ASSERT_EQ(all_planner_kinds().size(), 6u);
  for (PlannerKind kind : all_planner_kinds()) {
    EXPECT_EQ(planner_kind_from_string(to_string(kind)), kind);
  }
  EXPECT_EQ(planner_kind_from_string("vns_bastar"), PlannerKind::kVnsBaStar);
  EXPECT_EQ(planner_kind_from_string("jps"), PlannerKind::kJps);
  EXPECT_FALSE(planner_kind_from_string("dijkstra").has_value());
}

// Jump Point Search's rules hold for the 8-neighbourhood without corner cutting only: anything
// else is refused, naming the option, and never silently planned on other moves.
TEST(PlannerOptions, JpsRefusesOtherMovesNamingTheOption) {
  PlannerOptions o = default_options(PlannerKind::kJps);
  EXPECT_EQ(o.neighborhood, Neighborhood::kEight);
  EXPECT_EQ(o.corner_policy, CornerPolicy::kNever);
  EXPECT_TRUE(validate(o).is_ok()) << validate(o).message;
  for (auto policy : {CornerPolicy::kTouch, CornerPolicy::kAlways}) {
    o.corner_policy = policy;
    const auto status = validate(o);
    EXPECT_EQ(status.code, StatusCode::kInvalidRequest);
    EXPECT_NE(status.message.find("corner_policy " + std::string(to_string(policy))),
              std::string::npos)
        << status.message;
  }
  o.corner_policy = CornerPolicy::kNever;
  o.neighborhood = Neighborhood::kEightElevenThirteen;
  const auto status = validate(o);
  EXPECT_EQ(status.code, StatusCode::kInvalidRequest);
  EXPECT_NE(status.message.find("neighborhood 8-11-13"), std::string::npos) << status.message;
  // The other planners take every combination.
  for (PlannerKind kind : all_planner_kinds()) {
    if (kind == PlannerKind::kJps) continue;
    PlannerOptions other = default_options(kind);
    other.corner_policy = CornerPolicy::kAlways;
    other.neighborhood = Neighborhood::kEightElevenThirteen;
    EXPECT_TRUE(validate(other).is_ok()) << to_string(kind);
  }
}

}  // namespace
}  // namespace vnsba::core
