// Node configuration: YAML loading, defaults and validation (no DDS).
//
// Fixtures live in tests/fixtures/config (VNSBA_FIXTURE_DIR); the shipped config in
// VNSBA_CONFIG_DIR.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "core/options_support.hpp"
#include "node/yaml_values.hpp"
#include "vnsba/node/config.hpp"

namespace {

using std::chrono::microseconds;
using vnsba::core::CornerPolicy;
using vnsba::core::Neighborhood;
using vnsba::core::PlannerKind;
using vnsba::core::PlannerOptions;
using vnsba::node::ConfigResult;
using vnsba::node::dds_topic_name;
using vnsba::node::DebugPublishing;
using vnsba::node::load_config;
using vnsba::node::MapDurability;
using vnsba::node::NodeConfig;
using vnsba::node::parse_config;
using vnsba::test::CollectLeaves;
using vnsba::test::ExpectSameOptions;
using vnsba::test::SameYamlValue;

std::string Fixture(const std::string& name) {
  return std::string(VNSBA_FIXTURE_DIR) + "/config/" + name;
}

std::string DefaultYamlPath() {
  return std::string(VNSBA_CONFIG_DIR) + "/default.yaml";
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// The paper's setting as this test states it: default.yaml's configuration without the robot
// (no radius, inflation, costs or tolerance), planning with vns_bastar and no smoother; the
// node's 5 s planning-time budget holds (see config.hpp). config/paper.yaml must load to it.
NodeConfig PaperSetting() {
  const ConfigResult defaults = vnsba::node::default_config();
  EXPECT_TRUE(defaults.config.has_value()) << (defaults.errors.empty() ? "" : defaults.errors[0]);
  NodeConfig config = *defaults.config;
  config.map.robot_radius = 0.0;
  config.map.inflation_radius = 0.0;
  config.planner.auto_kind = false;
  config.planner.kind = PlannerKind::kVnsBaStar;
  config.planner.settings.smoother = vnsba::core::PathSmoother::kNone;
  config.planner.settings.cost_weight = 0.0;
  config.planner.settings.goal_tolerance = 0.0;
  config.planner.settings.start_tolerance = 0.0;
  EXPECT_EQ(config.planner.options().max_planning_time, std::chrono::seconds(5));
  return config;
}

std::string Joined(const std::vector<std::string>& errors) {
  std::string out;
  for (const std::string& e : errors) out += "\n  " + e;
  return out;
}

// The error that starts with `key` + ": " and contains every one of `parts`; fails otherwise.
::testing::AssertionResult HasError(const ConfigResult& result, const std::string& key,
                                    const std::vector<std::string>& parts = {}) {
  for (const std::string& e : result.errors) {
    if (e.rfind(key + ": ", 0) != 0) continue;
    bool all = true;
    for (const std::string& part : parts) all = all && e.find(part) != std::string::npos;
    if (all) return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure()
         << "no error for '" << key << "' with the expected text; errors:" << Joined(result.errors);
}

void ExpectSameConfig(const NodeConfig& a, const NodeConfig& b) {
  EXPECT_EQ(a.domain_id, b.domain_id);
  EXPECT_EQ(a.ros2_naming, b.ros2_naming);
  EXPECT_EQ(a.frame_id, b.frame_id);
  EXPECT_EQ(a.topics.projected_map, b.topics.projected_map);
  EXPECT_EQ(a.topics.goal_pose, b.topics.goal_pose);
  EXPECT_EQ(a.topics.robot_pose, b.topics.robot_pose);
  EXPECT_EQ(a.topics.plan_request, b.topics.plan_request);
  EXPECT_EQ(a.topics.plan, b.topics.plan);
  EXPECT_EQ(a.topics.plan_status, b.topics.plan_status);
  EXPECT_EQ(a.topics.planner_debug, b.topics.planner_debug);
  EXPECT_EQ(a.topics.octomap, b.topics.octomap);
  EXPECT_EQ(a.ros_namespace, b.ros_namespace);
  EXPECT_EQ(a.discovery_servers, b.discovery_servers);
  EXPECT_EQ(a.topics.plan_raw, b.topics.plan_raw);
  EXPECT_EQ(a.topics.plan_pruned, b.topics.plan_pruned);
  EXPECT_EQ(a.topics.expansions_forward, b.topics.expansions_forward);
  EXPECT_EQ(a.topics.expansions_backward, b.topics.expansions_backward);
  EXPECT_EQ(a.topics.meeting_point, b.topics.meeting_point);
  EXPECT_EQ(a.topics.tf, b.topics.tf);
  EXPECT_EQ(a.topics.tf_static, b.topics.tf_static);
  EXPECT_EQ(a.topics.clock, b.topics.clock);
  EXPECT_EQ(a.robot_pose_source, b.robot_pose_source);
  EXPECT_EQ(a.robot_pose_type, b.robot_pose_type);
  EXPECT_EQ(a.base_frame, b.base_frame);
  EXPECT_EQ(a.transform_tolerance_s, b.transform_tolerance_s);
  EXPECT_EQ(a.use_sim_time, b.use_sim_time);
  EXPECT_EQ(a.map.occupied_threshold, b.map.occupied_threshold);
  EXPECT_EQ(a.map.allow_unknown, b.map.allow_unknown);
  EXPECT_EQ(a.map.inflate_unknown, b.map.inflate_unknown);
  EXPECT_EQ(a.map.robot_radius, b.map.robot_radius);
  EXPECT_EQ(a.map.inflation_radius, b.map.inflation_radius);
  EXPECT_EQ(a.map.cost_scaling_factor, b.map.cost_scaling_factor);
  EXPECT_EQ(a.map.max_cells, b.map.max_cells);
  EXPECT_EQ(a.map_memory_budget_mb, b.map_memory_budget_mb);
  EXPECT_EQ(a.planner.path_spacing, b.planner.path_spacing);
  EXPECT_EQ(a.planner.kind, b.planner.kind);
  EXPECT_EQ(a.planner.auto_kind, b.planner.auto_kind);
  // The same options for the configured planner and for every per-request override.
  ExpectSameOptions(a.planner.options(), b.planner.options());
  for (PlannerKind kind : vnsba::core::all_planner_kinds()) {
    SCOPED_TRACE(std::string(vnsba::core::to_string(kind)));
    ExpectSameOptions(a.planner.options(kind), b.planner.options(kind));
  }
  EXPECT_EQ(a.preempt, b.preempt);
  EXPECT_EQ(a.queue_capacity, b.queue_capacity);
  EXPECT_EQ(a.debug, b.debug);
  EXPECT_EQ(a.log_level, b.log_level);
  EXPECT_EQ(a.slicer.z_min, b.slicer.z_min);
  EXPECT_EQ(a.slicer.z_max, b.slicer.z_max);
  EXPECT_EQ(a.slicer.resolution, b.slicer.resolution);
  EXPECT_EQ(a.slicer.remove_speckles, b.slicer.remove_speckles);
}

// Loads a fixture that must fail; checks the error count.
ConfigResult LoadBad(const std::string& name, size_t expected_errors) {
  ConfigResult result = load_config(Fixture(name));
  EXPECT_FALSE(result.config.has_value()) << name;
  EXPECT_EQ(result.errors.size(), expected_errors) << name << ":" << Joined(result.errors);
  return result;
}

std::string PaperYamlPath() {
  return std::string(VNSBA_CONFIG_DIR) + "/paper.yaml";
}

// What config/default.yaml adds to the paper's setting for a real robot: its radius, the cost
// gradient, cost_weight and the tolerances. Every loaded config starts here.
NodeConfig RobotDefaults() {
  NodeConfig config = PaperSetting();
  config.map.robot_radius = 0.15;
  config.map.inflation_radius = 0.55;
  config.map.cost_scaling_factor = 3.0;
  config.planner.settings.cost_weight = 2.0;
  config.planner.settings.goal_tolerance = 0.25;
  config.planner.settings.start_tolerance = 0.2;
  // name: auto with costs is the cost-aware choice (core::recommended_planner), pruned and
  // smoothed, then relaxed.
  config.planner.auto_kind = true;
  config.planner.kind = vnsba::core::kCostAwareChoice;
  config.planner.settings.smoother = vnsba::core::PathSmoother::kRelax;
  config.planner.settings.smoother_smoothness = 0.9;
  config.planner.settings.smoother_closeness = 0.0;
  config.planner.settings.smoother_cost = 0.1;
  config.planner.settings.smoother_iterations = 10;
  return config;
}

TEST(Config, DefaultYamlLoadsAndEqualsTheDefaultsWithTheRobotKeys) {
  const ConfigResult result = load_config(DefaultYamlPath());
  ASSERT_TRUE(result.errors.empty()) << Joined(result.errors);
  ASSERT_TRUE(result.config.has_value());
  ExpectSameConfig(*result.config, RobotDefaults());
  // The default planner plans with costs, and every planner that supports them gets the same
  // settings through make_options; path_spacing is left to the map's resolution.
  const NodeConfig& c = *result.config;
  EXPECT_TRUE(vnsba::core::supports_costs(c.planner.kind));
  EXPECT_TRUE(vnsba::core::validate(c.planner.options()).is_ok());
  for (PlannerKind kind : vnsba::core::all_planner_kinds()) {
    SCOPED_TRACE(std::string(vnsba::core::to_string(kind)));
    EXPECT_DOUBLE_EQ(c.planner.options(kind).cost_weight, 2.0);
    EXPECT_DOUBLE_EQ(c.planner.options(kind).goal_tolerance, 0.25);
    EXPECT_DOUBLE_EQ(c.planner.options(kind).start_tolerance, 0.2);
  }
  EXPECT_FALSE(c.planner.path_spacing.has_value());
  EXPECT_DOUBLE_EQ(c.planner.path_spacing_for(0.05), 0.05);
  EXPECT_TRUE(vnsba::core::validate(c.map).is_ok());
}

// config/paper.yaml is the paper's binary setting, and paper_config() is that file compiled in.
TEST(Config, PaperYamlLoadsAndEqualsThePaperSetting) {
  const ConfigResult result = load_config(PaperYamlPath());
  ASSERT_TRUE(result.errors.empty()) << Joined(result.errors);
  ASSERT_TRUE(result.config.has_value());
  ExpectSameConfig(*result.config, PaperSetting());
  const ConfigResult built_in = vnsba::node::paper_config();
  ASSERT_TRUE(built_in.config.has_value()) << Joined(built_in.errors);
  EXPECT_EQ(vnsba::node::config_as_yaml(*built_in.config),
            vnsba::node::config_as_yaml(*result.config));
  const PlannerOptions o = result.config->planner.options();
  EXPECT_EQ(o.cost_weight, 0.0);
  EXPECT_EQ(o.goal_tolerance, 0.0);
  EXPECT_EQ(o.start_tolerance, 0.0);
  EXPECT_EQ(result.config->map.inflation_radius, 0.0);
  // Every other line is default.yaml's: the same keys, so paper.yaml documents them too.
  const std::string paper = ReadText(PaperYamlPath());
  for (const char* key : {"inflation_radius:", "cost_scaling_factor:", "cost_weight:",
                          "goal_tolerance:", "start_tolerance:", "path_spacing:"}) {
    EXPECT_NE(paper.find(key), std::string::npos) << key;
  }
}

TEST(Config, DefaultYamlMentionsEveryKey) {
  // The planner-dependent keys are there but commented out (see default.yaml).
  const std::string text = ReadText(DefaultYamlPath());
  for (const char* key : {"domain_id:",
                          "ros2_naming:",
                          "frame_id:",
                          "topics:",
                          "projected_map:",
                          "goal_pose:",
                          "robot_pose:",
                          "plan_request:",
                          "plan:",
                          "plan_status:",
                          "planner_debug:",
                          "octomap:",
                          "map:",
                          "occupied_threshold:",
                          "allow_unknown:",
                          "inflate_unknown:",
                          "robot_radius:",
                          "inflation_radius:",
                          "cost_scaling_factor:",
                          "max_cells:",
                          "memory_budget_mb:",
                          "durability:",
                          "planner:",
                          "name:",
                          "omega:",
                          "eta:",
                          "neighborhood:",
                          "corner_policy:",
                          "prune:",
                          "smooth:",
                          "smoothing_distance:",
                          "sample_step:",
                          "smoother:",
                          "smoother_smoothness:",
                          "smoother_closeness:",
                          "smoother_cost:",
                          "smoother_iterations:",
                          "max_planning_time:",
                          "compute_length_ratio:",
                          "cost_weight:",
                          "goal_tolerance:",
                          "start_tolerance:",
                          "path_spacing:",
                          "requests:",
                          "preempt:",
                          "queue_capacity:",
                          "reply_wait:",
                          "network:",
                          "localhost_only:",
                          "security:",
                          "enable:",
                          "keystore:",
                          "enclave:",
                          "strategy:",
                          "debug:",
                          "publish:",
                          "log_level:",
                          "slicer:",
                          "z_min:",
                          "z_max:",
                          "resolution:",
                          "remove_speckles:"}) {
    EXPECT_NE(text.find(key), std::string::npos) << key;
  }
}

TEST(Config, ChangingOnlyThePlannerNameInDefaultYamlGivesThatPlannersDefaults) {
  std::string text = ReadText(DefaultYamlPath());
  const std::string from = "name: auto";
  const size_t at = text.find(from);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, from.size(), "name: astar");
  const ConfigResult result = parse_config(text, "default.yaml with astar");
  ASSERT_TRUE(result.config.has_value()) << Joined(result.errors);
  EXPECT_EQ(result.config->planner.kind, PlannerKind::kAStar);
  ExpectSameOptions(
      result.config->planner.options(),
      vnsba::core::make_options(PlannerKind::kAStar, RobotDefaults().planner.settings));
  EXPECT_EQ(result.config->planner.options().neighborhood, Neighborhood::kEight);
  EXPECT_FALSE(result.config->planner.options().prune);
  EXPECT_FALSE(result.config->planner.options().smooth);
}

// jps plans on uniform costs only: default.yaml's cost_weight makes `name: jps` alone an error
// naming planner.cost_weight; with cost_weight 0 it loads.
TEST(Config, ChangingThePlannerNameInDefaultYamlToJpsNeedsCostWeightZero) {
  std::string text = ReadText(DefaultYamlPath());
  const std::string from = "name: auto";
  const size_t at = text.find(from);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, from.size(), "name: jps");
  const ConfigResult bad = parse_config(text, "default.yaml with jps");
  EXPECT_FALSE(bad.config.has_value());
  ASSERT_EQ(bad.errors.size(), 1u) << Joined(bad.errors);
  EXPECT_TRUE(HasError(bad, "planner.cost_weight", {"found \"2\"", "expected 0 for jps"}));
  const std::string weight = "cost_weight: 2.0";
  const size_t w = text.find(weight);
  ASSERT_NE(w, std::string::npos);
  text.replace(w, weight.size(), "cost_weight: 0");
  const ConfigResult ok = parse_config(text, "default.yaml with jps, cost_weight 0");
  ASSERT_TRUE(ok.config.has_value()) << Joined(ok.errors);
  EXPECT_EQ(ok.config->planner.kind, PlannerKind::kJps);
}

// planner.name: auto (default.yaml's) picks by the file's options: jps where costs are off and
// its moves allow it, the cost-aware choice otherwise; both pruned and smoothed unless set.
TEST(Config, AutoPicksJpsWithoutCostsAndTheCostAwareChoiceWithThem) {
  struct Case {
    const char* planner_block;
    PlannerKind expected;
  };
  const Case cases[] = {
      {"", vnsba::core::kCostAwareChoice},  // default.yaml's cost_weight 2
      {"  cost_weight: 0\n", PlannerKind::kJps},
      {"  cost_weight: 0\n  corner_policy: touch\n", vnsba::core::kCostAwareChoice},
      {"  cost_weight: 0\n  neighborhood: \"8-11-13\"\n", vnsba::core::kCostAwareChoice},
      {"  name: auto\n  cost_weight: 5\n", vnsba::core::kCostAwareChoice},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.planner_block);
    const ConfigResult r = parse_config(std::string("planner:\n") + c.planner_block);
    ASSERT_TRUE(r.config.has_value()) << Joined(r.errors);
    EXPECT_TRUE(r.config->planner.auto_kind);
    EXPECT_EQ(r.config->planner.kind, c.expected);
    const PlannerOptions o = r.config->planner.options();
    EXPECT_EQ(o.planner, c.expected);
    EXPECT_TRUE(o.prune);
    EXPECT_TRUE(o.smooth);
    EXPECT_TRUE(vnsba::core::validate(o).is_ok()) << vnsba::core::validate(o).message;
    EXPECT_EQ(c.expected,
              vnsba::core::recommended_planner(o.cost_weight, o.neighborhood, o.corner_policy));
  }
  // Pruning or smoothing set in the file is kept; a named planner is not auto.
  const ConfigResult unpruned = parse_config("planner:\n  prune: false\n");
  ASSERT_TRUE(unpruned.config.has_value());
  EXPECT_FALSE(unpruned.config->planner.options().prune);
  EXPECT_TRUE(unpruned.config->planner.options().smooth);
  const ConfigResult named = parse_config("planner:\n  name: astar\n");
  ASSERT_TRUE(named.config.has_value());
  EXPECT_FALSE(named.config->planner.auto_kind);
  EXPECT_FALSE(named.config->planner.options().prune);
  // A misspelt name is refused naming the key and offering auto among the names.
  const ConfigResult bad = parse_config("planner:\n  name: autoo\n");
  EXPECT_FALSE(bad.config.has_value());
  EXPECT_TRUE(HasError(bad, "planner.name", {"\"autoo\"", "auto", "did you mean \"auto\""}));
}

