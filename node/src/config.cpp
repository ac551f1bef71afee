// Node configuration from YAML (config/default.yaml documents every key).
//
// One reader per YAML map (Section): each typed getter registers its key, checks the value and
// stores it only when valid, otherwise records one error and keeps the default. finish() then
// reports the keys nobody asked for (typos) and repeated keys. So every problem of a file is
// reported in one pass, and the schema is the sequence of getter calls that read_config() makes
// through its section readers (read_map, read_planner, ...).
#include "vnsba/node/config.hpp"

#include <arpa/inet.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <thread>
#include <utility>

#include "vnsba/core/planner_registry.hpp"
#include "vnsba/node/default_config_text.hpp"
#include "vnsba/node/security.hpp"
#include "vnsba/node/spelling.hpp"
#include "vnsba/yaml/document.hpp"

namespace vnsba::node {
namespace {

using Errors = std::vector<std::string>;

std::string join(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& w : words) out += (out.empty() ? "" : ", ") + w;
  return out;
}

// How a value found in the file is quoted in messages.
std::string describe(const YAML::Node& node) {
  if (!node.IsScalar()) return yaml::kind_of(node);  // "a list", "a map", "no value"
  const std::string& s = node.Scalar();
  return '"' + (s.size() > 60 ? s.substr(0, 57) + "..." : s) + '"';
}

// Strict base-10 integer ("65", "+65", "-3"); rejects "6.5", "0x41", "1e3", overflow.
bool parse_integer(const YAML::Node& node, long long& out) {
  if (!node.IsScalar()) return false;
  const std::string& s = node.Scalar();
  const char* first = s.data();
  const char* last = s.data() + s.size();
  if (s.size() > 1 && s[0] == '+' && s[1] >= '0' && s[1] <= '9') ++first;
  const auto [end, ec] = std::from_chars(first, last, out);
  return ec == std::errc{} && end == last && first != last;
}

// "" when `name` is a valid topic name, else what was expected instead.
std::string topic_name_problem(const std::string& name) {
  auto is_digit = [](char c) { return c >= '0' && c <= '9'; };
  auto is_allowed = [&](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || is_digit(c) || c == '_' ||
           c == '/' || c == '~';
  };
  if (name.empty()) return "a non-empty topic name";
  if (!std::all_of(name.begin(), name.end(), is_allowed))
    return "a topic name of letters, digits, '_', '/' and '~' only";
  if (name.find('~', 1) != std::string::npos) return "a topic name with '~' only at its start";
  if (name.find("//") != std::string::npos || name.back() == '/')
    return "a topic name without empty parts (no \"//\", no trailing '/')";
  for (size_t i = 0; i < name.size(); ++i)
    if (is_digit(name[i]) && (i == 0 || name[i - 1] == '/'))
      return "a topic name whose parts do not start with a digit";
  return "";
}

// A getter's target is a plain field (an absent key keeps its value) or an optional setting
// (an absent key leaves it unset); value_of<Out> is what the check reads either way.
template <class T>
struct ValueOf {
  using type = T;
};
template <class T>
struct ValueOf<std::optional<T>> {
  using type = T;
};
template <class Out>
using value_of = typename ValueOf<Out>::type;

template <class T>
T current(const T& out) {
  return out;
}
template <class T>
T current(const std::optional<T>& out) {
  return out.value_or(T{});
}
// Whether a getter's target holds a value (an optional setting may be unset).
template <class T>
bool holds_value(const T&) {
  return true;
}
template <class T>
bool holds_value(const std::optional<T>& out) {
  return out.has_value();
}

// A value as YAML text, for config_as_yaml: numbers in their shortest round-trip form (0.15, not
// 0.14999999999999999), strings double-quoted, lists in flow style.
std::string yaml_quoted(const std::string& text) {
  std::string out = "\"";
  for (const char ch : text) {
    if (ch == '"' || ch == '\\') out += '\\';
    out += ch;
  }
  return out + "\"";
}
struct ShowValue {
  std::string operator()(bool v) const { return v ? "true" : "false"; }
  std::string operator()(double v) const {
    char buffer[64];
    const auto [end, ec] = std::to_chars(buffer, buffer + sizeof(buffer), v);
    return ec == std::errc{} ? std::string(buffer, end) : std::to_string(v);
  }
  std::string operator()(const std::string& v) const { return yaml_quoted(v); }
  std::string operator()(const std::vector<std::string>& v) const {
    std::string out;
    for (const std::string& item : v) out += (out.empty() ? "" : ", ") + yaml_quoted(item);
    return "[" + out + "]";
  }
  template <class Int, class = std::enable_if_t<std::is_integral_v<Int>>>
  std::string operator()(Int v) const {
    return std::to_string(v);
  }
};

// Each key's effective value, dotted key path first ("map.robot_radius"), in schema order.
using Settings = std::vector<std::pair<std::string, std::string>>;

class Section {
 public:
  // `node` may be absent or null (an empty section); `path` is its dotted key ("" at the top).
  // `shown`, when given, receives every key the file leaves out with the value it keeps (a
  // std::optional left unset is not shown): read over an empty file, the whole configuration.
  Section(const YAML::Node& node, std::string path, Errors& errors, Settings* shown = nullptr)
      : path_(std::move(path)), errors_(&errors), shown_(shown) {
    if (!node.IsMap()) return;
    for (const auto& kv : node) entries_.push_back({kv.first, kv.second});
  }

  std::string key_path(const std::string& key) const {
    return path_.empty() ? key : path_ + "." + key;
  }
  void error(const std::string& key, const YAML::Node& found, const std::string& expected) {
    errors_->push_back(key_path(key) + ": found " + describe(found) + ", expected " + expected);
  }

  // Records a problem found across keys (the message names them); one found by a getter is
  // recorded by the getter.
  void report(std::string message) { errors_->push_back(std::move(message)); }

  // Whether this file gives `key` (registers it as known, like every getter).
  bool has(const std::string& key) { return find(key) != nullptr; }

  // A nested map; a scalar or list there is an error and reads as an empty section.
  Section child(const std::string& key) {
    const YAML::Node* node = find(key);
    if (node && !node->IsMap() && !node->IsNull()) error(key, *node, "a map of settings");
    return Section(node ? *node : YAML::Node(), key_path(key), *errors_, shown_);
  }

  // Every getter: an absent key keeps `out` (a std::optional stays unset) and returns true.
  // Otherwise `check(node, value)` returns "" and sets `value` when the node is acceptable, else
  // what was expected; the error is recorded, `out` keeps its value and the getter returns false.
  // `show` turns the value into YAML text for `shown`.
  template <class Out, class Check, class Show = ShowValue>
  bool get(const std::string& key, Out& out, Check check, Show show = {}) {
    const YAML::Node* node = find(key);
    if (!node) {
      if (shown_ != nullptr && holds_value(out))
        shown_->emplace_back(key_path(key), show(current(out)));
      return true;
    }
    value_of<Out> value = current(out);
    const std::string expected = check(*node, value);
    if (expected.empty())
      out = std::move(value);
    else
      error(key, *node, expected);
    return expected.empty();
  }

