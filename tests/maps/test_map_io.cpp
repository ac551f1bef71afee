// Map file readers and writer: Moving AI .map/.scen and ROS map_server .yaml + .pgm.
//
// Fixtures live in tests/fixtures (VNSBA_FIXTURE_DIR); the Moving AI benchmark set, when present,
// in VNSBA_DATA_DIR/movingai.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "temp_files.hpp"
#include "vnsba/maps/map_io.hpp"

namespace {

namespace fs = std::filesystem;
using vnsba::core::Cell;
using vnsba::core::Expected;
using vnsba::core::OccupancyGrid;
using vnsba::core::StatusCode;
using vnsba::maps::load_map_server;
using vnsba::maps::load_movingai_map;
using vnsba::maps::load_movingai_scenarios;
using vnsba::maps::MovingAiScenario;
using vnsba::maps::save_map_server;
using vnsba::test::FreshTempDir;
using vnsba::test::ReadBytes;
using vnsba::test::WriteBytes;

std::string Fixture(const std::string& relative) {
  return std::string(VNSBA_FIXTURE_DIR) + "/" + relative;
}

std::vector<int> Bytes(const std::string& bytes) {
  return std::vector<int>(reinterpret_cast<const unsigned char*>(bytes.data()),
                          reinterpret_cast<const unsigned char*>(bytes.data()) + bytes.size());
}

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The load failed with kInvalidMap and the message names "<file>:<line>:" (or just the file
// when line is 0) and `problem`.
template <class T>
::testing::AssertionResult FailsNaming(const Expected<T>& result, const std::string& file, int line,
                                       const std::string& problem = "") {
  if (result.has_value()) return ::testing::AssertionFailure() << "loaded without an error";
  const std::string& message = result.error().message;
  if (result.error().code != StatusCode::kInvalidMap) {
    return ::testing::AssertionFailure()
           << "code " << vnsba::core::to_string(result.error().code) << ": " << message;
  }
  const std::string where = line > 0 ? file + ":" + std::to_string(line) + ":" : file;
  if (!Contains(message, where) || !Contains(message, problem)) {
    return ::testing::AssertionFailure()
           << "message \"" << message << "\" lacks \"" << where << "\" or \"" << problem << "\"";
  }
  return ::testing::AssertionSuccess();
}

// Row y of the grid (row 0 at the bottom) as occupancy values.
std::vector<int> Row(const OccupancyGrid& grid, int32_t y) {
  std::vector<int> row;
  for (int32_t x = 0; x < grid.width; ++x) row.push_back(grid.at(x, y));
  return row;
}

// --- Moving AI maps ---

// tiny.map, top line first:   @.....   ->  row 3
//                             .T..W.   ->  row 2
//                             ..O...   ->  row 1
//                             S....G   ->  row 0
void ExpectTinyMap(const OccupancyGrid& grid) {
  ASSERT_EQ(grid.width, 6);
  ASSERT_EQ(grid.height, 4);
  ASSERT_EQ(grid.data.size(), 24u);
  EXPECT_EQ(grid.resolution, 1.0);
  EXPECT_EQ(grid.origin_x, 0.0);
  EXPECT_EQ(grid.origin_y, 0.0);
  EXPECT_EQ(Row(grid, 3), (std::vector<int>{100, 0, 0, 0, 0, 0}));    // '@' top left
  EXPECT_EQ(Row(grid, 2), (std::vector<int>{0, 100, 0, 0, 100, 0}));  // 'T' and 'W'
  EXPECT_EQ(Row(grid, 1), (std::vector<int>{0, 0, 100, 0, 0, 0}));    // 'O'
  EXPECT_EQ(Row(grid, 0), (std::vector<int>{0, 0, 0, 0, 0, 0}));      // 'S' and 'G' are free
}

TEST(MovingAiMap, TinyMapTopLineBecomesTopRow) {
  const auto grid = load_movingai_map(Fixture("maps/tiny.map"));
  ASSERT_TRUE(grid.has_value()) << grid.error().message;
  ExpectTinyMap(*grid);
  EXPECT_EQ(grid->at(0, 3), 100);  // '@' is in the file's first row, first column
  EXPECT_EQ(grid->at(0, 0), 0);    // 'S' in the last row is free
}

TEST(MovingAiMap, CrlfWithoutFinalNewlineLoadsTheSameGrid) {
  const auto crlf = load_movingai_map(Fixture("maps/tiny_crlf.map"));
  ASSERT_TRUE(crlf.has_value()) << crlf.error().message;
  ExpectTinyMap(*crlf);
}

TEST(MovingAiMap, TrailingBlankLinesAreTolerated) {
  const fs::path path = FreshTempDir("blank_tail") / "tail.map";
  WriteBytes(path, ReadBytes(Fixture("maps/tiny.map")) + "\n\r\n\n");
  const auto grid = load_movingai_map(path.string());
  ASSERT_TRUE(grid.has_value()) << grid.error().message;
  ExpectTinyMap(*grid);
}

TEST(MovingAiMap, MalformedFilesNameFileLineAndProblem) {
  struct Case {
    const char* file;
    int line;
    const char* problem;
  };
  const Case cases[] = {
      {"bad_empty.map", 1, "type octile"},
      {"bad_type.map", 1, "type octile"},
      {"bad_height_word.map", 2, "height 'four' is not an integer"},
      {"bad_swapped_header.map", 2, "expected 'height <cells>'"},
      {"bad_width_zero.map", 3, "width 0 is outside 1..100000"},
      {"bad_width_negative.map", 3, "width -6 is outside"},
      {"bad_height_huge.map", 2, "height 100001 is outside"},
      {"bad_map_keyword.map", 4, "expected 'map'"},
      {"bad_short_row.map", 7, "row has 5 cells, expected 6 (width)"},
      {"bad_char.map", 6, "unexpected character 'X' at x = 4"},
      {"bad_too_few_rows.map", 7, "file ends after 3 rows, expected 4 (height)"},
      {"bad_too_many_rows.map", 9, "extra row"},
      {"bad_crlf_short_row.map", 8, "row has 5 cells"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.file);
    EXPECT_TRUE(FailsNaming(load_movingai_map(Fixture(std::string("maps/bad/") + c.file)), c.file,
                            c.line, c.problem));
  }
}

TEST(MovingAiMap, MissingFileOrFolderIsAnError) {
  EXPECT_TRUE(
      FailsNaming(load_movingai_map(Fixture("maps/no_such.map")), "no_such.map", 0, "cannot open"));
  EXPECT_TRUE(FailsNaming(load_movingai_map(Fixture("maps")), "maps", 0, "cannot open"));
}

// Every prefix of a valid file either loads (only when just the final newline is missing) or
// fails cleanly: no crash, no exception, no sanitizer report.
TEST(MovingAiMap, EveryTruncationFailsCleanly) {
  const std::string full = ReadBytes(Fixture("maps/tiny.map"));
  const fs::path path = FreshTempDir("truncated_map") / "cut.map";
  for (size_t size = 0; size < full.size(); ++size) {
    SCOPED_TRACE(size);
    WriteBytes(path, full.substr(0, size));
    const auto grid = load_movingai_map(path.string());
    if (size == full.size() - 1) {
      EXPECT_TRUE(grid.has_value());
    } else {
      EXPECT_TRUE(FailsNaming(grid, "cut.map", 0));
    }
  }
}

// --- Moving AI scenarios ---

void ExpectTinyScenarios(const std::vector<MovingAiScenario>& scenarios) {
  ASSERT_EQ(scenarios.size(), 4u);
  const MovingAiScenario& first = scenarios[0];
  EXPECT_EQ(first.bucket, 0);
  EXPECT_EQ(first.map_name, "tiny.map");
  EXPECT_EQ(first.map_width, 6);
  EXPECT_EQ(first.map_height, 4);
  EXPECT_EQ(first.start, (Cell{0, 0}));  // file (0, 3): the 'S' on the last line
  EXPECT_EQ(first.goal, (Cell{5, 0}));   // file (5, 3): the 'G'
  EXPECT_DOUBLE_EQ(first.optimal_length, 5.0);
  EXPECT_EQ(first.line, 2);
  EXPECT_EQ(scenarios[1].start, (Cell{0, 1}));  // file y 2
  EXPECT_EQ(scenarios[1].goal, (Cell{5, 3}));   // file y 0: the top line
  EXPECT_DOUBLE_EQ(scenarios[1].optimal_length, 7.82842712);
  EXPECT_EQ(scenarios[2].bucket, 1);
  EXPECT_EQ(scenarios[2].line, 5);  // line 4 is empty and skipped
  EXPECT_EQ(scenarios[2].start, (Cell{1, 3}));
  EXPECT_EQ(scenarios[2].goal, (Cell{3, 0}));
  EXPECT_EQ(scenarios[3].start, (Cell{5, 2}));
  EXPECT_EQ(scenarios[3].goal, (Cell{0, 2}));
  EXPECT_EQ(scenarios[3].line, 6);
}

TEST(MovingAiScenarios, TabSeparatedVersion1FlipsY) {
  const auto scenarios = load_movingai_scenarios(Fixture("maps/tiny.map.scen"));
  ASSERT_TRUE(scenarios.has_value()) << scenarios.error().message;
  ExpectTinyScenarios(*scenarios);
}

TEST(MovingAiScenarios, PrintedPrecisionOfTheOptimum) {
  const auto eight = load_movingai_scenarios(Fixture("maps/tiny.map.scen"));
  ASSERT_TRUE(eight.has_value());
  EXPECT_DOUBLE_EQ((*eight)[0].optimal_resolution, 1e-8);  // "5.00000000"
  const std::string path = (FreshTempDir("two_decimals") / "two_decimals.scen").string();
  std::ofstream(path) << "version 1\n0\ttiny.map\t6\t4\t0\t3\t5\t3\t3206.91\n"
                      << "0\ttiny.map\t6\t4\t0\t3\t5\t3\t5\n";
  const auto two = load_movingai_scenarios(path);
  ASSERT_TRUE(two.has_value()) << two.error().message;
  EXPECT_DOUBLE_EQ((*two)[0].optimal_resolution, 0.01);
  EXPECT_DOUBLE_EQ((*two)[1].optimal_resolution, 1.0);
}

TEST(MovingAiScenarios, SpaceSeparatedVersion10WithCrlf) {
  const auto scenarios = load_movingai_scenarios(Fixture("maps/tiny_spaces.scen"));
  ASSERT_TRUE(scenarios.has_value()) << scenarios.error().message;
  ExpectTinyScenarios(*scenarios);
}

TEST(MovingAiScenarios, EndpointsAreFreeInTheirMap) {
  const auto grid = load_movingai_map(Fixture("maps/tiny.map"));
  const auto scenarios = load_movingai_scenarios(Fixture("maps/tiny.map.scen"));
  ASSERT_TRUE(grid.has_value() && scenarios.has_value());
  for (const MovingAiScenario& s : *scenarios) {
    EXPECT_EQ(grid->at(s.start.x, s.start.y), 0) << "line " << s.line;
    EXPECT_EQ(grid->at(s.goal.x, s.goal.y), 0) << "line " << s.line;
  }
}

TEST(MovingAiScenarios, MalformedFilesNameFileLineAndColumn) {
  struct Case {
    const char* file;
    int line;
    const char* problem;
  };
  const Case cases[] = {
      {"bad_version.scen", 1, "version 1"},
      {"bad_columns.scen", 3, "expected 9 columns"},
      {"bad_start_y.scen", 2, "start y 'abc' is not an integer"},
      {"bad_goal_x.scen", 4, "goal x 6 is outside the map (map width 6)"},
      {"bad_map_height.scen", 2, "map height 0"},
      {"bad_length.scen", 2, "optimal length '-5'"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.file);
    EXPECT_TRUE(FailsNaming(load_movingai_scenarios(Fixture(std::string("maps/bad/") + c.file)),
                            c.file, c.line, c.problem));
  }
  EXPECT_TRUE(FailsNaming(load_movingai_scenarios(Fixture("maps/no_such.scen")), "no_such.scen", 0,
                          "cannot open"));
}

// The fixture folder holds no malformed file that the tables above forget.
TEST(MovingAiFixtures, EveryBadFixtureFails) {
  int checked = 0;
  for (const auto& entry : fs::directory_iterator(Fixture("maps/bad"))) {
    const std::string path = entry.path().string();
    const std::string name = entry.path().filename().string();
    SCOPED_TRACE(name);
    if (entry.path().extension() == ".map") {
      EXPECT_TRUE(FailsNaming(load_movingai_map(path), name, 0));
    } else {
      EXPECT_TRUE(FailsNaming(load_movingai_scenarios(path), name, 0));
    }
    ++checked;
  }
  EXPECT_EQ(checked, 19);
}

// --- The Moving AI benchmark set (skipped when absent) ---

TEST(MovingAiData, EveryScenarioEndpointIsInsideAndFree) {
  const fs::path dir = fs::path(VNSBA_DATA_DIR) / "movingai";
  if (!fs::is_directory(dir)) GTEST_SKIP() << "Moving AI data not found at " << dir;
  std::vector<fs::path> maps;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() == ".map") maps.push_back(entry.path());
  }
  std::sort(maps.begin(), maps.end());
  ASSERT_FALSE(maps.empty());
  for (const fs::path& map_path : maps) {
    SCOPED_TRACE(map_path.filename().string());
    const auto grid = load_movingai_map(map_path.string());
    ASSERT_TRUE(grid.has_value()) << grid.error().message;
    const auto scenarios = load_movingai_scenarios(map_path.string() + ".scen");
    ASSERT_TRUE(scenarios.has_value()) << scenarios.error().message;
    ASSERT_FALSE(scenarios->empty());
    int bad = 0;  // report the first few only: one broken map could print thousands of lines
    for (const MovingAiScenario& s : *scenarios) {
      const bool ok = s.map_width == grid->width && s.map_height == grid->height &&
                      s.start.x < grid->width && s.start.y < grid->height &&
                      s.goal.x < grid->width && s.goal.y < grid->height &&
                      grid->at(s.start.x, s.start.y) == 0 && grid->at(s.goal.x, s.goal.y) == 0;
      if (!ok && ++bad <= 5) ADD_FAILURE() << "scenario on line " << s.line;
    }
    EXPECT_EQ(bad, 0);
  }
}