TEST(Config, EmptyFileGivesTheDefaults) {
  for (const char* name : {"empty.yaml", "comments_only.yaml"}) {
    const ConfigResult result = load_config(Fixture(name));
    ASSERT_TRUE(result.config.has_value()) << name << Joined(result.errors);
    EXPECT_TRUE(result.errors.empty());
    ExpectSameConfig(*result.config, RobotDefaults());
  }
  const ConfigResult text = parse_config("");
  ASSERT_TRUE(text.config.has_value());
  ExpectSameConfig(*text.config, RobotDefaults());
  // Empty sections are fine too.
  const ConfigResult sections = parse_config("planner:\ntopics: {}\n");
  ASSERT_TRUE(sections.config.has_value()) << Joined(sections.errors);
  ExpectSameConfig(*sections.config, RobotDefaults());
}

// Issue 31: a config with only domain_id (or only one map key, or nothing) planned with no robot
// radius, inflation or tolerance, although default.yaml says a left-out key keeps the value it
// shows. Every key default.yaml sets is compared, through the config as the node holds it
// (config_as_yaml), with the value default.yaml shows; the oracle is the file, read by yaml-cpp.
TEST(Config, EveryKeyAShortConfigLeavesOutHasDefaultYamlsValue) {
  std::map<std::string, YAML::Node> shipped;
  CollectLeaves(YAML::LoadFile(DefaultYamlPath()), "", shipped);
  ASSERT_GT(shipped.size(), 50u);
  for (const char* short_config :
       {"", "domain_id: 7\n", "map: {max_cells: 1000000}\n", "planner: {omega: 0.5}\n"}) {
    SCOPED_TRACE(std::string("config: '") + short_config + "'");
    const ConfigResult result = parse_config(short_config);
    ASSERT_TRUE(result.config.has_value()) << Joined(result.errors);
    std::map<std::string, YAML::Node> loaded;
    CollectLeaves(YAML::Load(vnsba::node::config_as_yaml(*result.config)), "", loaded);
    const YAML::Node given = YAML::Load(short_config);
    std::map<std::string, YAML::Node> given_keys;
    if (given.IsMap()) CollectLeaves(given, "", given_keys);
    for (const auto& [key, value] : shipped) {
      SCOPED_TRACE(key);
      ASSERT_EQ(loaded.count(key), 1u) << "the loaded config has no " << key;
      if (given_keys.count(key) == 0) {
        EXPECT_TRUE(SameYamlValue(loaded[key], value));
      }
    }
    // And nothing beyond default.yaml's keys: every key of the config is documented there.
    for (const auto& entry : loaded) {
      EXPECT_EQ(shipped.count(entry.first), 1u) << entry.first;
    }
  }
  // The values that went missing, checked on the fields themselves.
  const NodeConfig c = *parse_config("domain_id: 7\n").config;
  EXPECT_EQ(c.map.robot_radius, shipped["map.robot_radius"].as<double>());
  EXPECT_EQ(c.map.inflation_radius, shipped["map.inflation_radius"].as<double>());
  EXPECT_EQ(c.planner.options().goal_tolerance, shipped["planner.goal_tolerance"].as<double>());
  EXPECT_EQ(c.planner.options().cost_weight, shipped["planner.cost_weight"].as<double>());
  EXPECT_EQ(vnsba::node::default_config().config->map.robot_radius, c.map.robot_radius);
}