  // An integer in lo..hi; `unit` (e.g. "MiB"), when given, is said in the message.
  template <class Int>
  bool integer(const std::string& key, Int& out, long long lo, long long hi,
               const std::string& unit = "") {
    return get(key, out, [&](const YAML::Node& node, value_of<Int>& value) {
      long long v = 0;
      if (!parse_integer(node, v) || v < lo || v > hi)
        return (unit.empty() ? "an integer in " : "an integer number of " + unit + " in ") +
               std::to_string(lo) + ".." + std::to_string(hi);
      value = static_cast<value_of<Int>>(v);
      return std::string();
    });
  }

  // A finite number accepted by `in_range`; `expected` says what that is.
  template <class Out, class InRange>
  bool number(const std::string& key, Out& out, const std::string& expected, InRange in_range) {
    return get(key, out, [&](const YAML::Node& node, double& value) {
      const bool ok = node.IsScalar() && YAML::convert<double>::decode(node, value) &&
                      std::isfinite(value) && in_range(value);
      return ok ? std::string() : expected;
    });
  }

  template <class Out>
  bool boolean(const std::string& key, Out& out) {
    return get(key, out, [](const YAML::Node& node, bool& value) {
      const bool ok = node.IsScalar() && YAML::convert<bool>::decode(node, value);
      return std::string(ok ? "" : "true or false");
    });
  }

  // A string; `problem(text)` returns "" when it is acceptable, else what was expected.
  template <class Problem>
  bool text(const std::string& key, std::string& out, const std::string& what, Problem problem) {
    return get(key, out, [&](const YAML::Node& node, std::string& value) {
      if (!node.IsScalar()) return what;
      value = node.Scalar();
      return std::string(problem(value));
    });
  }

  // One of `names`; `parse` maps a name to the value (an optional).
  template <class Out, class Parse>
  bool choice(const std::string& key, Out& out, Parse parse,
              const std::vector<std::string>& names) {
    // A value shows as the name that parses to it.
    auto show = [&](const value_of<Out>& value) {
      for (const std::string& name : names)
        if (const auto parsed = parse(name); parsed && *parsed == value) return yaml_quoted(name);
      return std::string("\"?\"");
    };
    return get(
        key, out,
        [&](const YAML::Node& node, value_of<Out>& value) {
          if (auto parsed = node.IsScalar() ? parse(node.Scalar()) : std::nullopt) {
            value = *parsed;
            return std::string();
          }
          const std::string near = node.IsScalar() ? closest(node.Scalar(), names) : "";
          return "one of " + join(names) +
                 (near.empty() ? "" : " (did you mean \"" + near + "\"?)");
        },
        show);
  }

  // One of the names of a {name, value} table.
  template <class T>
  bool choice(const std::string& key, T& out, const std::vector<std::pair<std::string, T>>& table) {
    std::vector<std::string> names;
    for (const auto& entry : table) names.push_back(entry.first);
    auto parse = [&](const std::string& s) -> std::optional<T> {
      for (const auto& [name, value] : table)
        if (name == s) return value;
      return std::nullopt;
    };
    return choice(key, out, parse, names);
  }

  // Reports keys no getter asked for, and keys given twice.
  void finish() {
    for (size_t i = 0; i < entries_.size(); ++i) {
      const YAML::Node& key_node = entries_[i].first;
      const std::string where = path_.empty() ? "top level" : path_;
      if (!key_node.IsScalar()) {
        errors_->push_back(where + ": found " + describe(key_node) +
                           " as a key, expected a key name");
        continue;
      }
      const std::string& key = key_node.Scalar();
      if (key.empty()) {  // `? |` or `"": 1`: there is no name to put in the message
        errors_->push_back(where + ": found an empty key, expected one of " + join(known_));
      } else if (std::find(known_.begin(), known_.end(), key) == known_.end()) {
        const std::string near = closest(key, known_);
        errors_->push_back(key_path(key) + ": unknown key" +
                           (near.empty() ? ", expected one of " + join(known_)
                                         : " (did you mean \"" + key_path(near) + "\"?)"));
      } else if (std::any_of(entries_.begin(), entries_.begin() + i, [&](const auto& e) {
                   return e.first.IsScalar() && e.first.Scalar() == key;
                 })) {
        errors_->push_back(key_path(key) + ": found the key again, expected each key once");
      }
    }
  }

 private:
  // The value of `key` (the first one when repeated) or nullptr; registers `key` as known.
  const YAML::Node* find(const std::string& key) {
    known_.push_back(key);
    for (const auto& [k, v] : entries_)
      if (k.IsScalar() && k.Scalar() == key) return &v;
    return nullptr;
  }