// --- map_server ---

TEST(MapServer, P2WithCommentsAndTrinaryThresholdsAtTheirBoundaries) {
  const auto grid = load_map_server(Fixture("map_server/p2_thresholds.yaml"));
  ASSERT_TRUE(grid.has_value()) << grid.error().message;
  EXPECT_EQ(grid->width, 5);
  EXPECT_EQ(grid->height, 2);
  EXPECT_EQ(grid->resolution, 0.5);
  EXPECT_EQ(grid->origin_x, -1.25);
  EXPECT_EQ(grid->origin_y, 2.0);
  // Top image line v = 0 1 2 3 4 is p = 1 0.75 0.5 0.25 0: p = occupied_thresh (0.75) is not
  // occupied and p = free_thresh (0.25) is not free; both are unknown.
  EXPECT_EQ(Row(*grid, 1), (std::vector<int>{100, -1, -1, -1, 0}));
  EXPECT_EQ(Row(*grid, 0), (std::vector<int>{0, 0, 0, 0, 100}));
}

// Writes `<dir>/<name>` with the image given by absolute path, so one image serves many YAMLs.
std::string YamlFor(const fs::path& dir, const std::string& name, const std::string& image,
                    const std::string& extra) {
  const fs::path path = dir / name;
  WriteBytes(path, "image: " + fs::absolute(Fixture(image)).string() +
                       "\nresolution: 0.5\norigin: [0.0, 0.0, 0.0]\n" + extra);
  return path.string();
}