// config_as_yaml is a config file: it loads back to the same configuration (custom.yaml sets
// every key to something other than its default).
TEST(Config, ConfigAsYamlLoadsBackToTheSameConfig) {
  for (const std::string& path : {Fixture("custom.yaml"), DefaultYamlPath(), PaperYamlPath()}) {
    SCOPED_TRACE(path);
    const ConfigResult original = load_config(path);
    ASSERT_TRUE(original.config.has_value()) << Joined(original.errors);
    const std::string text = vnsba::node::config_as_yaml(*original.config);
    const ConfigResult again = parse_config(text, "config_as_yaml");
    ASSERT_TRUE(again.config.has_value()) << Joined(again.errors) << "\n" << text;
    ExpectSameConfig(*again.config, *original.config);
    EXPECT_EQ(vnsba::node::config_as_yaml(*again.config), text);
  }
}

// jps weighs no costs: with cost_weight left out (default.yaml's 2.0 is for the planners that
// do) `name: jps` loads and its plans say they ran on uniform costs; given, it is refused.
TEST(Config, JpsAloneLoadsWithTheDefaultCostWeightLeftToOtherPlanners) {
  const ConfigResult jps = parse_config("planner: {name: jps}\n");
  ASSERT_TRUE(jps.config.has_value()) << Joined(jps.errors);
  EXPECT_EQ(jps.config->planner.kind, PlannerKind::kJps);
  vnsba::core::PlannerOptions options = jps.config->planner.options();
  EXPECT_TRUE(vnsba::core::drop_unsupported_costs(options));
  EXPECT_TRUE(HasError(parse_config("planner: {name: jps, cost_weight: 2}\n"),
                       "planner.cost_weight", {"expected 0 for jps"}));
}

// A namespace (or robot) that makes a topic name longer than ROS 2 allows is refused at load,
// naming the key and the limit: Fast DDS cut such names, and the node matched nothing.
TEST(Config, ANamespaceThatMakesTopicNamesTooLongIsRefused) {
  const std::string long_ns(300, 'n');
  const ConfigResult result = parse_config("namespace: " + long_ns + "\n");
  EXPECT_FALSE(result.config.has_value());
  EXPECT_TRUE(HasError(result, "namespace, topics.projected_map", {"247"}))
      << Joined(result.errors);
  // The longest that fits: the longest DDS topic, an action's cancel service's requests, is "rq"
  // + "/" + namespace + "/" + the action's name and "/_action/cancel_goal" (its ROS name, which
  // rcl_action derives) + "Request": 255 characters at most (Fast DDS), one fewer than ROS 2's
  // 247-character ROS name would allow (a namespace of 198 made that topic 256 long, and not all
  // of the action's endpoints matched).
  const size_t longest_topic =
      std::string("compute_path_through_poses").size() + std::string("/_action/cancel_goal").size();
  const std::string fits(
      vnsba::node::kMaxDdsTopicNameLength - std::string("rq//Request").size() - longest_topic, 'n');
  EXPECT_TRUE(parse_config("namespace: " + fits + "\n").config.has_value());
  const ConfigResult one_more = parse_config("namespace: " + fits + "x\n");
  EXPECT_FALSE(one_more.config.has_value());
  EXPECT_TRUE(HasError(one_more, "namespace, topics.compute_path_through_poses",
                       {"DDS topic", "256 characters", "at most 255"}))
      << Joined(one_more.errors);
  // A robot's name counts too.
  const ConfigResult robots = parse_config("robots: [r1, " + long_ns + "]\n");
  EXPECT_FALSE(robots.config.has_value());
  EXPECT_TRUE(HasError(robots, "robots, topics.goal_pose", {"247"})) << Joined(robots.errors);
}

TEST(Config, MapWaitIsSecondsInZeroToSixty) {
  EXPECT_EQ(parse_config("requests: {map_wait: 0.25}\n").config->map_wait,
            std::chrono::milliseconds(250));
  EXPECT_EQ(parse_config("requests: {map_wait: 0}\n").config->map_wait,
            std::chrono::milliseconds(0));
  EXPECT_TRUE(HasError(parse_config("requests: {map_wait: 61}\n"), "requests.map_wait",
                       {"seconds in [0, 60]"}));
  EXPECT_TRUE(HasError(parse_config("requests: {map_wait: -1}\n"), "requests.map_wait"));
}

TEST(Config, EveryKeyReachesItsField) {
  const ConfigResult result = load_config(Fixture("custom.yaml"));
  ASSERT_TRUE(result.config.has_value()) << Joined(result.errors);
  const NodeConfig& c = *result.config;
  EXPECT_EQ(c.domain_id, 42);
  EXPECT_FALSE(c.ros2_naming);
  EXPECT_EQ(c.frame_id, "odom");
  EXPECT_EQ(c.topics.projected_map, "/slice");
  EXPECT_EQ(c.topics.goal_pose, "nav/goal");
  EXPECT_EQ(c.topics.robot_pose, "nav/pose");
  EXPECT_EQ(c.topics.plan_request, "nav/request");
  EXPECT_EQ(c.topics.plan, "nav/path");
  EXPECT_EQ(c.topics.plan_status, "nav/status");
  EXPECT_EQ(c.topics.planner_debug, "nav/debug");
  EXPECT_EQ(c.topics.octomap, "~/octomap_full");
  EXPECT_EQ(c.map.occupied_threshold, 50);
  EXPECT_TRUE(c.map.allow_unknown);
  EXPECT_TRUE(c.map.inflate_unknown);
  EXPECT_DOUBLE_EQ(c.map.robot_radius, 0.25);
  EXPECT_EQ(c.map.max_cells, 1000000);
  EXPECT_EQ(c.planner.kind, PlannerKind::kBidirectionalAStar);
  const PlannerOptions p = c.planner.options();
  EXPECT_EQ(p.planner, PlannerKind::kBidirectionalAStar);
  EXPECT_DOUBLE_EQ(p.omega, 2.0);
  EXPECT_DOUBLE_EQ(p.eta, 0.0);
  EXPECT_EQ(p.neighborhood, Neighborhood::kEightElevenThirteen);
  EXPECT_EQ(p.corner_policy, CornerPolicy::kTouch);
  EXPECT_TRUE(p.prune);
  EXPECT_TRUE(p.smooth);
  EXPECT_DOUBLE_EQ(p.smoothing_distance, 2.5);
  EXPECT_DOUBLE_EQ(p.sample_step, 0.5);
  EXPECT_EQ(p.max_planning_time, microseconds(250000));
  EXPECT_TRUE(p.compute_length_ratio);
  EXPECT_FALSE(p.record_expansions);  // the node sets it per request (debug readers)
  EXPECT_FALSE(c.preempt);
  EXPECT_EQ(c.queue_capacity, 8);
  EXPECT_EQ(c.debug, DebugPublishing::kAlways);
  EXPECT_EQ(c.log_level, "debug");
  EXPECT_DOUBLE_EQ(c.slicer.z_min, -0.5);
  EXPECT_DOUBLE_EQ(c.slicer.z_max, 2.0);
  EXPECT_DOUBLE_EQ(c.slicer.resolution, 0.1);
  EXPECT_TRUE(c.slicer.remove_speckles);
  EXPECT_TRUE(c.localhost_only);
}