  std::string path_;
  Errors* errors_;
  Settings* shown_;
  std::vector<std::pair<YAML::Node, YAML::Node>> entries_;
  std::vector<std::string> known_;
};

std::chrono::microseconds to_microseconds(double seconds) {
  long long us = std::llround(seconds * 1e6);
  if (seconds > 0.0 && us == 0) us = 1;  // a tiny budget must not turn into "unlimited"
  return std::chrono::microseconds{us};
}

template <class Enum>
std::vector<std::string> names_of(std::initializer_list<Enum> values) {
  std::vector<std::string> out;
  for (Enum v : values) out.emplace_back(core::to_string(v));
  return out;
}

// Every topics.* key with its field, in the order default.yaml lists them.
std::vector<std::pair<const char*, std::string*>> topic_keys(TopicNames& t) {
  return {{"projected_map", &t.projected_map},
          {"goal_pose", &t.goal_pose},
          {"robot_pose", &t.robot_pose},
          {"plan_request", &t.plan_request},
          {"plan", &t.plan},
          {"plan_status", &t.plan_status},
          {"planner_debug", &t.planner_debug},
          {"octomap", &t.octomap},
          {"plan_raw", &t.plan_raw},
          {"plan_pruned", &t.plan_pruned},
          {"expansions_forward", &t.expansions_forward},
          {"expansions_backward", &t.expansions_backward},
          {"meeting_point", &t.meeting_point},
          {"tf", &t.tf},
          {"tf_static", &t.tf_static},
          {"clock", &t.clock},
          {"compute_path_to_pose", &t.compute_path_to_pose},
          {"compute_path_through_poses", &t.compute_path_through_poses},
          {"is_path_valid", &t.is_path_valid}};
}
// The topics.* keys that name actions: ROS 2 derives longer names from them (kActionSuffix).
const std::set<std::string> kActionKeys = {"compute_path_to_pose", "compute_path_through_poses"};
// The longest name an action's services and topics add to it (rcl_action).
constexpr const char* kActionSuffix = "/_action/cancel_goal";
// The topics a node reads once for all its robots, under its own namespace.
const std::set<std::string> kSharedTopicKeys = {"projected_map", "octomap", "tf", "tf_static",
                                                "clock"};

// The readers of the sections, one function each, in the order read_config calls them. The order
// is the schema's: it is the order of the error messages, of the keys a "did you mean" or an
// "expected one of" lists, and of the lines config_as_yaml prints. A key of the top level is read
// by the reader its meaning belongs to; a section reader takes the top level, opens its own map
// (Section::child) and closes it (Section::finish: unknown and repeated keys). A check across keys
// runs where both keys have been read and reports through Section::report.

std::string frame_name_problem(const std::string& s) {
  if (s.empty()) return "a non-empty frame name";
  if (s.size() > kMaxFrameIdBytes)
    return "a frame name of at most " + std::to_string(kMaxFrameIdBytes) +
           " bytes (a request's frame_id is refused past it, so every goal would be)";
  return "";
}

// Top level: the DDS domain, the node's name and lifecycle, ROS 2 naming, the frame and the
// namespace.
void read_naming(Section& top, NodeConfig& c) {
  top.integer("domain_id", c.domain_id, 0, 232);
  top.text("node_name", c.node_name, "a ROS 2 node name", node_name_problem);
  top.choice<LifecycleMode>(
      "lifecycle", c.lifecycle,
      {{"self_activating", LifecycleMode::kSelfActivating}, {"managed", LifecycleMode::kManaged}});
  top.boolean("ros2_naming", c.ros2_naming);
  top.text("frame_id", c.frame_id, "a frame name", frame_name_problem);
  // ROS 2 namespace of the relative topic names (see normalized_namespace).
  std::string given = c.ros_namespace;
  if (top.text("namespace", given, "a namespace", [](const std::string& s) {
        const auto ns = normalized_namespace(s);
        return ns ? std::string() : ns.error().message;
      })) {
    if (auto ns = normalized_namespace(given)) c.ros_namespace = *ns;
  }
}

// Top level, robots: one node serving several robots, each a namespace under `namespace`.
void read_robots(Section& top, NodeConfig& c) {
  top.get("robots", c.robots, [](const YAML::Node& node, std::vector<std::string>& value) {
    const std::string expected =
        "a list of distinct robot names, each a namespace under `namespace` (e.g. [robot1, "
        "robot2]), at most " +
        std::to_string(kMaxRobots);
    if (!node.IsSequence() && !node.IsNull()) return expected;
    std::vector<std::string> robots;
    for (const YAML::Node& item : node) {
      if (!item.IsScalar()) return expected;
      const auto name = normalized_namespace(item.Scalar());
      if (!name) return expected + ": \"" + item.Scalar() + "\" is not " + name.error().message;
      if (name->empty()) return expected + ": \"" + item.Scalar() + "\" is empty";
      if (std::find(robots.begin(), robots.end(), *name) != robots.end())
        return expected + ": \"" + *name + "\" is listed twice";
      robots.push_back(*name);
    }
    if (robots.size() > kMaxRobots) return expected + ": found " + std::to_string(robots.size());
    value = std::move(robots);
    return std::string();
  });
}

// topics: every name valid and no two the same topic once resolved; then, across the namespace,
// the robots and the topics, no full name longer than ROS 2 allows.
void read_topics(Section& top, NodeConfig& c) {
  Section topics = top.child("topics");
  const auto topic_fields = topic_keys(c.topics);
  std::vector<std::pair<const char*, const std::string*>> valid;  // read without error
  for (const auto& [key, name] : topic_fields) {
    if (!topics.text(key, *name, "a topic name", topic_name_problem)) continue;
    // As resolved: "/plan" and "plan" are one topic without a namespace, two with one.
    for (const auto& [other_key, other] : valid)
      if (dds_topic_name(c, *other) == dds_topic_name(c, *name))
        topics.report(topics.key_path(other_key) + ", " + topics.key_path(key) + ": found \"" +
                      *other + "\" and \"" + *name + "\", expected different topics");
    valid.emplace_back(key, name);
  }
  topics.finish();
  if (std::string problem = overlong_topic_name(c); !problem.empty())
    top.report(std::move(problem));
}

// Top level: where goal_pose goals start (a pose topic or tf) and which clock the node keeps.
void read_robot_pose(Section& top, NodeConfig& c) {
  top.choice<RobotPoseSource>("robot_pose_source", c.robot_pose_source,
                              {{"topic", RobotPoseSource::kTopic}, {"tf", RobotPoseSource::kTf}});
  top.choice<RobotPoseType>(
      "robot_pose_type", c.robot_pose_type,
      {{"PoseStamped", RobotPoseType::kPoseStamped},
       {"PoseWithCovarianceStamped", RobotPoseType::kPoseWithCovarianceStamped}});
  top.text("base_frame", c.base_frame, "a frame name", frame_name_problem);
  top.number("transform_tolerance", c.transform_tolerance_s,
             "a finite number of seconds in [0, 60]",
             [](double v) { return v >= 0.0 && v <= 60.0; });
  top.boolean("use_sim_time", c.use_sim_time);
  if (!c.base_frame.empty() &&
      without_leading_slash(c.base_frame) == without_leading_slash(c.frame_id))
    top.report("base_frame: found \"" + c.base_frame +
               "\", expected the robot's frame, not frame_id (\"" + c.frame_id + "\")");
}

// map: how a slice becomes a planning grid.
void read_map(Section& top, NodeConfig& c) {
  Section map = top.child("map");
  map.integer("occupied_threshold", c.map.occupied_threshold, 1, 100);
  map.boolean("allow_unknown", c.map.allow_unknown);
  map.boolean("inflate_unknown", c.map.inflate_unknown);
  const bool radius_ok =
      map.number("robot_radius", c.map.robot_radius, "a finite number of metres >= 0",
                 [](double v) { return v >= 0.0; });
  // The cost gradient beyond robot_radius (docs/algorithm.md section 8, Nav2's inflation layer).
  const bool inflation_ok = map.number("inflation_radius", c.map.inflation_radius,
                                       "a finite number of metres >= 0 (0 = no cost gradient)",
                                       [](double v) { return v >= 0.0; });
  if (radius_ok && inflation_ok && c.map.inflation_radius > 0.0 &&
      c.map.inflation_radius < c.map.robot_radius) {
    std::ostringstream msg;
    msg << "map.inflation_radius: found \"" << c.map.inflation_radius
        << "\", expected 0 (no cost gradient) or a number of metres >= map.robot_radius ("
        << c.map.robot_radius << " m): the gradient starts at the robot's radius";
    map.report(msg.str());
  }
  map.number("cost_scaling_factor", c.map.cost_scaling_factor, "a finite number per metre >= 0",
             [](double v) { return v >= 0.0; });
  map.integer("max_cells", c.map.max_cells, 1, core::kMaxCellsLimit);
  map.integer("memory_budget_mb", c.map_memory_budget_mb, 1, kMaxMapMemoryBudgetMb, "MiB");
  map.choice("durability", c.map_durability,
             {{"transient_local", MapDurability::kTransientLocal},
              {"volatile", MapDurability::kVolatile}});
  map.choice("cost_source", c.map_cost_source,
             {{"own", MapCostSource::kOwn}, {"costmap", MapCostSource::kCostmap}});
  map.finish();
}

// A planner.* number whose key, range, unit and message come from core's one table (kOmegaRange,
// ...).
bool read_planner_number(Section& planner, const core::OptionRange& range,
                         std::optional<double>& out) {
  return planner.number(range.key, out, range.describe(),
                        [&range](double v) { return range.contains(v); });
}

// planner.name: auto or a planner.
void read_planner_name(Section& planner, PlannerConfig& p) {
  std::vector<std::string> planner_names = {std::string(core::kAutoPlannerName)};
  for (core::PlannerKind k : core::all_planner_kinds()) planner_names.emplace_back(to_string(k));
  std::string name =
      p.auto_kind ? std::string(core::kAutoPlannerName) : std::string(to_string(p.kind));
  planner.choice(
      "name", name,
      [&](const std::string& text) -> std::optional<std::string> {
        if (std::find(planner_names.begin(), planner_names.end(), text) == planner_names.end())
          return std::nullopt;
        return text;
      },
      planner_names);
  p.auto_kind = name == core::kAutoPlannerName;
  // auto: the cost-aware choice until cost_weight and the moves are read (read_planner_costs),
  // which supports every option, so that no check before then refuses what auto will not pick.
  p.kind =
      p.auto_kind ? core::kCostAwareChoice : core::planner_kind_from_string(name).value_or(p.kind);
}

// planner.aliases: a map of other names to planners ("default": planner.name).
void read_planner_aliases(Section& planner, PlannerConfig& p) {
  std::vector<std::string> targets = {kDefaultPlannerAlias, std::string(core::kAutoPlannerName)};
  for (core::PlannerKind k : core::all_planner_kinds()) targets.emplace_back(to_string(k));
  planner.get(
      "aliases", p.aliases,
      [&](const YAML::Node& node,
          std::vector<std::pair<std::string, std::string>>& value) -> std::string {
        const std::string expected =
            "a map of names to planners, e.g. {GridBased: default} (each name at most " +
            std::to_string(kMaxPlannerNameBytes) +
            " bytes and not itself a planner; each planner one of " + join(targets) + ")";
        if (node.IsNull()) {
          value.clear();
          return "";
        }
        if (!node.IsMap()) return expected;
        std::vector<std::pair<std::string, std::string>> aliases;
        for (const auto& entry : node) {
          if (!entry.first.IsScalar() || !entry.second.IsScalar()) return expected;
          const std::string& name = entry.first.Scalar();
          const std::string& target = entry.second.Scalar();
          if (name.empty() || name.size() > kMaxPlannerNameBytes ||
              std::find(targets.begin(), targets.end(), name) != targets.end())
            return expected + ": " + describe(entry.first) + " is not an alias name";
          if (std::find(targets.begin(), targets.end(), target) == targets.end())
            return expected + ": " + describe(entry.second) + " is not a planner";
          for (const auto& [earlier, unused] : aliases)
            if (earlier == name) return expected + ": " + describe(entry.first) + " given twice";
          aliases.emplace_back(name, target);
        }
        value = std::move(aliases);
        return "";
      },
      [](const std::vector<std::pair<std::string, std::string>>& aliases) {
        std::string out = "{";
        for (const auto& [name, target] : aliases)
          out += (out.size() > 1 ? ", " : "") + yaml_quoted(name) + ": " + yaml_quoted(target);
        return out + "}";
      });
}

// The keys planners own (planner.omega and planner.eta: VNS-BA*'s heuristic weights), read
// whichever planner is named (a request may switch to their owner), then the named planner's own
// rules (for VNS-BA*: not both 0).
void read_planner_own_options(Section& planner, PlannerConfig& p) {
  core::PlannerSettings& s = p.settings;
  bool all_ok = true;
  for (const core::OwnOption* own : core::all_own_options())
    all_ok = read_planner_number(planner, *own->range, s.*own->setting) && all_ok;
  const core::PlannerDescriptor* named = p.kind.descriptor();
  if (!all_ok || named == nullptr || named->check_own_options == nullptr) return;
  std::vector<core::OptionProblem> problems;
  named->check_own_options(p.options(), problems);
  for (const core::OptionProblem& problem : problems) {
    std::string keys;
    for (std::string_view key : problem.keys)
      keys += (keys.empty() ? "planner." : ", planner.") + std::string(key);
    planner.report(keys + ": " + problem.found_expected + " for " + std::string(named->name) +
                   " (" + problem.why + ")");
  }
}

// planner.neighborhood, planner.corner_policy: the moves, as the planner supports them.
void read_planner_moves(Section& planner, PlannerConfig& p) {
  core::PlannerSettings& s = p.settings;
  planner.choice("neighborhood", s.neighborhood, core::neighborhood_from_string,
                 names_of({core::Neighborhood::kEight, core::Neighborhood::kEightElevenThirteen}));
  planner.choice("corner_policy", s.corner_policy, core::corner_policy_from_string,
                 names_of({core::CornerPolicy::kNever, core::CornerPolicy::kTouch,
                           core::CornerPolicy::kAlways}));
  // Named here by key (core::validate says the same to requests, without the key path).
  const core::PlannerOptions moves = p.options();
  const core::PlannerDescriptor* named = p.kind.descriptor();
  if (named == nullptr) return;
  if (!core::supports(p.kind, moves.corner_policy))
    planner.report("planner.corner_policy: found \"" + std::string(to_string(moves.corner_policy)) +
                   "\", expected never for " + std::string(named->name) + " (" +
                   std::string(named->can.without_corner_cutting) + ")");
  if (!core::supports(p.kind, moves.neighborhood))
    planner.report("planner.neighborhood: found \"" + std::string(to_string(moves.neighborhood)) +
                   "\", expected 8 for " + std::string(named->name) + " (" +
                   std::string(named->can.without_long_moves) + ")");
}

// planner.prune ... planner.smoother_iterations: pruning, smoothing and the relax smoother.
void read_planner_postprocessing(Section& planner, PlannerConfig& p) {
  core::PlannerSettings& s = p.settings;
  planner.boolean("prune", s.prune);
  planner.boolean("smooth", s.smooth);
  read_planner_number(planner, core::kSmoothingDistanceRange, s.smoothing_distance);
  read_planner_number(planner, core::kSampleStepRange, s.sample_step);
  planner.choice("smoother", s.smoother, core::path_smoother_from_string,
                 names_of({core::PathSmoother::kNone, core::PathSmoother::kRelax}));
  const bool smoothness_ok =
      read_planner_number(planner, core::kSmootherSmoothnessRange, s.smoother_smoothness);
  const bool closeness_ok =
      read_planner_number(planner, core::kSmootherClosenessRange, s.smoother_closeness);
  const core::PlannerOptions relax = p.options();
  if (smoothness_ok && closeness_ok &&
      !(2.0 * relax.smoother_smoothness + relax.smoother_closeness < 2.0)) {
    std::ostringstream msg;
    msg << "planner.smoother_smoothness, planner.smoother_closeness: found "
        << relax.smoother_smoothness << " and " << relax.smoother_closeness
        << ", expected 2 * smoother_smoothness + smoother_closeness below 2 (the relaxation "
           "would overshoot further each iteration)";
    planner.report(msg.str());
  }
  read_planner_number(planner, core::kSmootherCostRange, s.smoother_cost);
  planner.integer(core::kSmootherIterationsRange.key, s.smoother_iterations,
                  static_cast<long long>(core::kSmootherIterationsRange.min),
                  static_cast<long long>(core::kSmootherIterationsRange.max));
}

// planner.max_planning_time (seconds, stored in microseconds), planner.compute_length_ratio.
void read_planner_budget(Section& planner, PlannerConfig& p) {
  core::PlannerSettings& s = p.settings;
  std::optional<double> seconds;
  if (s.max_planning_time) seconds = static_cast<double>(s.max_planning_time->count()) / 1e6;
  planner.number(core::kMaxPlanningTimeRange.key, seconds,
                 core::kMaxPlanningTimeRange.describe() + " (0 = unlimited)",
                 [](double v) { return core::kMaxPlanningTimeRange.contains(v); });
  if (seconds) s.max_planning_time = to_microseconds(*seconds);
  planner.boolean("compute_length_ratio", s.compute_length_ratio);
}

// docs/algorithm.md section 8: costs, tolerances and path poses. Absent = 0 (the paper's binary
// grid, exact start and goal) and the map's resolution for path_spacing. With every key that
// decides it read, auto resolves to its planner here.
void read_planner_costs(Section& planner, PlannerConfig& p) {
  core::PlannerSettings& s = p.settings;
  // A cost_weight the file leaves out is default.yaml's, meant for the planners that weigh costs:
  // with jps it is no contradiction, and each plan says it ran on uniform costs (requests.cpp).
  const bool cost_weight_given = planner.has("cost_weight");
  const bool cost_weight_ok = read_planner_number(planner, core::kCostWeightRange, s.cost_weight);
  if (cost_weight_given && cost_weight_ok && s.cost_weight && *s.cost_weight > 0.0 &&
      !core::supports_costs(p.kind)) {
    std::ostringstream msg;
    msg << "planner.cost_weight: found \"" << *s.cost_weight << "\", expected 0 for "
        << to_string(p.kind) << " (" << p.kind.descriptor()->can.without_costs
        << "; use a planner that supports costs, such as vns_bastar or astar)";
    planner.report(msg.str());
  }
  for (const auto& [key, out] : {std::pair{"goal_tolerance", &s.goal_tolerance},
                                 std::pair{"start_tolerance", &s.start_tolerance}}) {
    planner.number(key, *out, core::kToleranceRange.describe() + " (0 = exact)",
                   [](double v) { return core::kToleranceRange.contains(v); });
  }
  if (p.auto_kind) p.kind = core::make_auto_options(s).planner;
  planner.number(kPathSpacingRange.key, p.path_spacing,
                 kPathSpacingRange.describe() + " (absent = the map's resolution)",
                 [](double v) { return kPathSpacingRange.contains(v); });
}

// planner: every key the file gives becomes a setting; a key left out stays unset, so that it
// follows the paper configuration of whichever planner runs (the configured one or a request's).
void read_planner(Section& top, NodeConfig& c) {
  Section planner = top.child("planner");
  read_planner_name(planner, c.planner);
  read_planner_aliases(planner, c.planner);
  read_planner_own_options(planner, c.planner);
  read_planner_moves(planner, c.planner);
  read_planner_postprocessing(planner, c.planner);
  read_planner_budget(planner, c.planner);
  read_planner_costs(planner, c.planner);
  // Removed keys: refused by name with what replaced them, not as unknown keys.
  if (planner.has("vns_threads"))
    planner.report(
        "planner.vns_threads: removed, delete the key: VNS-BA* plans on one thread per request "
        "(two threads in lockstep saved too little time to keep; docs/limitations.md)");
  planner.finish();
}

// A number of seconds in [0, max_s], stored in milliseconds.
void read_milliseconds(Section& section, const char* key, std::chrono::milliseconds& out,
                       double max_s, double min_s = 0.0) {
  std::optional<double> value_s = static_cast<double>(out.count()) / 1000.0;
  std::ostringstream expected;
  expected << "a finite number of seconds in [" << min_s << ", " << max_s << "]";
  if (section.number(key, value_s, expected.str(),
                     [min_s, max_s](double v) { return v >= min_s && v <= max_s; }) &&
      value_s) {
    out = std::chrono::milliseconds(std::llround(*value_s * 1000.0));
  }
}

// requests: the queue, its workers and how long a request waits for a reply or a map.
void read_requests(Section& top, NodeConfig& c) {
  Section requests = top.child("requests");
  requests.boolean("preempt", c.preempt);
  requests.integer("queue_capacity", c.queue_capacity, 1, 100000);
  requests.integer("workers", c.workers, 0, kMaxWorkers);
  read_milliseconds(requests, "reply_wait", c.reply_wait, 10.0);
  read_milliseconds(requests, "map_wait", c.map_wait, 60.0);
  requests.finish();
}

// actions: Nav2's planner actions.
void read_actions(Section& top, NodeConfig& c) {
  Section actions = top.child("actions");
  actions.boolean("enabled", c.actions.enabled);
  read_milliseconds(actions, "result_timeout", c.actions.result_timeout, 86400.0);
  actions.integer("max_results", c.actions.max_results, 1, 100000);
  actions.choice<ReplyMapping>("reply_mapping", c.actions.reply_mapping,
                               {{"auto", ReplyMapping::kAuto},
                                {"fastrtps", ReplyMapping::kFastRtps},
                                {"cyclonedds", ReplyMapping::kCycloneDds}});
  actions.integer("kept_results_mb", c.actions.kept_results_mb, 1, 65536);
  actions.integer("max_result_poses", c.actions.max_result_poses, 1, 10000000);
  actions.integer("max_goal_poses", c.actions.max_goal_poses, 1, 100000);
  actions.integer("replies_in_flight_mb", c.actions.replies_in_flight_mb, 1, 4096);
  read_milliseconds(actions, "reply_ack_timeout", c.actions.reply_ack_timeout, 60.0, 0.05);
  actions.integer("max_pending_replies", c.actions.max_pending_replies, 1, 100000);
  actions.integer("status_finished_goals", c.actions.status_finished_goals, 0, 100000);
  actions.finish();
}

// bond: the lifecycle manager's heartbeat (BondConfig).
void read_bond(Section& top, NodeConfig& c) {
  Section bond = top.child("bond");
  bond.choice<BondMode>(
      "mode", c.bond.mode,
      {{"managed", BondMode::kManaged}, {"always", BondMode::kAlways}, {"off", BondMode::kOff}});
  read_milliseconds(bond, "heartbeat_period", c.bond.heartbeat_period, 60.0, 0.01);
  bond.finish();
}

// network: which interfaces DDS uses.
void read_network(Section& top, NodeConfig& c) {
  Section network = top.child("network");
  network.boolean("localhost_only", c.localhost_only);
  network.finish();
}

// discovery: Discovery Server locators.
void read_discovery(Section& top, NodeConfig& c) {
  Section discovery = top.child("discovery");
  discovery.get(
      "servers", c.discovery_servers, [](const YAML::Node& node, std::vector<std::string>& value) {
        const std::string expected =
            "a list of Discovery Server locators \"IPv4:port\" (port 1..65535), e.g. "
            "[\"127.0.0.1:11811\"]";
        if (!node.IsSequence() && !node.IsNull()) return expected;
        std::vector<std::string> servers;
        for (const YAML::Node& item : node) {
          if (!item.IsScalar()) return expected;
          if (const std::string problem = discovery_server_problem(item.Scalar()); !problem.empty())
            return expected + ": \"" + item.Scalar() + "\" " + problem;
          servers.push_back(item.Scalar());
        }
        value = std::move(servers);
        return std::string();
      });
  discovery.finish();
}

// security: DDS Security (node/security.hpp); the ROS_SECURITY_* environment is applied after
// loading.
void read_security(Section& top, NodeConfig& c) {
  Section security = top.child("security");
  security.boolean("enable", c.security.enable);
  security.text("keystore", c.security.keystore, "a directory", [](const std::string&) {
    return std::string();  // any path; checked when a participant is created
  });
  security.text("enclave", c.security.enclave, "an enclave name", [](const std::string& s) {
    return s.empty() ? std::string() : enclave_name_problem(s);
  });
  security.choice<SecurityStrategy>(
      "strategy", c.security.strategy,
      {{"Enforce", SecurityStrategy::kEnforce}, {"Permissive", SecurityStrategy::kPermissive}});
  security.finish();
}

// dds: the Fast DDS XML profile of the participant.
void read_dds(Section& top, NodeConfig& c) {
  Section dds = top.child("dds");
  dds.text("participant_profile", c.participant_profile, "a profile name", [](const std::string&) {
    return std::string();  // any name; looked up in the XML profiles when a participant is made
  });
  dds.finish();
}

// ros: which ROS 2 distribution's wire types the node speaks.
void read_ros(Section& top, NodeConfig& c) {
  Section ros = top.child("ros");
  std::vector<std::pair<std::string, RosDistro>> distros;
  for (const RosDistro distro : kRosDistros) distros.emplace_back(distro_name(distro), distro);
  ros.choice<RosDistro>("distro", c.ros_distro, distros);
  ros.finish();
}

// debug: when the debug topics are published.
void read_debug(Section& top, NodeConfig& c) {
  Section debug = top.child("debug");
  debug.choice<DebugPublishing>("publish", c.debug,
                                {{"auto", DebugPublishing::kAuto},
                                 {"always", DebugPublishing::kAlways},
                                 {"never", DebugPublishing::kNever}});
  debug.finish();
}

// Top level, log_level: spdlog's level names.
void read_log_level(Section& top, NodeConfig& c) {
  std::vector<std::pair<std::string, std::string>> levels;
  for (const char* level : {"trace", "debug", "info", "warn", "error", "critical", "off"})
    levels.emplace_back(level, level);
  top.choice("log_level", c.log_level, levels);
}

// slicer: vnsba_slicer's height band and cells.
void read_slicer(Section& top, NodeConfig& c) {
  Section slicer = top.child("slicer");
  auto any = [](double) { return true; };
  const bool z_min_ok = slicer.number("z_min", c.slicer.z_min, "a finite number of metres", any);
  const bool z_max_ok = slicer.number("z_max", c.slicer.z_max, "a finite number of metres", any);
  if (z_min_ok && z_max_ok && c.slicer.z_max < c.slicer.z_min) {
    std::ostringstream msg;
    msg << "slicer.z_max: found \"" << c.slicer.z_max << "\", expected a height >= slicer.z_min ("
        << c.slicer.z_min << ")";
    slicer.report(msg.str());
  }
  slicer.number("resolution", c.slicer.resolution,
                "a finite number of metres >= 0 (0 = the tree's leaf size)",
                [](double v) { return v >= 0.0; });
  slicer.boolean("remove_speckles", c.slicer.remove_speckles);
  slicer.finish();
}

// Safety net for a file without errors: core's own checks must agree (they can only fire if core
// grows new rules).
void check_with_core(const NodeConfig& c, Errors& errors) {
  // As requests plan: a planner on uniform costs drops an inherited cost_weight (requests.cpp).
  core::PlannerOptions options = c.planner.options();
  core::drop_unsupported_costs(options);
  if (core::Status s = core::validate(options); !s.is_ok())
    errors.push_back("planner: " + s.message);
  if (core::Status s = core::validate(c.map); !s.is_ok()) errors.push_back("map: " + s.message);
}

// Reads `root` over `c`, every section in the schema's order. With `shown`, also lists every key
// `root` leaves out with the value it keeps (config_as_yaml reads an empty file so).
void read_config(const YAML::Node& root, NodeConfig& c, Errors& errors, Settings* shown = nullptr) {
  Section top(root, "", errors, shown);
  read_naming(top, c);
  read_robots(top, c);
  read_topics(top, c);
  read_robot_pose(top, c);
  read_map(top, c);
  read_planner(top, c);
  read_requests(top, c);
  read_actions(top, c);
  read_bond(top, c);
  read_network(top, c);
  read_discovery(top, c);
  read_security(top, c);
  read_dds(top, c);
  read_ros(top, c);
  read_debug(top, c);
  read_log_level(top, c);
  read_slicer(top, c);
  top.finish();
  if (errors.empty()) check_with_core(c, errors);
}

}  // namespace