TEST(MapServer, ScaleModeInterpolatesBetweenThresholds) {
  const fs::path dir = FreshTempDir("scale");
  const auto grid = load_map_server(YamlFor(dir, "scale.yaml", "map_server/p2_thresholds.pgm",
                                            "occupied_thresh: 0.75\nfree_thresh: 0.25\n"
                                            "mode: scale\n"));
  ASSERT_TRUE(grid.has_value()) << grid.error().message;
  // Nav2's map_server: rint(100 * ratio), so p = 0.75 -> 100, p = 0.5 -> 50, p = 0.25 -> 0.
  EXPECT_EQ(Row(*grid, 1), (std::vector<int>{100, 100, 50, 0, 0}));
}

TEST(MapServer, NegateMakesWhiteOccupied) {
  const fs::path dir = FreshTempDir("negate");
  const auto grid = load_map_server(YamlFor(dir, "negate.yaml", "map_server/p2_thresholds.pgm",
                                            "negate: 1\noccupied_thresh: 0.75\n"
                                            "free_thresh: 0.25\n"));
  ASSERT_TRUE(grid.has_value()) << grid.error().message;
  // p = v / 4: 0 0.25 0.5 0.75 1.
  EXPECT_EQ(Row(*grid, 1), (std::vector<int>{0, -1, -1, -1, 100}));
  EXPECT_EQ(Row(*grid, 0), (std::vector<int>{100, 100, 100, 100, 0}));
}