TEST(Config, WrongTypesAreReportedWithTheirKeys) {
  const ConfigResult r = LoadBad("bad_types.yaml", 10);
  EXPECT_TRUE(HasError(r, "domain_id", {"found \"abc\"", "expected an integer in 0..232"}));
  EXPECT_TRUE(HasError(r, "ros2_naming", {"found \"3\"", "true or false"}));
  EXPECT_TRUE(HasError(r, "frame_id", {"found a list"}));
  EXPECT_TRUE(HasError(r, "topics", {"found \"plan\"", "expected a map"}));
  EXPECT_TRUE(HasError(r, "map.occupied_threshold", {"\"65.5\"", "integer in 1..100"}));
  EXPECT_TRUE(HasError(r, "map.robot_radius", {"found a map", "metres"}));
  EXPECT_TRUE(HasError(r, "planner.omega", {"found \"abc\"", "expected a number in [0, 1e6]"}));
  EXPECT_TRUE(HasError(r, "planner.prune", {"\"maybe\"", "true or false"}));
  EXPECT_TRUE(HasError(r, "requests.queue_capacity", {"found no value", "1..100000"}));
  EXPECT_TRUE(HasError(r, "slicer", {"found a list", "expected a map"}));
}

TEST(Config, MessageFormatIsKeyFoundExpected) {
  const ConfigResult r = parse_config("planner:\n  omega: abc\n");
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0], "planner.omega: found \"abc\", expected a number in [0, 1e6]");
}

TEST(Config, OutOfRangeValuesAreReportedWithTheirKeys) {
  const ConfigResult r = LoadBad("out_of_range.yaml", 12);
  EXPECT_TRUE(HasError(r, "domain_id", {"\"233\"", "0..232"}));
  EXPECT_TRUE(HasError(r, "map.occupied_threshold", {"\"0\"", "1..100"}));
  EXPECT_TRUE(HasError(r, "map.robot_radius", {"\"-0.1\"", ">= 0"}));
  EXPECT_TRUE(HasError(r, "map.max_cells", {"\"268435457\"", "1..268435456"}));
  EXPECT_TRUE(HasError(r, "planner.omega", {"\"1.0e7\"", "[0, 1e6]"}));
  EXPECT_TRUE(HasError(r, "planner.eta", {"\".inf\"", "[0, 1e6]"}));
  EXPECT_TRUE(HasError(r, "planner.smoothing_distance", {"\"0\"", "cells in (0, 1e6]"}));
  EXPECT_TRUE(HasError(r, "planner.sample_step", {"\"10.5\"", "cells in [0.05, 10]"}));
  EXPECT_TRUE(HasError(r, "planner.max_planning_time", {"\"3601\"", "seconds in [0, 3600]"}));
  EXPECT_TRUE(HasError(r, "requests.queue_capacity", {"\"100001\"", "1..100000"}));
  EXPECT_TRUE(HasError(r, "slicer.z_max", {"\"1\"", ">= slicer.z_min (2)"}));
  EXPECT_TRUE(HasError(r, "slicer.resolution", {"\"-0.5\"", ">= 0"}));
}

TEST(Config, BoundaryValuesAreAccepted) {
  const ConfigResult r = parse_config(
      "domain_id: 232\nmap: {occupied_threshold: 100, max_cells: 268435456, robot_radius: 0}\n"
      "planner: {omega: 1e6, eta: 0, sample_step: 10, max_planning_time: 3600}\n"
      "requests: {queue_capacity: 100000}\nslicer: {z_min: 1.0, z_max: 1.0}\n");
  ASSERT_TRUE(r.config.has_value()) << Joined(r.errors);
  EXPECT_EQ(r.config->domain_id, 232);
  EXPECT_EQ(r.config->map.max_cells, int64_t{1} << 28);
  EXPECT_EQ(r.config->planner.options().max_planning_time, std::chrono::hours(1));
}

// Issue 47: map.memory_budget_mb is read in MiB, and a bad value is refused naming the key and
// its unit; the range ends are accepted.
TEST(Config, MemoryBudgetIsReadInMibAndRefusedNamingKeyAndUnit) {
  for (const char* bad : {"0", "1048577", "-5", "2.5", "lots"}) {
    const ConfigResult r = parse_config(std::string("map: {memory_budget_mb: ") + bad + "}\n");
    ASSERT_FALSE(r.config.has_value()) << bad;
    EXPECT_TRUE(
        HasError(r, "map.memory_budget_mb",
                 {"\"" + std::string(bad) + "\"", "an integer number of MiB in 1..1048576"}))
        << Joined(r.errors);
  }
  for (const int good : {1, 3000, vnsba::node::kMaxMapMemoryBudgetMb}) {
    const ConfigResult r = parse_config("map: {memory_budget_mb: " + std::to_string(good) + "}\n");
    ASSERT_TRUE(r.config.has_value()) << Joined(r.errors);
    EXPECT_EQ(r.config->map_memory_budget_mb, good);
    // It prints back as it was read (vnsba_node --print-config).
    EXPECT_NE(
        vnsba::node::config_as_yaml(*r.config).find("memory_budget_mb: " + std::to_string(good)),
        std::string::npos);
  }
}

// Issue 13: planner.sample_step 1e-6, inside the old (0, 10], asked for billions of spline
// samples and ended in bad_alloc. The range is core's (kSampleStepRange), so the config, the
// tools and core::validate refuse the same values.
TEST(Config, OptionRangesAreCoresOwn) {
  for (const char* value : {"1e-6", "0.0499"}) {
    const ConfigResult r = parse_config(std::string("planner:\n  sample_step: ") + value + "\n");
    EXPECT_TRUE(HasError(r, "planner.sample_step", {vnsba::core::kSampleStepRange.describe()}))
        << value;
    vnsba::core::PlannerOptions options =
        vnsba::core::default_options(vnsba::core::PlannerKind::kVnsBaStar);
    options.sample_step = std::stod(value);
    EXPECT_FALSE(vnsba::core::validate(options).is_ok()) << value;
  }
  const ConfigResult ok = parse_config("planner:\n  sample_step: 0.05\n");
  EXPECT_TRUE(ok.config.has_value()) << Joined(ok.errors);
  EXPECT_EQ(vnsba::core::kSampleStepRange.describe(), "a number of cells in [0.05, 10]");
  EXPECT_EQ(vnsba::core::kOmegaRange.describe(), "a number in [0, 1e6]");
}

TEST(Config, NonFiniteAndMalformedNumbersAreRejected) {
  for (const char* value : {".nan", "-.inf", "1e400", "0x10", "1,5", "''"}) {
    const ConfigResult r = parse_config(std::string("map:\n  robot_radius: ") + value + "\n");
    EXPECT_TRUE(HasError(r, "map.robot_radius")) << value;
  }
  for (const char* value : {"1.0", "1e3", "0x10", "99999999999999999999", "--1"}) {
    const ConfigResult r = parse_config(std::string("domain_id: ") + value + "\n");
    EXPECT_TRUE(HasError(r, "domain_id", {"0..232"})) << value;
  }
  EXPECT_TRUE(parse_config("domain_id: +7\n").config.has_value());
}

// The keys of docs/algorithm.md section 8: each refuses every bad value at load, naming the key
// and its unit.
TEST(Config, CostAndToleranceKeysRefuseBadValuesNamingKeyAndUnit) {
  struct Key {
    std::string section, key;
    std::vector<std::string> expected;  // parts of the message (unit, range)
    std::vector<std::string> out_of_range;
  };
  const Key keys[] = {
      {"map", "inflation_radius", {"metres", ">= 0", "no cost gradient"}, {"-0.1", "-1e-9"}},
      {"map", "cost_scaling_factor", {"per metre", ">= 0"}, {"-3"}},
      {"planner", "cost_weight", {"a number in [0, 1000]"}, {"-0.5", "1000.5", "1e9"}},
      {"planner", "goal_tolerance", {"metres in [0, 100]"}, {"-0.25", "100.1"}},
      {"planner", "start_tolerance", {"metres in [0, 100]"}, {"-0.2", "1e4"}},
      {"planner",
       "path_spacing",
       {"metres in (0, 10]", "the map's resolution"},
       {"0", "-0.05", "10.01"}},
  };
  for (const Key& k : keys) {
    std::vector<std::string> values = {".nan",   ".inf",   "-.inf", "abc",
                                       "[1, 2]", "{a: 1}", "''",    "true"};
    values.insert(values.end(), k.out_of_range.begin(), k.out_of_range.end());
    for (const std::string& v : values) {
      SCOPED_TRACE(k.section + "." + k.key + ": " + v);
      const ConfigResult r = parse_config(k.section + ":\n  " + k.key + ": " + v + "\n");
      EXPECT_FALSE(r.config.has_value());
      EXPECT_EQ(r.errors.size(), 1u) << Joined(r.errors);
      EXPECT_TRUE(HasError(r, k.section + "." + k.key, k.expected));
    }
  }
  // Every bad key of a file at once.
  const ConfigResult all = parse_config(
      "map: {inflation_radius: -1, cost_scaling_factor: .nan}\n"
      "planner: {cost_weight: -1, goal_tolerance: .inf, start_tolerance: x, path_spacing: 0}\n");
  EXPECT_EQ(all.errors.size(), 6u) << Joined(all.errors);
  // Boundaries are accepted.
  const ConfigResult edges = parse_config(
      "map: {inflation_radius: 0, cost_scaling_factor: 0}\n"
      "planner: {cost_weight: 1000, goal_tolerance: 100, start_tolerance: 0, path_spacing: 10}\n");
  ASSERT_TRUE(edges.config.has_value()) << Joined(edges.errors);
  EXPECT_EQ(edges.config->planner.path_spacing, 10.0);
  EXPECT_TRUE(parse_config("planner: {path_spacing: 1e-6}\n").config.has_value());
}