std::string node_name_problem(const std::string& name) {
  auto is_digit = [](char ch) { return ch >= '0' && ch <= '9'; };
  auto is_allowed = [&](char ch) {
    return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || is_digit(ch) || ch == '_';
  };
  if (name.empty()) return "a non-empty node name";
  if (!std::all_of(name.begin(), name.end(), is_allowed))
    return "a node name of letters, digits and '_' only";
  if (is_digit(name.front())) return "a node name that does not start with a digit";
  if (name.size() > 255) return "a node name of at most 255 characters";
  return "";
}

std::string node_full_name(const NodeConfig& config) {
  return "/" + (config.ros_namespace.empty() ? "" : config.ros_namespace + "/") + config.node_name;
}

// The one maker of a blank NodeConfig (its constructor is private): default.yaml is read onto it.
struct ConfigReader {
  static NodeConfig blank() { return NodeConfig(); }
};

namespace {

// config/default.yaml as compiled in, read once: the starting point of every loaded config.
const ConfigResult& built_in_defaults() {
  static const ConfigResult defaults = [] {
    ConfigResult result;
    const yaml::Document doc = yaml::load_document(generated::kDefaultConfigYaml);
    NodeConfig config = ConfigReader::blank();
    if (doc.problem) {
      result.errors.push_back("the built-in default.yaml: " + doc.problem->message);
    } else {
      try {
        read_config(doc.root, config, result.errors);
      } catch (const std::exception& e) {
        result.errors.push_back(std::string("the built-in default.yaml: ") + e.what());
      }
    }
    for (std::string& e : result.errors) e = "the built-in default.yaml (a build defect): " + e;
    if (result.errors.empty()) result.config = std::move(config);
    return result;
  }();
  return defaults;
}

}  // namespace