TEST(MapServer, P5MapSaverOutputWithCrlfYaml) {
  const auto grid = load_map_server(Fixture("map_server/p5_8bit.yaml"));
  ASSERT_TRUE(grid.has_value()) << grid.error().message;
  EXPECT_EQ(grid->width, 4);
  EXPECT_EQ(grid->height, 3);
  EXPECT_EQ(grid->resolution, 0.05);
  EXPECT_EQ(grid->origin_x, -10.0);
  EXPECT_EQ(grid->origin_y, -5.5);
  // Image lines top first: 0 254 205 0 / 254 254 100 250 / 205 0 254 80; thresholds 0.65, 0.196.
  EXPECT_EQ(Row(*grid, 2), (std::vector<int>{100, 0, -1, 100}));
  EXPECT_EQ(Row(*grid, 1), (std::vector<int>{0, 0, -1, 0}));      // 100: p = 0.61 is unknown
  EXPECT_EQ(Row(*grid, 0), (std::vector<int>{-1, 100, 0, 100}));  // 80: p = 0.69 is occupied
}

TEST(MapServer, RawModeKeepsZeroTo100) {
  const fs::path dir = FreshTempDir("raw");
  const auto grid =
      load_map_server(YamlFor(dir, "raw.yaml", "map_server/p5_8bit.pgm", "mode: raw\n"));
  ASSERT_TRUE(grid.has_value()) << grid.error().message;
  EXPECT_EQ(Row(*grid, 2), (std::vector<int>{0, -1, -1, 0}));
  EXPECT_EQ(Row(*grid, 1), (std::vector<int>{-1, -1, 100, -1}));
  EXPECT_EQ(Row(*grid, 0), (std::vector<int>{-1, 0, -1, 80}));
}

TEST(MapServer, SixteenBitP5IsBigEndian) {
  const auto grid = load_map_server(Fixture("map_server/p5_16bit.yaml"));
  ASSERT_TRUE(grid.has_value()) << grid.error().message;
  ASSERT_EQ(grid->width, 3);
  ASSERT_EQ(grid->height, 2);
  // Samples 0x0000 0xFFFF 0x8000 / 0x00FF 0xFF00 0x5A5A. Read little-endian, 0x00FF and 0xFF00
  // would swap their meaning.
  EXPECT_EQ(Row(*grid, 1), (std::vector<int>{100, 0, -1}));
  EXPECT_EQ(Row(*grid, 0), (std::vector<int>{100, 0, -1}));
}