TEST(Config, InflationRadiusBelowTheRobotRadiusIsRefused) {
  const ConfigResult r = parse_config("map: {robot_radius: 0.3, inflation_radius: 0.2}\n");
  ASSERT_EQ(r.errors.size(), 1u) << Joined(r.errors);
  EXPECT_TRUE(
      HasError(r, "map.inflation_radius",
               {"found \"0.2\"", "0 (no cost gradient)", "metres >= map.robot_radius (0.3 m)"}));
  // 0 (no gradient) and the radius itself are fine; a bad radius is reported alone.
  EXPECT_TRUE(parse_config("map: {robot_radius: 0.3, inflation_radius: 0}\n").config.has_value());
  EXPECT_TRUE(parse_config("map: {robot_radius: 0.3, inflation_radius: 0.3}\n").config.has_value());
  const ConfigResult radius = parse_config("map: {robot_radius: -1, inflation_radius: 0.2}\n");
  ASSERT_EQ(radius.errors.size(), 1u) << Joined(radius.errors);
  EXPECT_TRUE(HasError(radius, "map.robot_radius"));
}

TEST(Config, CostAndToleranceKeysReachTheirFieldsForEveryPlanner) {
  const ConfigResult r = parse_config(
      "map: {robot_radius: 0.1, inflation_radius: 0.6, cost_scaling_factor: 4.5}\n"
      "planner: {cost_weight: 7, goal_tolerance: 0.4, start_tolerance: 0.15, path_spacing: 0.2}\n");
  ASSERT_TRUE(r.config.has_value()) << Joined(r.errors);
  const NodeConfig& c = *r.config;
  EXPECT_DOUBLE_EQ(c.map.inflation_radius, 0.6);
  EXPECT_DOUBLE_EQ(c.map.cost_scaling_factor, 4.5);
  EXPECT_DOUBLE_EQ(c.planner.path_spacing_for(0.05), 0.2);
  for (PlannerKind kind : vnsba::core::all_planner_kinds()) {
    SCOPED_TRACE(std::string(vnsba::core::to_string(kind)));
    const PlannerOptions o = c.planner.options(kind);
    EXPECT_DOUBLE_EQ(o.cost_weight, 7.0);
    EXPECT_DOUBLE_EQ(o.goal_tolerance, 0.4);
    EXPECT_DOUBLE_EQ(o.start_tolerance, 0.15);
  }
  // Absent: default.yaml's robot, and the map's resolution.
  const NodeConfig d = parse_config("").config.value();
  const NodeConfig robot = RobotDefaults();
  EXPECT_EQ(d.planner.options().cost_weight, robot.planner.options().cost_weight);
  EXPECT_EQ(d.planner.options().goal_tolerance, robot.planner.options().goal_tolerance);
  EXPECT_EQ(d.planner.options().start_tolerance, robot.planner.options().start_tolerance);
  EXPECT_EQ(d.map.inflation_radius, robot.map.inflation_radius);
  EXPECT_DOUBLE_EQ(d.planner.path_spacing_for(0.05), 0.05);
}

TEST(Config, JpsWithCostWeightIsRefusedAtLoad) {
  const ConfigResult r = parse_config("planner: {name: jps, cost_weight: 0.5}\n");
  ASSERT_EQ(r.errors.size(), 1u) << Joined(r.errors);
  EXPECT_TRUE(HasError(r, "planner.cost_weight", {"found \"0.5\"", "expected 0 for jps"}));
  EXPECT_TRUE(parse_config("planner: {name: jps, cost_weight: 0}\n").config.has_value());
  EXPECT_TRUE(parse_config("planner: {name: astar, cost_weight: 0.5}\n").config.has_value());
}

TEST(Config, VnsBaStarNeedsANonZeroWeight) {
  const ConfigResult both = parse_config("planner:\n  name: vns_bastar\n  omega: 0\n  eta: 0\n");
  ASSERT_EQ(both.errors.size(), 1u) << Joined(both.errors);
  EXPECT_TRUE(HasError(both, "planner.omega, planner.eta", {"both 0", "vns_bastar"}));
  EXPECT_TRUE(parse_config("planner:\n  name: vns_bastar\n  omega: 0\n").config.has_value());
  // The other planners ignore the weights.
  EXPECT_TRUE(parse_config("planner: {name: astar, omega: 0, eta: 0}\n").config.has_value());
}

// jps plans on the 8-neighbourhood without corner cutting only: a config asking it for other
// moves is refused at load, naming each key (both errors at once), never planned otherwise.
TEST(Config, JpsNeedsCornerPolicyNeverAndTheEightNeighbourhood) {
  const ConfigResult bad =
      parse_config("planner:\n  name: jps\n  corner_policy: touch\n  neighborhood: 8-11-13\n");
  ASSERT_EQ(bad.errors.size(), 2u) << Joined(bad.errors);
  EXPECT_TRUE(HasError(bad, "planner.corner_policy", {"\"touch\"", "never", "jps"}));
  EXPECT_TRUE(HasError(bad, "planner.neighborhood", {"\"8-11-13\"", "8", "jps"}));
  EXPECT_TRUE(parse_config("planner: {name: jps}\n").config.has_value());
  EXPECT_TRUE(
      parse_config("planner: {name: jps, corner_policy: never, prune: true}\n").config.has_value());
  // The same keys are fine for the other planners.
  EXPECT_TRUE(parse_config("planner: {name: astar, corner_policy: always}\n").config.has_value());
}

TEST(Config, UnknownEnumNamesListTheValidNames) {
  const ConfigResult r = LoadBad("bad_enums.yaml", 5);
  EXPECT_TRUE(
      HasError(r, "planner.name",
               {"\"astr\"", "astar", "weighted_astar", "bidirectional_astar",
                "alternating_bidirectional_astar", "vns_bastar", "did you mean \"astar\"?"}));
  EXPECT_TRUE(HasError(r, "planner.neighborhood", {"\"4\"", "8, 8-11-13"}));
  EXPECT_TRUE(HasError(r, "planner.corner_policy", {"\"sometimes\"", "never, touch, always"}));
  EXPECT_TRUE(HasError(r, "debug.publish", {"\"maybe\"", "auto, always, never"}));
  EXPECT_TRUE(
      HasError(r, "log_level", {"\"verbose\"", "trace, debug, info, warn, error, critical, off"}));
}

TEST(Config, MapDurabilityIsTransientLocalOrVolatile) {
  EXPECT_EQ(parse_config("").config->map_durability, MapDurability::kTransientLocal);
  EXPECT_EQ(parse_config("map: {durability: volatile}\n").config->map_durability,
            MapDurability::kVolatile);
  EXPECT_EQ(parse_config("map: {durability: transient_local}\n").config->map_durability,
            MapDurability::kTransientLocal);
  const ConfigResult bad = parse_config("map: {durability: latched}\n");
  EXPECT_FALSE(bad.config.has_value());
  EXPECT_TRUE(HasError(bad, "map.durability", {"\"latched\"", "transient_local, volatile"}));
}

TEST(Config, UnknownKeysAreReportedWithSuggestions) {
  const ConfigResult r = LoadBad("unknown_keys.yaml", 4);
  EXPECT_TRUE(HasError(r, "planer", {"unknown key", "did you mean \"planner\"?"}));
  EXPECT_TRUE(HasError(r, "planner.omgea", {"unknown key", "did you mean \"planner.omega\"?"}));
  EXPECT_TRUE(HasError(r, "topics.plann", {"unknown key", "did you mean \"topics.plan\"?"}));
  EXPECT_TRUE(HasError(r, "frobnicate", {"unknown key", "expected one of", "domain_id"}));
  for (const std::string& e : r.errors) {
    if (e.rfind("frobnicate", 0) == 0) {
      EXPECT_EQ(e.find("did you mean"), std::string::npos);
    }
  }
}

// An empty key (`? |`, `"": 1`, found by the long fuzz run) is named by where it is.
TEST(Config, AnEmptyKeyIsNamedByItsSection) {
  for (const char* yaml : {"? |\n", "\"\": 1\n", "planner:\n  \"\": 1\n"}) {
    const ConfigResult r = parse_config(yaml);
    ASSERT_EQ(r.errors.size(), 1u) << yaml << Joined(r.errors);
    const std::string where = std::string(yaml).rfind("planner", 0) == 0 ? "planner" : "top level";
    EXPECT_TRUE(HasError(r, where, {"found an empty key", "expected one of"})) << yaml;
  }
}

TEST(Config, SuggestionsOnlyForNearMisses) {
  const ConfigResult r = parse_config(
      "a: 1\nplanner: {name: astra, corner_policy: nevr}\n"
      "map: {allow_unknwn: true}\n");
  ASSERT_EQ(r.errors.size(), 4u) << Joined(r.errors);
  EXPECT_TRUE(HasError(r, "a", {"unknown key, expected one of"}));
  EXPECT_TRUE(HasError(r, "planner.name", {"did you mean \"astar\"?"}));
  EXPECT_TRUE(HasError(r, "planner.corner_policy", {"did you mean \"never\"?"}));
  EXPECT_TRUE(HasError(r, "map.allow_unknwn", {"did you mean \"map.allow_unknown\"?"}));
  for (const std::string& e : r.errors) {
    if (e.rfind("a: ", 0) == 0) {
      EXPECT_EQ(e.find("did you mean"), std::string::npos) << e;
    }
  }
}

TEST(Config, RepeatedKeysAreErrors) {
  const ConfigResult r = parse_config("domain_id: 1\ndomain_id: 2\n");
  ASSERT_EQ(r.errors.size(), 1u) << Joined(r.errors);
  EXPECT_TRUE(HasError(r, "domain_id", {"again"}));
}