ConfigResult default_config() {
  return built_in_defaults();
}

ConfigResult paper_config() {
  static const ConfigResult paper = [] {
    ConfigResult result = parse_config(generated::kPaperConfigYaml, "the built-in paper.yaml");
    for (std::string& e : result.errors) e += " (a build defect)";
    return result;
  }();
  return paper;
}

std::string config_as_yaml(const NodeConfig& config) {
  Settings shown;
  Errors ignored;  // an empty file raises none but the checks across keys, already passed
  NodeConfig copy = config;
  read_config(YAML::Node(), copy, ignored, &shown);
  // Sections in the order their first key was read; a top-level key is its own "section".
  std::vector<std::pair<std::string, std::vector<std::string>>> sections;
  for (const auto& [key, value] : shown) {
    const size_t dot = key.find('.');
    const std::string section = dot == std::string::npos ? "" : key.substr(0, dot);
    const std::string line =
        dot == std::string::npos ? key + ": " + value : "  " + key.substr(dot + 1) + ": " + value;
    if (section.empty() || sections.empty() || sections.back().first != section)
      sections.push_back({section, {}});
    sections.back().second.push_back(line);
  }
  std::string out;
  for (const auto& [section, lines] : sections) {
    if (!section.empty()) out += section + ":\n";
    for (const std::string& line : lines) out += line + "\n";
  }
  return out;
}