TEST(MapServer, MalformedFilesNameFileAndProblem) {
  struct Case {
    const char* yaml;
    const char* named_file;  // the YAML, or the image for image problems
    int line;
    const char* problem;
  };
  const Case cases[] = {
      {"missing_image.yaml", "missing_image.yaml", 0, "missing required key 'image'"},
      {"missing_resolution.yaml", "missing_resolution.yaml", 0, "key 'resolution'"},
      {"missing_origin.yaml", "missing_origin.yaml", 0, "key 'origin'"},
      {"yaw.yaml", "yaw.yaml", 3, "origin yaw 0.5 rad is not 0"},
      {"origin_two_values.yaml", "origin_two_values.yaml", 3, "[x, y, yaw]"},
      {"resolution_zero.yaml", "resolution_zero.yaml", 2, "resolution 0 is not positive"},
      {"resolution_text.yaml", "resolution_text.yaml", 2, "resolution 'fine'"},
      {"thresholds_crossed.yaml", "thresholds_crossed.yaml", 6, "free_thresh 0.7"},
      {"negate_maybe.yaml", "negate_maybe.yaml", 4, "negate 'maybe'"},
      {"mode_unknown.yaml", "mode_unknown.yaml", 7, "mode 'fuzzy'"},
      {"duplicate_key.yaml", "duplicate_key.yaml", 7, "duplicate key 'resolution'"},
      {"no_colon.yaml", "no_colon.yaml", 7, "expected 'key: value'"},
      {"missing_image_file.yaml", "does_not_exist.pgm", 0, "cannot open image file"},
      {"truncated.yaml", "truncated.pgm", 0, "truncated: expected 16 bytes, found 10"},
      {"truncated_p2.yaml", "truncated_p2.pgm", 0, "truncated: found 5 of 6 samples"},
      {"not_pgm.yaml", "missing_origin.yaml", 0, "not a PGM image"},
      {"maxval_zero.yaml", "maxval_zero.pgm", 0, "PGM maxval '0'"},
      {"sample_above_maxval.yaml", "sample_above_maxval.pgm", 0, "value 101 exceeds maxval 100"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.yaml);
    EXPECT_TRUE(FailsNaming(load_map_server(Fixture(std::string("map_server/bad/") + c.yaml)),
                            c.named_file, c.line, c.problem));
  }
  EXPECT_TRUE(FailsNaming(load_map_server(Fixture("map_server/no_such.yaml")), "no_such.yaml", 0,
                          "cannot open"));
}

TEST(MapServer, EveryTruncationOfAP5ImageFailsCleanly) {
  const std::string full = ReadBytes(Fixture("map_server/p5_8bit.pgm"));
  const fs::path dir = FreshTempDir("truncated_pgm");
  const std::string yaml = (dir / "cut.yaml").string();
  WriteBytes(yaml, "image: cut.pgm\nresolution: 1\norigin: [0, 0, 0]\n");
  for (size_t size = 0; size < full.size(); ++size) {
    SCOPED_TRACE(size);
    WriteBytes(dir / "cut.pgm", full.substr(0, size));
    EXPECT_TRUE(FailsNaming(load_map_server(yaml), "cut.pgm", 0));
  }
  WriteBytes(dir / "cut.pgm", full);
  EXPECT_TRUE(load_map_server(yaml).has_value());
}

// --- map_server YAML through yaml-cpp ---

// `name` with `yaml` in `dir` (the test's own FreshTempDir), beside p5_8bit.pgm (4 x 3, see
// P5MapSaverOutputWithCrlfYaml), copied there by the first call.
std::string YamlBesideImage(const fs::path& dir, const std::string& name, const std::string& yaml) {
  if (!fs::exists(dir / "p5_8bit.pgm")) {
    fs::copy_file(Fixture("map_server/p5_8bit.pgm"), dir / "p5_8bit.pgm");
  }
  WriteBytes(dir / name, yaml);
  return (dir / name).string();
}

