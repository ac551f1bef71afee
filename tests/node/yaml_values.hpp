// Reading a config back as YAML in tests: its leaf keys, and whether two values mean the same
// setting. Shared by the config tests and the configuration page's test.
#pragma once

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <map>
#include <string>

namespace vnsba::test {

// Every leaf key of a YAML document, dotted ("map.robot_radius"), with its node. A map written in
// flow style below a section ("planner.aliases: {GridBased: default}", as --print-config writes a
// map-valued key) is a value; a section is a map however it is written ("map: {max_cells: 9}").
inline void CollectLeaves(const YAML::Node& node, const std::string& path,
                          std::map<std::string, YAML::Node>& out) {
  const bool map_value =
      node.Style() == YAML::EmitterStyle::Flow && path.find('.') != std::string::npos;
  if (node.IsMap() && !map_value) {
    for (const auto& kv : node) {
      const std::string key = kv.first.Scalar();
      CollectLeaves(kv.second, path.empty() ? key : path + "." + key, out);
    }
  } else {
    out[path] = node;
  }
}

// Two YAML values mean the same setting: numbers compared as numbers ("0.5" and "5e-1"), lists
// item by item, maps key by key, anything else as text.
inline ::testing::AssertionResult SameYamlValue(const YAML::Node& expected,
                                                const YAML::Node& actual) {
  if (expected.IsSequence() || actual.IsSequence()) {
    if (!expected.IsSequence() || !actual.IsSequence() || expected.size() != actual.size())
      return ::testing::AssertionFailure() << "a list on one side only, or of another length";
    for (size_t i = 0; i < actual.size(); ++i)
      if (auto same = SameYamlValue(expected[i], actual[i]); !same) return same;
    return ::testing::AssertionSuccess();
  }
  if (expected.IsMap() || actual.IsMap()) {
    if (!expected.IsMap() || !actual.IsMap() || expected.size() != actual.size())
      return ::testing::AssertionFailure() << "a map on one side only, or of another size";
    for (const auto& kv : expected) {
      const YAML::Node other = actual[kv.first.Scalar()];
      if (!other) return ::testing::AssertionFailure() << "no key " << kv.first.Scalar();
      if (auto same = SameYamlValue(kv.second, other); !same) return same;
    }
    return ::testing::AssertionSuccess();
  }
  double x = 0.0, y = 0.0;
  if (YAML::convert<double>::decode(expected, x) && YAML::convert<double>::decode(actual, y))
    return x == y ? ::testing::AssertionSuccess()
                  : ::testing::AssertionFailure() << "expected " << x << ", got " << y;
  const std::string a = expected.IsNull() ? "" : expected.Scalar();
  const std::string b = actual.IsNull() ? "" : actual.Scalar();
  return a == b ? ::testing::AssertionSuccess()
                : ::testing::AssertionFailure() << "expected \"" << a << "\", got \"" << b << '"';
}

}  // namespace vnsba::test