ConfigResult parse_config(const std::string& yaml_text, const std::string& source) {
  ConfigResult result;
  const ConfigResult& defaults = built_in_defaults();
  if (!defaults.config) return defaults;
  // The project's guards (vnsba/yaml/document.hpp): nesting, documents, bytes yaml-cpp misreads.
  const yaml::Document doc = yaml::load_document(yaml_text);
  if (doc.problem) {
    const yaml::Problem& p = *doc.problem;
    std::string where = source;
    if (p.line > 0) {
      where += ": " +
               std::string(p.kind == yaml::Problem::Kind::kSyntax ? "YAML syntax error at " : "") +
               "line " + std::to_string(p.line);
      if (p.column > 0) where += ", column " + std::to_string(p.column);
    } else if (p.kind == yaml::Problem::Kind::kSyntax) {
      where += ": YAML syntax error";
    }
    std::string message = p.message;
    if (p.kind == yaml::Problem::Kind::kNesting) message += " (a config nests 3 levels)";
    if (p.kind == yaml::Problem::Kind::kOther) message = "cannot read the config: " + message;
    result.errors.push_back(where + ": " + message);
    return result;
  }
  try {
    const YAML::Node& root = doc.root;
    // A key the file leaves out keeps default.yaml's value.
    NodeConfig config = *defaults.config;
    if (!root.IsMap() && !root.IsNull()) {
      result.errors.push_back(source + ": found " + describe(root) +
                              " at the top level, expected a map of settings");
    } else {
      read_config(root, config, result.errors);
    }
    if (result.errors.empty()) result.config = std::move(config);
  } catch (const std::exception& e) {
    result = {std::nullopt, {source + ": cannot read the config: " + e.what()}};
  } catch (...) {
    result = {std::nullopt, {source + ": cannot read the config: unknown error"}};
  }
  return result;
}