TEST(Config, BadTopicNamesAndFrameAreReported) {
  const ConfigResult r = LoadBad("bad_topics.yaml", 6);
  EXPECT_TRUE(HasError(r, "frame_id", {"found \"\"", "non-empty"}));
  EXPECT_TRUE(HasError(r, "topics.plan", {"found \"\"", "non-empty"}));
  EXPECT_TRUE(HasError(r, "topics.plan_status", {"\"plan status\"", "letters, digits"}));
  EXPECT_TRUE(HasError(r, "topics.planner_debug", {"\"2debug\"", "digit"}));
  EXPECT_TRUE(HasError(r, "topics.robot_pose", {"\"a//b\"", "empty parts"}));
  EXPECT_TRUE(HasError(r, "topics.goal_pose, topics.plan_request",
                       {"\"/plan_request\"", "\"plan_request\"", "different topics"}));
}

TEST(Config, TopicNameRules) {
  for (const char* good : {"plan", "/plan", "ns/plan_2", "~/plan", "A_b9"}) {
    EXPECT_TRUE(parse_config(std::string("topics: {plan: \"") + good + "\"}\n").config) << good;
  }
  for (const char* bad : {"plan-x", "plan.x", "9plan", "ns/9plan", "plan/", "/", "a~b", "pl an"}) {
    const ConfigResult r = parse_config(std::string("topics: {plan: \"") + bad + "\"}\n");
    EXPECT_TRUE(HasError(r, "topics.plan")) << bad;
  }
  const ConfigResult same = parse_config("topics: {plan: x, plan_status: x}\n");
  ASSERT_EQ(same.errors.size(), 1u) << Joined(same.errors);
  EXPECT_TRUE(HasError(same, "topics.plan, topics.plan_status", {"different topics"}));
}

TEST(Config, SyntaxErrorGivesOneErrorWithLineAndColumn) {
  const std::string path = Fixture("syntax_error.yaml");
  const ConfigResult r = load_config(path);
  EXPECT_FALSE(r.config.has_value());
  ASSERT_EQ(r.errors.size(), 1u) << Joined(r.errors);
  EXPECT_EQ(r.errors[0].rfind(path + ": ", 0), 0u) << r.errors[0];
  EXPECT_NE(r.errors[0].find("syntax error at line 5, column "), std::string::npos) << r.errors[0];

  const ConfigResult text = parse_config("a: [1, 2\n", "inline.yaml");
  ASSERT_EQ(text.errors.size(), 1u);
  EXPECT_EQ(text.errors[0].rfind("inline.yaml: YAML syntax error at line ", 0), 0u)
      << text.errors[0];
}

// yaml-cpp refuses documents nested 500 levels deep (its DepthGuard): that is reported as the
// nesting it is, with the file and the line, not as a syntax error; 100,000 levels neither crash
// (stack) nor hang.
TEST(Config, DeepNestingIsReportedAsSuchWithFileAndLine) {
  auto repeat = [](const std::string& unit, int times) {
    std::string out;
    for (int i = 0; i < times; ++i) out += unit;
    return out;
  };
  struct Case {
    std::string name;
    std::string text;
    int line;   // where the nesting passes the limit: the error must point there,
    int slack;  // give or take this (a block level a line: yaml-cpp stops on that line or before)
  };
  std::string indented;  // a block mapping 600 levels deep, one level (and space) more a line
  for (int i = 0; i < 600; ++i) indented += std::string(i, ' ') + "k:\n";
  const std::vector<Case> cases = {
      {"flow sequences", "slicer:\n  z_min: " + repeat("[", 600) + repeat("]", 600) + "\n", 2, 0},
      {"flow maps", "map: " + repeat("{a: ", 600) + "1" + repeat("}", 600) + "\n", 1, 0},
      {"block sequences", repeat("- ", 600) + "x\n", 1, 0},
      {"block maps", indented, 500, 1},
      {"100,000 flow", repeat("[", 100000) + repeat("]", 100000) + "\n", 1, 0},
      {"100,000 block", repeat("- ", 100000) + "x\n", 1, 0},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const ConfigResult r = parse_config(c.text, "deep.yaml");
    EXPECT_FALSE(r.config.has_value());
    ASSERT_EQ(r.errors.size(), 1u) << Joined(r.errors);
    const std::string prefix = "deep.yaml: line ";
    ASSERT_EQ(r.errors[0].rfind(prefix, 0), 0u) << r.errors[0];
    const int line = std::atoi(r.errors[0].c_str() + prefix.size());
    EXPECT_LE(std::abs(line - c.line), c.slack) << r.errors[0];
    EXPECT_NE(r.errors[0].find("nested deeper than 499 levels"), std::string::npos) << r.errors[0];
    EXPECT_EQ(r.errors[0].find("syntax error"), std::string::npos) << r.errors[0];
  }
  // 498 levels is still a document (here a wrong type for the key, reported as such).
  const ConfigResult ok = parse_config("slicer:\n  z_min: " + repeat("[", 497) + repeat("]", 497));
  ASSERT_EQ(ok.errors.size(), 1u) << Joined(ok.errors);
  EXPECT_NE(ok.errors[0].find("slicer.z_min"), std::string::npos) << ok.errors[0];
}

TEST(Config, MissingOrUnreadableFileGivesOneErrorNamingIt) {
  const std::string missing = Fixture("no_such_file.yaml");
  const ConfigResult r = load_config(missing);
  EXPECT_FALSE(r.config.has_value());
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_NE(r.errors[0].find(missing), std::string::npos);
  EXPECT_NE(r.errors[0].find("no such file"), std::string::npos);

  const std::string folder = std::string(VNSBA_FIXTURE_DIR) + "/config";
  const ConfigResult dir = load_config(folder);
  ASSERT_EQ(dir.errors.size(), 1u);
  EXPECT_NE(dir.errors[0].find(folder), std::string::npos);
}

TEST(Config, TopLevelMustBeAMap) {
  for (const char* text : {"- a\n- b\n", "just a string\n", "42\n"}) {
    const ConfigResult r = parse_config(text, "top.yaml");
    ASSERT_EQ(r.errors.size(), 1u) << text;
    EXPECT_NE(r.errors[0].find("top.yaml: found"), std::string::npos) << r.errors[0];
    EXPECT_NE(r.errors[0].find("expected a map"), std::string::npos) << r.errors[0];
  }
  const ConfigResult two = parse_config("a: 1\n---\nb: 2\n", "two.yaml");
  ASSERT_EQ(two.errors.size(), 1u);
  EXPECT_NE(two.errors[0].find("2 YAML documents"), std::string::npos);
}

TEST(Config, ManyErrorsAreAllReportedAtOnce) {
  const ConfigResult r = LoadBad("many_errors.yaml", 11);
  EXPECT_TRUE(HasError(r, "domain_id", {"\"-1\""}));
  EXPECT_TRUE(HasError(r, "ros2_naming", {"\"yes please\""}));
  EXPECT_TRUE(HasError(r, "topics.plan, topics.plan_status"));
  EXPECT_TRUE(HasError(r, "topics.goal_pose", {"\"goal-pose\""}));
  EXPECT_TRUE(HasError(r, "map.occupied_threshold", {"\"101\""}));
  EXPECT_TRUE(HasError(r, "map.inflation", {"unknown key"}));
  EXPECT_TRUE(HasError(r, "planner.omega, planner.eta", {"both 0"}));
  EXPECT_TRUE(HasError(r, "planner.sample_step", {"\"abc\""}));
  EXPECT_TRUE(HasError(r, "requests.preempt", {"again"}));
  EXPECT_TRUE(HasError(r, "debug.publsh", {"did you mean \"debug.publish\"?"}));
  EXPECT_TRUE(HasError(r, "log_level", {"\"loud\""}));
}

TEST(Config, PlannerDefaultsFollowTheChosenPlanner) {
  const ConfigResult vns = parse_config("planner:\n  name: vns_bastar\n  omega: 1.0\n");
  ASSERT_TRUE(vns.config.has_value());
  EXPECT_EQ(vns.config->planner.kind, PlannerKind::kVnsBaStar);
  EXPECT_TRUE(vns.config->planner.options().prune);
  EXPECT_TRUE(vns.config->planner.options().smooth);
  EXPECT_EQ(vns.config->planner.options().neighborhood, Neighborhood::kEightElevenThirteen);

  const ConfigResult astar = parse_config("planner:\n  name: astar\n");
  ASSERT_TRUE(astar.config.has_value());
  EXPECT_EQ(astar.config->planner.kind, PlannerKind::kAStar);
  EXPECT_FALSE(astar.config->planner.options().prune);
  EXPECT_FALSE(astar.config->planner.options().smooth);
  EXPECT_EQ(astar.config->planner.options().neighborhood, Neighborhood::kEight);
  EXPECT_EQ(astar.config->planner.options().max_planning_time, std::chrono::seconds(5));

  // Keys given explicitly override the planner's defaults, wherever they appear in the block.
  const ConfigResult pruned = parse_config("planner:\n  prune: true\n  name: astar\n");
  ASSERT_TRUE(pruned.config.has_value());
  EXPECT_TRUE(pruned.config->planner.options().prune);
  EXPECT_FALSE(pruned.config->planner.options().smooth);
}

TEST(Config, MaxPlanningTimeIsSecondsToMicroseconds) {
  auto budget = [](const std::string& value) {
    const ConfigResult r = parse_config("planner:\n  max_planning_time: " + value + "\n");
    EXPECT_TRUE(r.config.has_value()) << value << Joined(r.errors);
    return r.config ? r.config->planner.options().max_planning_time : microseconds(-1);
  };
  EXPECT_EQ(budget("0.25"), microseconds(250000));
  EXPECT_EQ(budget("2"), microseconds(2000000));
  EXPECT_EQ(budget("0"), microseconds(0));  // unlimited
  EXPECT_EQ(budget("0.0000015"), microseconds(2));
  EXPECT_EQ(budget("1e-9"), microseconds(1));  // never rounds down to "unlimited"
  // Absent key, or absent planner block: 5 s.
  EXPECT_EQ(parse_config("planner: {name: astar}\n").config->planner.options().max_planning_time,
            std::chrono::seconds(5));
  EXPECT_EQ(parse_config("domain_id: 3\n").config->planner.options().max_planning_time,
            std::chrono::seconds(5));
  EXPECT_TRUE(
      HasError(parse_config("planner: {max_planning_time: -1}\n"), "planner.max_planning_time"));
}