// Everything yaml-cpp reads that the flat "key: value" subset did not: quoted values, comments
// after values, block and flow lists for origin, a flow map as the whole document, anchors and
// aliases, document markers, tags. Every spelling loads the same map.
TEST(MapServerYaml, QuotesCommentsListsAnchorsAndFlowStyleLoadTheSameMap) {
  const fs::path dir = FreshTempDir("yaml_spellings");
  const auto plain = load_map_server(YamlBesideImage(
      dir, "plain.yaml",
      "image: p5_8bit.pgm\nresolution: 0.05\norigin: [-10.0, -5.5, 0.0]\nnegate: 0\n"));
  ASSERT_TRUE(plain.has_value()) << plain.error().message;
  EXPECT_EQ(plain->origin_x, -10.0);
  EXPECT_EQ(plain->origin_y, -5.5);
  EXPECT_EQ(plain->resolution, 0.05);
  const std::pair<const char*, const char*> spellings[] = {
      {"double quotes", "image: \"p5_8bit.pgm\"\nresolution: \"0.05\"\norigin: [-10, -5.5, 0]\n"},
      {"single quotes", "image: 'p5_8bit.pgm'\nresolution: 0.05\norigin: ['-10', '-5.5', '0']\n"},
      {"comments",
       "# a map\nimage: p5_8bit.pgm # the image\nresolution: 0.05   # m\n"
       "origin: [-10.0, -5.5, 0.0]  # x, y, yaw\n# the end\n"},
      {"block list",
       "image: p5_8bit.pgm\nresolution: 0.05\norigin:\n  - -10.0\n  - -5.5\n  - 0.0\n"},
      {"block list, no indent",
       "image: p5_8bit.pgm\norigin:\n- -10.0\n- -5.5\n- 0\nresolution: 0.05\n"},
      {"flow list over lines",
       "image: p5_8bit.pgm\nresolution: 0.05\norigin: [\n  -10.0,\n  -5.5,\n  0.0\n]\n"},
      {"flow map document", "{image: p5_8bit.pgm, resolution: 0.05, origin: [-10.0, -5.5, 0.0]}\n"},
      {"anchors and aliases",
       "x: &x -10.0\nimage: p5_8bit.pgm\nresolution: 0.05\norigin: [*x, -5.5, 0.0]\n"},
      {"document markers",
       "%YAML 1.2\n---\nimage: p5_8bit.pgm\nresolution: 0.05\n"
       "origin: [-10.0, -5.5, 0.0]\n...\n"},
      {"tags",
       "image: !!str p5_8bit.pgm\nresolution: !!float 0.05\norigin: !!seq [-10.0, -5.5, 0.0]\n"},
      {"crlf and indented keys",
       " image: p5_8bit.pgm\r\n resolution: 0.05\r\n origin: [-10.0, -5.5, 0.0]\r\n"},
      {"negate spelled false",
       "image: p5_8bit.pgm\nresolution: 0.05\norigin: [-10.0, -5.5, 0.0]\nnegate: false\n"},
  };
  for (const auto& [name, yaml] : spellings) {
    SCOPED_TRACE(name);
    const auto grid = load_map_server(YamlBesideImage(dir, "spelling.yaml", yaml));
    ASSERT_TRUE(grid.has_value()) << grid.error().message;
    EXPECT_EQ(grid->resolution, plain->resolution);
    EXPECT_EQ(grid->origin_x, plain->origin_x);
    EXPECT_EQ(grid->origin_y, plain->origin_y);
    EXPECT_EQ(grid->width, plain->width);
    EXPECT_EQ(grid->data, plain->data);
  }
  // A quoted name keeps what YAML quotes for: a '#' after a space, a leading space.
  fs::copy_file(Fixture("map_server/p5_8bit.pgm"), dir / "a #1.pgm");
  const auto hashed = load_map_server(YamlBesideImage(
      dir, "hashed.yaml", "image: \"a #1.pgm\"\nresolution: 0.05\norigin: [-10.0, -5.5, 0.0]\n"));
  ASSERT_TRUE(hashed.has_value()) << hashed.error().message;
  EXPECT_EQ(hashed->data, plain->data);
}