ConfigResult load_config(const std::string& path) {
  try {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
      return {std::nullopt, {path + ": cannot read the config file: it is a directory"}};
    std::ifstream in(path, std::ios::binary);
    if (!in) {
      const bool exists = std::filesystem::exists(path, ec);
      return {std::nullopt,
              {path + ": cannot read the config file: " +
               (exists ? "it cannot be opened (permissions?)" : "no such file")}};
    }
    std::ostringstream text;
    text << in.rdbuf();
    if (in.bad()) return {std::nullopt, {path + ": cannot read the config file: read error"}};
    return parse_config(text.str(), path);
  } catch (const std::exception& e) {
    return {std::nullopt, {path + ": cannot read the config file: " + e.what()}};
  }
}

namespace {
// A configured name resolved against the namespace, without any leading '/' ("robot7/plan").
std::string resolved_name(const NodeConfig& config, const std::string& name) {
  const bool absolute = !name.empty() && name.front() == '/';
  std::string resolved(without_leading_slash(name));
  if (!absolute && !config.ros_namespace.empty()) resolved = config.ros_namespace + "/" + resolved;
  return resolved;
}
}  // namespace

std::string dds_topic_name(const NodeConfig& config, const std::string& name) {
  const std::string resolved = resolved_name(config, name);
  return config.ros2_naming ? "rt/" + resolved : resolved;
}