// A request that picks another planner gets PlannerConfig::options(its planner), as the node's
// worker builds it: every planner key the file gave is kept, whatever its value and whichever
// planner the file named, and only the keys the file left out follow the chosen planner's paper
// configuration.
TEST(Config, PlannerOverrideKeepsEveryConfiguredKey) {
  // The planner-dependent keys once with the baselines' paper values and once with VNS-BA*'s,
  // so that each configured value differs from some override's paper configuration.
  for (const bool vns_values : {false, true}) {
    for (PlannerKind configured : vnsba::core::all_planner_kinds()) {
      // jps refuses corner_policy always at load (JpsNeedsCornerPolicyNever...).
      if (configured == PlannerKind::kJps) continue;
      const std::string yaml =
          "planner:\n  name: " + std::string(vnsba::core::to_string(configured)) +
          "\n  omega: 2\n  eta: 3\n  neighborhood: \"" + (vns_values ? "8-11-13" : "8") +
          "\"\n  corner_policy: always\n" + "  prune: " + (vns_values ? "true" : "false") +
          "\n  smooth: " + (vns_values ? "true" : "false") +
          "\n  smoothing_distance: 2.5\n  sample_step: 0.5\n"
          "  max_planning_time: 0.25\n  compute_length_ratio: true\n";
      const ConfigResult r = parse_config(yaml);
      ASSERT_TRUE(r.config.has_value()) << yaml << Joined(r.errors);
      EXPECT_EQ(r.config->planner.kind, configured);
      for (PlannerKind kind : vnsba::core::all_planner_kinds()) {
        SCOPED_TRACE(yaml + "override: " + std::string(vnsba::core::to_string(kind)));
        const PlannerOptions o = r.config->planner.options(kind);
        EXPECT_EQ(o.planner, kind);
        EXPECT_EQ(o.omega, 2.0);
        EXPECT_EQ(o.eta, 3.0);
        EXPECT_EQ(o.neighborhood,
                  vns_values ? Neighborhood::kEightElevenThirteen : Neighborhood::kEight);
        EXPECT_EQ(o.corner_policy, CornerPolicy::kAlways);
        EXPECT_EQ(o.prune, vns_values);
        EXPECT_EQ(o.smooth, vns_values);
        EXPECT_EQ(o.smoothing_distance, 2.5);
        EXPECT_EQ(o.sample_step, 0.5);
        EXPECT_EQ(o.max_planning_time, microseconds(250000));
        EXPECT_TRUE(o.compute_length_ratio);
        EXPECT_FALSE(o.record_expansions);  // not a config key: the node sets it per request
        if (kind == PlannerKind::kJps) {    // kept, and then refused by name, not changed
          EXPECT_NE(vnsba::core::validate(o).message.find("corner_policy always"),
                    std::string::npos);
        } else {
          EXPECT_TRUE(vnsba::core::validate(o).is_ok()) << vnsba::core::validate(o).message;
        }
      }
    }
  }
}

TEST(Config, PlannerOverrideTakesTheKeysLeftOutFromTheChosenPlanner) {
  const ConfigResult r = parse_config(
      "planner:\n  name: astar\n  prune: false\n"
      "  corner_policy: touch\n");
  ASSERT_TRUE(r.config.has_value()) << Joined(r.errors);
  for (PlannerKind kind : vnsba::core::all_planner_kinds()) {
    SCOPED_TRACE(std::string(vnsba::core::to_string(kind)));
    // default.yaml's robot and smoother, then what this file configures.
    PlannerOptions expected = vnsba::core::make_options(kind, RobotDefaults().planner.settings);
    expected.prune = false;                         // configured
    expected.corner_policy = CornerPolicy::kTouch;  // configured
    ExpectSameOptions(r.config->planner.options(kind), expected);
  }
  // So VNS-BA* as an override still smooths with its 8-11-13 neighbourhood, but does not prune.
  const PlannerOptions vns = r.config->planner.options(PlannerKind::kVnsBaStar);
  EXPECT_EQ(vns.neighborhood, Neighborhood::kEightElevenThirteen);
  EXPECT_TRUE(vns.smooth);
  EXPECT_FALSE(vns.prune);
}

TEST(Config, ComputeLengthRatioIsOffUnlessConfigured) {
  EXPECT_FALSE(parse_config("").config->planner.options().compute_length_ratio);
  EXPECT_TRUE(parse_config("planner: {compute_length_ratio: true}\n")
                  .config->planner.options(PlannerKind::kAStar)
                  .compute_length_ratio);
  EXPECT_TRUE(HasError(parse_config("planner: {compute_length_ratio: 1.5}\n"),
                       "planner.compute_length_ratio", {"\"1.5\"", "true or false"}));
}

TEST(Config, DdsTopicName) {
  NodeConfig ros2 = PaperSetting();
  ros2.ros2_naming = true;
  EXPECT_EQ(dds_topic_name(ros2, "plan"), "rt/plan");
  EXPECT_EQ(dds_topic_name(ros2, "/plan"), "rt/plan");
  EXPECT_EQ(dds_topic_name(ros2, "ns/plan"), "rt/ns/plan");
  EXPECT_EQ(dds_topic_name(ros2, ros2.topics.octomap), "rt/octomap_binary");
  NodeConfig plain = PaperSetting();
  plain.ros2_naming = false;
  EXPECT_EQ(dds_topic_name(plain, "plan"), "plan");
  EXPECT_EQ(dds_topic_name(plain, "/plan"), "plan");
}

TEST(Config, NeverThrowsOnHostileInput) {
  const std::vector<std::string> inputs = {"{",
                                           "[",
                                           "a: *undefined\n",
                                           "\t\n",
                                           std::string("\0\x01\xff", 3),
                                           "? [a, b]\n: 1\n",
                                           "~: 1\n",
                                           "planner: &p {name: astar}\nmap: *p\n",
                                           "a: !!binary x\n",
                                           std::string(100000, '['),
                                           "planner:\n  name: [astar]\n"};
  for (const std::string& text : inputs) {
    ConfigResult r;
    EXPECT_NO_THROW(r = parse_config(text)) << text.substr(0, 40);
    EXPECT_NE(r.config.has_value(), !r.errors.empty()) << text.substr(0, 40);
  }
}

}  // namespace

// Found by the fuzz stage: yaml-cpp 0.7's LoadAll never returns on a document that starts with
// ',' (it appended empty documents until 23 GB were gone). A syntax error naming the place.
TEST(Config, ADocumentStartingWithACommaIsASyntaxError) {
  for (const char* text : {",", "- 1\n,\n", "a: b\n---\n,"}) {
    const ConfigResult r = parse_config(text, "c.yaml");
    ASSERT_FALSE(r.config.has_value()) << text;
    ASSERT_EQ(r.errors.size(), 1u) << text;
    EXPECT_NE(r.errors[0].find("c.yaml: YAML syntax error at line"), std::string::npos)
        << r.errors[0];
  }
  const ConfigResult two = parse_config("a: 1\n---\nb: 2\n", "c.yaml");
  ASSERT_EQ(two.errors.size(), 1u);
  EXPECT_NE(two.errors[0].find("found 2 YAML documents, expected one"), std::string::npos);
}