TEST(MapServerYaml, MalformedYamlNamesFileLineAndKey) {
  const fs::path dir = FreshTempDir("yaml_malformed");
  const std::string head = "image: p5_8bit.pgm\nresolution: 0.05\n";
  const std::string origin = "origin: [0.0, 0.0, 0.0]\n";
  const auto resolution = [&](const std::string& value) {  // line 2
    return "image: p5_8bit.pgm\nresolution: " + value + "\n" + origin;
  };
  auto repeat = [](const std::string& unit, int times) {
    std::string out;
    for (int i = 0; i < times; ++i) out += unit;
    return out;
  };
  std::string billion_laughs = "a: &a [x, x, x, x, x, x, x, x, x, x]\n";
  for (char c = 'b'; c <= 'j'; ++c) {
    billion_laughs += std::string(1, c) + ": &" + c + " [" +
                      repeat(std::string("*") + static_cast<char>(c - 1) + ", ", 9) + "*" +
                      static_cast<char>(c - 1) + "]\n";
  }
  struct Case {
    const char* name;
    std::string yaml;
    int line;  // 0: the message names no line
    std::string problem;
  };
  const Case cases[] = {
      // yaml-cpp reports an unclosed flow list where the text ends.
      {"syntax error", head + "origin: [0.0, 0.0, 0.0\n", 4, "YAML syntax error"},
      {"syntax error, bad indent", head + origin + "  mode: raw\n", 4, "YAML syntax error"},
      // yaml-cpp 0.7 ends an unclosed quote at the end of the text: the keys it took in are
      // missing.
      {"unclosed quote", "image: \"p5_8bit.pgm\nresolution: 0.05\n" + origin, 0,
       "missing required key 'resolution'"},
      {"resolution is a map", resolution("{m: 0.05}"), 2,
       "resolution is a map, expected a finite number"},
      {"resolution is a list", resolution("[0.05]"), 2,
       "resolution is a list, expected a finite number"},
      {"resolution without a value", resolution(""), 2,
       "resolution has no value, expected a finite number"},
      {"resolution text", resolution("\"five cm\""), 2,
       "resolution 'five cm' is not a finite number"},
      {"resolution .nan", resolution(".nan"), 2, "resolution '.nan' is not a finite number"},
      {"resolution nan", resolution("nan"), 2, "resolution 'nan' is not a finite number"},
      {"resolution .inf", resolution(".inf"), 2, "resolution '.inf' is not a finite number"},
      {"resolution inf", resolution("inf"), 2, "resolution 'inf' is not a finite number"},
      {"resolution overflows", resolution("1e999"), 2, "resolution '1e999' is not a finite number"},
      {"free_thresh -.inf", head + origin + "free_thresh: -.inf\n", 4,
       "free_thresh '-.inf' is not a finite number"},
      {"image is a map", "image: {file: p5_8bit.pgm}\nresolution: 0.05\n" + origin, 1,
       "image is a map, expected a file name"},
      {"image is null", "image: ~\nresolution: 0.05\n" + origin, 1, "image has no value"},
      {"image is empty", "image: ''\nresolution: 0.05\n" + origin, 1, "image is empty"},
      {"mode is a list", head + origin + "mode: [trinary]\n", 4,
       "mode is a list, expected trinary, scale or raw"},
      {"negate is a map", head + origin + "negate: {a: 1}\n", 4, "negate is a map"},
      {"origin is a map", head + "origin: {x: 0, y: 0, yaw: 0}\n", 3,
       "origin (a map) is not [x, y, yaw]"},
      {"origin quoted", head + "origin: \"[0, 0, 0]\"\n", 3,
       "origin '[0, 0, 0]' is not [x, y, yaw]"},
      {"origin of four", head + "origin: [0, 0, 0, 0]\n", 3, "origin ['0', '0', '0', '0'] is not"},
      {"origin nested", head + "origin: [[0], 0, 0]\n", 3, "origin [a list, '0', '0'] is not"},
      {"origin .nan", head + "origin: [.nan, 0, 0]\n", 3, "origin ['.nan', '0', '0'] is not"},
      {"origin block list of two", head + "origin:\n  - 1\n  - 2\n", 3, "origin ['1', '2'] is not"},
      {"origin yaw in a block list", head + "origin:\n  - 1\n  - 2\n  - 0.5\n", 3,
       "origin yaw 0.5 rad is not 0"},
      {"duplicate key", head + origin + "resolution: 0.1\n", 4, "duplicate key 'resolution'"},
      {"duplicate key, flow map", "{image: a.pgm, image: b.pgm}\n", 1, "duplicate key 'image'"},
      {"map as a key", head + origin + "? {a: 1}\n: 2\n", 4, "found a map as a key"},
      {"list as a key", head + origin + "[a, b]: 2\n", 4, "found a list as a key"},
      {"line without a colon", head + origin + "just words\n", 4,
       "expected 'key: value', found 'just words'"},
      {"line without a colon, keys after it", head + "just words\n" + origin, 4,
       "YAML syntax error at column 7: illegal map value"},
      {"top level list", "- image: p5_8bit.pgm\n", 1, "found a list at the top level"},
      {"top level text", "p5_8bit.pgm\n", 1, "found a text at the top level"},
      {"two documents", head + origin + "---\nmode: raw\n", 4,
       "found 2 YAML documents, expected one"},
      {"a document starting with ','", head + origin + "---\n,\n", 5, "YAML syntax error"},
      {"nested 600 deep", head + origin + "extra: " + repeat("[", 600) + repeat("]", 600) + "\n", 4,
       "nested deeper than"},
      {"nested 100,000 deep", repeat("{a: ", 100000) + "1" + repeat("}", 100000) + "\n", 1,
       "nested deeper than"},
      {"block nesting 100,000 deep", repeat("- ", 100000) + "x\n", 1, "nested deeper than"},
      {"NUL byte", head + origin + "# a comment\n" + std::string(1, '\0') + "mode: raw\n", 5,
       "a NUL byte"},
      {"NUL byte in a value", "image: p5_8bit" + std::string(1, '\0') + "x.pgm\n", 1, "a NUL byte"},
      {"control character", head + origin + "mode: ra\x7fw\n", 4, "control character 0x7f"},
      {"lone carriage return", head + origin + "# note\rmode: raw\n", 4, "carriage return"},
      {"alias bomb without image", billion_laughs + "resolution: 0.05\n" + origin, 0,
       "missing required key 'image'"},
      {"undefined alias", head + "origin: [*x, 0, 0]\n", 3, "YAML syntax error"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = YamlBesideImage(dir, "bad.yaml", c.yaml);
    EXPECT_TRUE(FailsNaming(load_map_server(path), path, c.line, c.problem));
  }
  // An alias bomb that is otherwise a good map loads: yaml-cpp shares aliased nodes (10^9 "x"
  // would otherwise be read), and the reader walks only the keys it knows.
  const auto bomb =
      load_map_server(YamlBesideImage(dir, "bomb.yaml", billion_laughs + head + origin));
  EXPECT_TRUE(bomb.has_value()) << bomb.error().message;
}

// --- save_map_server ---

TEST(MapServerSave, RoundTripIsExact) {
  OccupancyGrid grid;
  grid.width = 37;
  grid.height = 23;
  grid.resolution = 0.1 * 3;  // 0.30000000000000004: needs all 17 digits
  grid.origin_x = -7.0 * std::sqrt(2.0);
  grid.origin_y = 1.0 / 3.0;
  std::mt19937 random(20240531);
  const int8_t values[3] = {0, 100, -1};
  for (int i = 0; i < grid.width * grid.height; ++i) grid.data.push_back(values[random() % 3]);

  const fs::path dir = FreshTempDir("round_trip");
  const auto yaml = save_map_server(grid, (dir / "office").string());
  ASSERT_TRUE(yaml.has_value()) << yaml.error().message;
  EXPECT_EQ(*yaml, (dir / "office.yaml").string());
  EXPECT_TRUE(Contains(ReadBytes(*yaml), "image: office.pgm\n"));  // relative: folder can move
  EXPECT_TRUE(Contains(ReadBytes(*yaml), "mode: trinary\n"));
  EXPECT_EQ(ReadBytes(dir / "office.pgm").size(), 13 + 37u * 23u);  // "P5\n37 23\n255\n" + pixels

  const auto loaded = load_map_server(*yaml);
  ASSERT_TRUE(loaded.has_value()) << loaded.error().message;
  EXPECT_EQ(loaded->width, grid.width);
  EXPECT_EQ(loaded->height, grid.height);
  EXPECT_EQ(loaded->resolution, grid.resolution);
  EXPECT_EQ(loaded->origin_x, grid.origin_x);
  EXPECT_EQ(loaded->origin_y, grid.origin_y);
  EXPECT_EQ(loaded->data, grid.data);
}

TEST(MapServerSave, ColoursFollowMapSaverThresholds) {
  OccupancyGrid grid;
  grid.width = 9;
  grid.height = 2;
  // Bottom row (written last in the PGM) carries the values; the top row is all occupied.
  grid.data = {0, 25, 26, 64, 65, 100, -1, -7, 127, 100, 100, 100, 100, 100, 100, 100, 100, 100};
  const fs::path dir = FreshTempDir("colours");
  ASSERT_TRUE(save_map_server(grid, (dir / "m").string()).has_value());
  const std::string pgm = ReadBytes(dir / "m.pgm");
  const std::string header = "P5\n9 2\n255\n";
  ASSERT_EQ(pgm.size(), header.size() + 18);
  EXPECT_EQ(pgm.substr(0, header.size()), header);
  const std::vector<int> grey = Bytes(pgm.substr(header.size()));
  EXPECT_EQ(std::vector<int>(grey.begin(), grey.begin() + 9), std::vector<int>(9, 0));
  EXPECT_EQ(std::vector<int>(grey.begin() + 9, grey.end()),
            (std::vector<int>{254, 254, 205, 205, 0, 0, 205, 205, 0}));

  const auto loaded = load_map_server((dir / "m.yaml").string());
  ASSERT_TRUE(loaded.has_value()) << loaded.error().message;
  EXPECT_EQ(Row(*loaded, 0), (std::vector<int>{0, 0, -1, -1, 100, 100, -1, -1, 100}));

  // A lower occupied threshold turns 26..64 black.
  ASSERT_TRUE(save_map_server(grid, (dir / "low").string(), 26).has_value());
  EXPECT_EQ(Bytes(ReadBytes(dir / "low.pgm"))[header.size() + 9 + 2], 0);
}

TEST(MapServerSave, InvalidGridsAndPathsAreRefused) {
  const fs::path dir = FreshTempDir("refused");
  const std::string stem = (dir / "m").string();
  OccupancyGrid good;
  good.width = 2;
  good.height = 2;
  good.data = {0, 0, 100, -1};

  OccupancyGrid bad = good;
  bad.width = 0;
  EXPECT_TRUE(FailsNaming(save_map_server(bad, stem), stem, 0, "width 0"));
  bad = good;
  bad.height = -3;
  EXPECT_TRUE(FailsNaming(save_map_server(bad, stem), stem, 0, "height -3"));
  bad = good;
  bad.data.pop_back();
  EXPECT_TRUE(FailsNaming(save_map_server(bad, stem), stem, 0, "data has 3 values"));
  bad = good;
  bad.resolution = std::nan("");
  EXPECT_TRUE(FailsNaming(save_map_server(bad, stem), stem, 0, "resolution"));
  bad = good;
  bad.resolution = 0.0;
  EXPECT_TRUE(FailsNaming(save_map_server(bad, stem), stem, 0, "resolution"));
  bad = good;
  bad.origin_y = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(FailsNaming(save_map_server(bad, stem), stem, 0, "origin"));
  EXPECT_FALSE(fs::exists(stem + ".pgm"));  // nothing written for a refused grid

  const auto threshold = save_map_server(good, stem, 0);
  ASSERT_FALSE(threshold.has_value());
  EXPECT_EQ(threshold.error().code, StatusCode::kInvalidRequest);
  EXPECT_TRUE(Contains(threshold.error().message, "occupied_threshold 0"));

  const std::string unwritable = (dir / "no_such_folder" / "m").string();
  EXPECT_TRUE(FailsNaming(save_map_server(good, unwritable), unwritable + ".pgm", 0,
                          "cannot open file for writing"));
}

}  // namespace