std::string ros_topic_name(const NodeConfig& config, const std::string& name) {
  return "/" + resolved_name(config, name);
}

std::string overlong_topic_name(const NodeConfig& c) {
  // The longest robot name counts (the fleet's); the map, the octomap and tf/clock are read once,
  // under the node's namespace alone.
  std::string longest_robot;
  for (const std::string& robot : c.robots)
    if (robot.size() > longest_robot.size()) longest_robot = robot;
  const NodeConfig view = robot_view(c, longest_robot);

  auto check = [&](const char* key, const std::string& name, bool robot_topic) -> std::string {
    const std::string full = ros_topic_name(robot_topic ? view : c, name);
    if (full.size() <= kMaxTopicNameLength) return "";
    std::ostringstream msg;
    msg << (c.ros_namespace.empty() ? "" : "namespace, ")
        << (robot_topic && !longest_robot.empty() ? "robots, " : "") << "topics." << key
        << ": found the topic \"" << full.substr(0, 60) << "...\" of " << full.size()
        << " characters, expected at most " << kMaxTopicNameLength
        << " (ROS 2's limit for a full topic name; Fast DDS would cut it and match nothing)";
    return msg.str();
  };
  // An action's longest DDS topic: its cancel service's request topic, "rq" + the service's
  // ROS name + "Request" (rmw's naming of service topics), which a ROS name of 247 characters
  // takes to 256.
  auto check_action = [&](const char* key, const std::string& name) -> std::string {
    const std::string dds = "rq" + ros_topic_name(view, name + kActionSuffix) + "Request";
    if (dds.size() <= kMaxDdsTopicNameLength) return "";
    std::ostringstream msg;
    msg << (c.ros_namespace.empty() ? "" : "namespace, ")
        << (!longest_robot.empty() ? "robots, " : "") << "topics." << key
        << ": found the action's DDS topic \"" << dds.substr(0, 60) << "...\" of " << dds.size()
        << " characters, expected at most " << kMaxDdsTopicNameLength
        << " (Fast DDS's limit for a topic name; a longer one is cut and matches nothing)";
    return msg.str();
  };
  // One message says it: a long namespace makes every name long. Topics in table order, so the
  // map (read once, under the namespace alone) is named first.
  TopicNames names = c.topics;
  for (const auto& [key, name] : topic_keys(names)) {
    const bool robot_topic = kSharedTopicKeys.count(key) == 0;
    const bool action = kActionKeys.count(key) > 0;
    const std::string derived = action ? *name + kActionSuffix : *name;
    if (std::string problem = check(key, derived, robot_topic); !problem.empty()) return problem;
    if (action)
      if (std::string problem = check_action(key, *name); !problem.empty()) return problem;
  }
  return "";
}

core::GridBuildOptions planning_grid_options(const NodeConfig& config) {
  core::GridBuildOptions options = config.map;
  if (config.map_cost_source == MapCostSource::kCostmap) {
    options.occupied_threshold = kCostmapInscribed;
    options.robot_radius = 0.0;
    options.inflation_radius = 0.0;
  }
  return options;
}

NodeConfig robot_view(const NodeConfig& config, const std::string& robot) {
  NodeConfig view = config;
  if (!robot.empty())
    view.ros_namespace = config.ros_namespace.empty() ? robot : config.ros_namespace + "/" + robot;
  return view;
}

int planning_workers(const NodeConfig& config) {
  int workers = config.workers;
  if (workers <= 0) workers = static_cast<int>(std::max(1U, std::thread::hardware_concurrency()));
  const size_t robots = std::max<size_t>(1, config.robots.size());
  return static_cast<int>(std::min<size_t>(static_cast<size_t>(workers), robots));
}

core::Expected<std::string> normalized_namespace(std::string_view given) {
  std::string_view bare = without_leading_slash(given);
  if (!bare.empty() && bare.back() == '/') bare.remove_suffix(1);
  if (bare.empty()) return std::string();
  std::string problem;
  if (bare.find('~') != std::string_view::npos)
    problem = "a namespace without '~'";
  else if (std::string p = topic_name_problem(std::string(bare)); !p.empty())
    problem = "a namespace: " + p;
  if (!problem.empty()) return core::Status::error(core::StatusCode::kInvalidRequest, problem);
  return std::string(bare);
}

std::string discovery_server_problem(const std::string& locator) {
  const size_t colon = locator.rfind(':');
  if (colon == std::string::npos) return "has no ':port'";
  in_addr address{};
  if (inet_pton(AF_INET, locator.substr(0, colon).c_str(), &address) != 1)
    return "is not an IPv4 address and port";
  const std::string port = locator.substr(colon + 1);
  int p = 0;
  const auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), p);
  if (port.empty() || ec != std::errc{} || end != port.data() + port.size() || p < 1 || p > 65535)
    return "has a port outside 1..65535";
  return "";
}

std::string_view without_leading_slash(std::string_view name) {
  if (!name.empty() && name.front() == '/') name.remove_prefix(1);
  return name;
}

bool ros_localhost_only_from_environment() {
  const char* value = std::getenv("ROS_LOCALHOST_ONLY");
  return value != nullptr && std::string_view(value) == "1";
}

core::Expected<std::optional<int>> ros_domain_id_from_environment() {
  const char* value = std::getenv("ROS_DOMAIN_ID");
  if (value == nullptr || *value == '\0') return std::optional<int>();
  const std::string_view text(value);
  int domain = -1;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), domain);
  if (error != std::errc{} || end != text.data() + text.size() || domain < 0 || domain > 232) {
    return core::Status::error(
        core::StatusCode::kInvalidRequest,
        "ROS_DOMAIN_ID: found \"" + std::string(text.substr(0, 32)) +
            "\" in the environment, expected an integer 0..232 (unset it, or give --domain)");
  }
  return std::optional<int>(domain);
}

core::Expected<std::string> find_default_config() {
  namespace fs = std::filesystem;
  std::vector<fs::path> candidates;
  std::error_code error;
  // The executable's own path (not argv[0], which may be a bare name found through PATH).
  const fs::path executable = fs::read_symlink("/proc/self/exe", error);
  if (!error) {
    candidates.push_back(executable.parent_path().parent_path() / "share" / "vnsba" /
                         "default.yaml");
  }
  candidates.push_back(fs::path(VNSBA_SOURCE_CONFIG_DIR) / "default.yaml");
  std::string looked;
  for (const fs::path& candidate : candidates) {
    if (fs::is_regular_file(candidate, error)) return candidate.lexically_normal().string();
    looked += (looked.empty() ? "" : ", ") + candidate.lexically_normal().string();
  }
  return core::Status::error(
      core::StatusCode::kInvalidRequest,
      "no --config given and no default config found (looked at " + looked + ")");
}

}  // namespace vnsba::node