namespace vnsba::node {
namespace {

// Issue 17 item 4: where a goal's start comes from, and the clock.
TEST(Config, RobotPoseSourceTypeBaseFrameToleranceAndSimTime) {
  const NodeConfig defaults = *parse_config("").config;
  EXPECT_EQ(defaults.robot_pose_source, RobotPoseSource::kTopic);
  EXPECT_EQ(defaults.robot_pose_type, RobotPoseType::kPoseStamped);
  EXPECT_EQ(defaults.base_frame, "base_link");
  EXPECT_FALSE(defaults.use_sim_time);
  const ConfigResult set = parse_config(
      "robot_pose_source: tf\nrobot_pose_type: PoseWithCovarianceStamped\nbase_frame: "
      "base_footprint\ntransform_tolerance: 0.25\nuse_sim_time: true\n");
  ASSERT_TRUE(set.config) << Joined(set.errors);
  EXPECT_EQ(set.config->robot_pose_source, RobotPoseSource::kTf);
  EXPECT_EQ(set.config->robot_pose_type, RobotPoseType::kPoseWithCovarianceStamped);
  EXPECT_EQ(set.config->base_frame, "base_footprint");
  EXPECT_DOUBLE_EQ(set.config->transform_tolerance_s, 0.25);
  EXPECT_TRUE(set.config->use_sim_time);

  const ConfigResult bad = parse_config(
      "robot_pose_source: amcl\nrobot_pose_type: Pose\nbase_frame: /map\n"
      "transform_tolerance: -1\nuse_sim_time: sometimes\n");
  EXPECT_FALSE(bad.config);
  EXPECT_TRUE(HasError(bad, "robot_pose_source", {"\"amcl\"", "topic, tf"})) << Joined(bad.errors);
  EXPECT_TRUE(HasError(bad, "robot_pose_type", {"PoseStamped, PoseWithCovarianceStamped"}));
  EXPECT_TRUE(HasError(bad, "base_frame", {"\"/map\"", "not frame_id"}));
  EXPECT_TRUE(HasError(bad, "transform_tolerance", {"seconds in [0, 60]"}));
  EXPECT_TRUE(HasError(bad, "use_sim_time", {"true or false"}));
  for (const char* tolerance : {"61", ".nan", ".inf", "[1]"})
    EXPECT_TRUE(HasError(parse_config(std::string("transform_tolerance: ") + tolerance),
                         "transform_tolerance", {"seconds"}))
        << tolerance;
  EXPECT_TRUE(HasError(parse_config("base_frame: \"\"\n"), "base_frame", {"non-empty"}));
}

TEST(Config, DebugLayerAndTfTopicsAreTopicNamesLikeEveryOther) {
  const NodeConfig defaults = *parse_config("").config;
  EXPECT_EQ(dds_topic_name(defaults, defaults.topics.tf), "rt/tf");
  EXPECT_EQ(dds_topic_name(defaults, defaults.topics.expansions_forward),
            "rt/planner_expansions_forward");
  const ConfigResult bad = parse_config("topics: {plan_raw: plan, clock: \"2clock\"}\n");
  EXPECT_TRUE(HasError(bad, "topics.plan, topics.plan_raw", {"expected different topics"}))
      << Joined(bad.errors);
  EXPECT_TRUE(HasError(bad, "topics.clock", {"do not start with a digit"})) << Joined(bad.errors);
}

// Issue 18: names resolve as ROS 2 resolves them.
TEST(Config, ANamespacePrefixesRelativeTopicNamesAndLeavesAbsoluteOnes) {
  const ConfigResult r = parse_config(
      "namespace: /robot7/\ntopics: {projected_map: /map, goal_pose: goal_pose, plan: nav/plan}\n");
  ASSERT_TRUE(r.config) << Joined(r.errors);
  const NodeConfig& c = *r.config;
  EXPECT_EQ(c.ros_namespace, "robot7");
  EXPECT_EQ(dds_topic_name(c, c.topics.projected_map), "rt/map");
  EXPECT_EQ(dds_topic_name(c, c.topics.goal_pose), "rt/robot7/goal_pose");
  EXPECT_EQ(dds_topic_name(c, c.topics.plan), "rt/robot7/nav/plan");
  EXPECT_EQ(dds_topic_name(c, c.topics.tf), "rt/tf");  // tf is absolute: shared by the fleet
  NodeConfig plain = c;
  plain.ros2_naming = false;
  EXPECT_EQ(dds_topic_name(plain, plain.topics.goal_pose), "robot7/goal_pose");
  // With a namespace "/plan" and "plan" are two topics; without one they are the same.
  EXPECT_TRUE(parse_config("namespace: r1\ntopics: {plan: /plan, plan_status: plan}\n").config);
  EXPECT_TRUE(HasError(parse_config("topics: {plan: /plan, plan_status: plan}\n"),
                       "topics.plan, topics.plan_status", {"expected different topics"}));
  for (const char* bad : {"\"r 1\"", "\"~r1\"", "\"1robot\"", "\"a//b\"", "[a]"}) {
    const ConfigResult refused = parse_config(std::string("namespace: ") + bad + "\n");
    EXPECT_TRUE(HasError(refused, "namespace", {"expected a namespace"})) << bad;
  }
  EXPECT_EQ(parse_config("namespace: \"\"\n").config->ros_namespace, "");
  EXPECT_EQ(parse_config("namespace: /\n").config->ros_namespace, "");
}

TEST(Config, DiscoveryServersAreIPv4AndPortEach) {
  const ConfigResult ok =
      parse_config("discovery:\n  servers: [\"127.0.0.1:11811\", \"10.0.0.2:1\"]\n");
  ASSERT_TRUE(ok.config) << Joined(ok.errors);
  EXPECT_EQ(ok.config->discovery_servers,
            (std::vector<std::string>{"127.0.0.1:11811", "10.0.0.2:1"}));
  EXPECT_TRUE(parse_config("").config->discovery_servers.empty());
  for (const char* bad :
       {"[\"localhost:11811\"]", "[\"127.0.0.1\"]", "[\"127.0.0.1:0\"]", "[\"127.0.0.1:70000\"]",
        "[\"1.2.3:5\"]", "[\"1.2.3.256:5\"]", "\"127.0.0.1:11811\"", "[[1]]"}) {
    const ConfigResult r = parse_config(std::string("discovery: {servers: ") + bad + "}\n");
    EXPECT_TRUE(HasError(r, "discovery.servers", {"IPv4:port"})) << bad << Joined(r.errors);
  }
}

// Issue 18: one node for many robots; each name is a namespace, and workers are bounded.
TEST(Config, RobotsAreDistinctNamespacesAndWorkersAreBounded) {
  const ConfigResult ok = parse_config(
      "namespace: site\nrobots: [robot1, /robot2/, fleet/robot3]\nrequests: {workers: 3}\n");
  ASSERT_TRUE(ok.config) << Joined(ok.errors);
  EXPECT_EQ(ok.config->robots, (std::vector<std::string>{"robot1", "robot2", "fleet/robot3"}));
  EXPECT_EQ(ok.config->workers, 3);
  EXPECT_EQ(dds_topic_name(robot_view(*ok.config, "robot2"), "goal_pose"),
            "rt/site/robot2/goal_pose");
  const NodeConfig defaults = *parse_config("").config;
  EXPECT_TRUE(defaults.robots.empty());
  EXPECT_EQ(defaults.workers, 0);  // one per core
  for (const char* bad : {"[robot1, robot1]", "[robot1, /robot1]", "[\"\"]", "[\"r 1\"]",
                          "[\"~r\"]", "robot1", "[[robot1]]", "{a: b}"}) {
    const ConfigResult r = parse_config(std::string("robots: ") + bad + "\n");
    EXPECT_TRUE(HasError(r, "robots", {"expected a list of distinct robot names"}))
        << bad << Joined(r.errors);
  }
  std::string many = "robots: [";
  for (size_t i = 0; i <= kMaxRobots; ++i) many += (i ? ", r" : "r") + std::to_string(i);
  EXPECT_TRUE(HasError(parse_config(many + "]\n"), "robots", {"at most"}));
  for (const char* bad : {"-1", "257", "1.5", "many"}) {
    const ConfigResult r = parse_config(std::string("requests: {workers: ") + bad + "}\n");
    EXPECT_TRUE(HasError(r, "requests.workers")) << bad << Joined(r.errors);
  }
}

// planner.vns_threads (VNS-BA* on two threads) was removed: a file that still gives it, with any
// value, is refused by the key's name with what to do, among the file's other errors, and never
// as an unknown key.
TEST(Config, RemovedVnsThreadsIsRefusedByName) {
  for (const char* value : {"1", "2", "auto"}) {
    const ConfigResult r =
        parse_config(std::string("planner: {vns_threads: ") + value + ", omega: abc}\n");
    EXPECT_FALSE(r.config.has_value()) << value;
    EXPECT_EQ(r.errors.size(), 2u) << Joined(r.errors);
    EXPECT_TRUE(HasError(r, "planner.vns_threads", {"removed", "delete the key"}))
        << Joined(r.errors);
    EXPECT_TRUE(HasError(r, "planner.omega"));
    for (const std::string& e : r.errors) EXPECT_EQ(e.find("unknown key"), std::string::npos) << e;
  }
}

// Issue 18, item 3: the XML participant profile's name (looked up when a participant is made).
TEST(Config, DdsParticipantProfileIsAName) {
  const ConfigResult ok = parse_config("dds: {participant_profile: robot_profile}\n");
  ASSERT_TRUE(ok.config) << Joined(ok.errors);
  EXPECT_EQ(ok.config->participant_profile, "robot_profile");
  EXPECT_EQ(parse_config("").config->participant_profile, "");
  EXPECT_TRUE(HasError(parse_config("dds: {participant_profile: [a]}\n"), "dds.participant_profile",
                       {"a profile name"}));
  EXPECT_TRUE(HasError(parse_config("dds: {profile: a}\n"), "dds.profile"));
}

TEST(Config, RosDistroIsJazzyHumbleOrKiltedAndRefusedByName) {
  for (const auto& [text, distro] :
       {std::pair{"", RosDistro::kJazzy}, std::pair{"ros: {distro: humble}\n", RosDistro::kHumble},
        std::pair{"ros: {distro: kilted}\n", RosDistro::kKilted},
        std::pair{"ros: {distro: jazzy}\n", RosDistro::kJazzy}}) {
    const ConfigResult parsed = parse_config(text);
    ASSERT_TRUE(parsed.config.has_value()) << text;
    EXPECT_EQ(parsed.config->ros_distro, distro) << text;
  }
  // An unknown distribution names the key and every allowed value, beside the file's other
  // errors (all reported at once).
  const ConfigResult r = parse_config("ros: {distro: iron}\ndebug: {publish: maybe}\n");
  EXPECT_FALSE(r.config.has_value());
  EXPECT_TRUE(HasError(r, "ros.distro", {"\"iron\"", "humble, jazzy, kilted"}));
  EXPECT_TRUE(HasError(r, "debug.publish", {"\"maybe\""}));
  // config_as_yaml prints it and it loads back.
  const ConfigResult kilted = parse_config("ros: {distro: kilted}\n");
  ASSERT_TRUE(kilted.config.has_value());
  const ConfigResult reloaded = parse_config(config_as_yaml(*kilted.config));
  ASSERT_TRUE(reloaded.config.has_value());
  EXPECT_EQ(reloaded.config->ros_distro, RosDistro::kKilted);
}

}  // namespace
}  // namespace vnsba::node
