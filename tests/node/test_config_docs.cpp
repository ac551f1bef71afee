// docs/configuration.md's "Every key" tables against the configuration itself (no DDS), so that
// the page cannot drift from the code: the oracle is vnsba_node --print-config's text
// (config_as_yaml), read back by yaml-cpp.
//
// The page's tables are those whose header is `| key | meaning | unit | range | default |`.
// Each row names one key as a code span (`map.robot_radius`); its default is a code span holding
// the value as YAML (`0.15`, `map`, `""`, `[]`), or text starting with "unset" for a key that
// config_as_yaml prints only when a file sets it.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "node/yaml_values.hpp"
#include "vnsba/node/config.hpp"

// A named namespace rather than an anonymous one: the unity build compiles this file in one
// unit with other node tests, whose anonymous namespaces define helpers of the same names.
namespace config_docs_test {

using vnsba::test::CollectLeaves;
using vnsba::test::SameYamlValue;

std::string ConfigurationPage() {
  return std::string(VNSBA_SOURCE_DIR) + "/docs/configuration.md";
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::string Trimmed(const std::string& text) {
  const size_t begin = text.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return "";
  const size_t end = text.find_last_not_of(" \t\r");
  return text.substr(begin, end - begin + 1);
}

// The cells of a Markdown table row, trimmed; a '|' inside a code span does not split.
std::vector<std::string> Cells(const std::string& row) {
  std::vector<std::string> cells;
  std::string cell;
  bool in_code = false;
  for (const char ch : Trimmed(row)) {
    if (ch == '`') in_code = !in_code;
    if (ch == '|' && !in_code) {
      cells.push_back(Trimmed(cell));
      cell.clear();
    } else {
      cell += ch;
    }
  }
  cells.push_back(Trimmed(cell));
  // A row starts and ends with '|': drop the empty cells outside them.
  if (!cells.empty() && cells.front().empty()) cells.erase(cells.begin());
  if (!cells.empty() && cells.back().empty()) cells.pop_back();
  return cells;
}

// The text of a cell that is exactly one code span, else nothing.
bool OneCodeSpan(const std::string& cell, std::string& inside) {
  if (cell.size() < 2 || cell.front() != '`' || cell.back() != '`') return false;
  inside = cell.substr(1, cell.size() - 2);
  return inside.find('`') == std::string::npos;
}

struct Row {
  int line = 0;
  std::string key, meaning, unit, range, default_cell;
};

// Every row of the page's key tables.
std::vector<Row> KeyRows(const std::string& page) {
  const std::vector<std::string> header = {"key", "meaning", "unit", "range", "default"};
  std::vector<Row> rows;
  std::istringstream in(page);
  std::string line;
  int number = 0;
  bool in_table = false;
  while (std::getline(in, line)) {
    ++number;
    const std::string text = Trimmed(line);
    if (text.empty() || text.front() != '|') {
      in_table = false;
      continue;
    }
    const std::vector<std::string> cells = Cells(text);
    if (cells == header) {
      in_table = true;
      continue;
    }
    if (!in_table || text.rfind("|---", 0) == 0) continue;
    Row row;
    row.line = number;
    if (cells.size() != header.size()) {
      ADD_FAILURE() << "configuration.md:" << number << ": " << cells.size()
                    << " cells, expected 5: " << text;
      continue;
    }
    if (!OneCodeSpan(cells[0], row.key)) {
      ADD_FAILURE() << "configuration.md:" << number << ": the key is not a code span: " << text;
      continue;
    }
    row.meaning = cells[1];
    row.unit = cells[2];
    row.range = cells[3];
    row.default_cell = cells[4];
    rows.push_back(row);
  }
  return rows;
}

// The keys and values `vnsba_node --print-config` prints for a config file's text.
std::map<std::string, YAML::Node> PrintedKeys(const std::string& config_text) {
  const vnsba::node::ConfigResult result = vnsba::node::parse_config(config_text, "test");
  std::map<std::string, YAML::Node> keys;
  EXPECT_TRUE(result.config.has_value()) << config_text;
  if (result.config)
    CollectLeaves(YAML::Load(vnsba::node::config_as_yaml(*result.config)), "", keys);
  return keys;
}

// Every key of the page is a key of the configuration and the other way round; each default is
// what the node prints for an empty config (default.yaml's), each "unset" default a key the node
// prints only when it is set; every row has a meaning, a unit and a range.
TEST(ConfigDocs, EveryKeyIsDocumentedWithItsUnitRangeAndPrintedDefault) {
  const std::string page = ReadFile(ConfigurationPage());
  ASSERT_FALSE(page.empty()) << "cannot read " << ConfigurationPage();
  const std::vector<Row> rows = KeyRows(page);
  ASSERT_GT(rows.size(), 50u) << "no key tables found in " << ConfigurationPage();

  // The oracle: what --print-config shows for an empty config, for the fixture that sets every
  // key, and for one that sets the keys a config may leave unset.
  const std::map<std::string, YAML::Node> defaults = PrintedKeys("");
  std::set<std::string> all_keys;
  for (const auto& entry : defaults) all_keys.insert(entry.first);
  for (const std::string& text :
       {ReadFile(std::string(VNSBA_FIXTURE_DIR) + "/config/custom.yaml"),
        std::string("planner: {neighborhood: \"8\", prune: true, smooth: true, path_spacing: "
                    "0.05}\n")}) {
    for (const auto& entry : PrintedKeys(text)) all_keys.insert(entry.first);
  }
  ASSERT_GT(defaults.size(), 50u);
  ASSERT_GT(all_keys.size(), defaults.size()) << "no key is left unset by default any more";

  std::set<std::string> documented;
  for (const Row& row : rows) {
    SCOPED_TRACE("configuration.md:" + std::to_string(row.line) + ": " + row.key);
    EXPECT_TRUE(documented.insert(row.key).second) << "documented twice";
    EXPECT_EQ(all_keys.count(row.key), 1u) << "not a key of the configuration";
    EXPECT_FALSE(row.meaning.empty()) << "no meaning";
    EXPECT_FALSE(row.unit.empty()) << "no unit";
    EXPECT_FALSE(row.range.empty()) << "no range";
    const auto printed = defaults.find(row.key);
    if (row.default_cell.rfind("unset", 0) == 0) {
      EXPECT_EQ(printed, defaults.end())
          << "documented as unset, but --print-config prints " << printed->second;
      continue;
    }
    std::string value;
    if (!OneCodeSpan(row.default_cell, value)) {
      ADD_FAILURE() << "the default is neither a code span nor \"unset ...\": " << row.default_cell;
      continue;
    }
    if (printed == defaults.end()) {
      ADD_FAILURE() << "--print-config does not print it for the default config";
      continue;
    }
    EXPECT_TRUE(SameYamlValue(YAML::Load(value), printed->second));
  }
  for (const std::string& key : all_keys)
    EXPECT_EQ(documented.count(key), 1u) << key << " is missing from " << ConfigurationPage();
}

// The parser above must see what a reader sees: a table row whose default differs, a missing
// key and an extra one are found (the same checks, on a page edited in memory).
TEST(ConfigDocs, TheTableParserReadsRowsCellsAndCodeSpans) {
  const std::vector<std::string> cells = Cells("| `a.b` | x `c | d` y | m | 0..1 | `[]` |");
  ASSERT_EQ(cells.size(), 5u);
  EXPECT_EQ(cells[1], "x `c | d` y");
  std::string inside;
  EXPECT_TRUE(OneCodeSpan(cells[0], inside));
  EXPECT_EQ(inside, "a.b");
  EXPECT_FALSE(OneCodeSpan("`a` or `b`", inside));

  const std::string page =
      "text\n\n| key | meaning | unit | range | default |\n|---|---|---|---|---|\n"
      "| `map.robot_radius` | the radius | metres | >= 0 | `0.15` |\n"
      "| `planner.path_spacing` | poses | metres | (0, 10] | unset: the resolution |\n"
      "\n| key | what |\n|---|---|\n| `not.a.row` | other table |\n";
  const std::vector<Row> rows = KeyRows(page);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].key, "map.robot_radius");
  EXPECT_EQ(rows[0].default_cell, "`0.15`");
  EXPECT_EQ(rows[1].key, "planner.path_spacing");
  EXPECT_EQ(rows[1].line, 6);

  const std::map<std::string, YAML::Node> defaults = PrintedKeys("");
  ASSERT_EQ(defaults.count("map.robot_radius"), 1u);
  EXPECT_TRUE(SameYamlValue(YAML::Load("0.15"), defaults.at("map.robot_radius")));
  EXPECT_FALSE(SameYamlValue(YAML::Load("0.2"), defaults.at("map.robot_radius")));
  EXPECT_FALSE(SameYamlValue(YAML::Load("[]"), defaults.at("map.robot_radius")));
  ASSERT_EQ(defaults.count("frame_id"), 1u);
  EXPECT_TRUE(SameYamlValue(YAML::Load("map"), defaults.at("frame_id")));
  EXPECT_FALSE(SameYamlValue(YAML::Load("odom"), defaults.at("frame_id")));
  ASSERT_EQ(defaults.count("robots"), 1u);
  EXPECT_TRUE(SameYamlValue(YAML::Load("[]"), defaults.at("robots")));
  EXPECT_EQ(defaults.count("planner.path_spacing"), 0u);
}

}  // namespace config_docs_test
