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

std::string Fixture(const std::string& relative) {
  return std::string(VNSBA_FIXTURE_DIR) + "/" + relative;
}

// A fresh, empty folder under the gtest temp dir.
fs::path FreshTempDir(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("vnsba_map_io_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string ReadBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void WriteBytes(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << bytes;
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
  const std::string path = ::testing::TempDir() + "/two_decimals.scen";
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
  // p = 0.75 -> 99, p = 0.5 -> round(49.5) = 50, p = 0.25 -> 0.
  EXPECT_EQ(Row(*grid, 1), (std::vector<int>{100, 99, 50, 0, 0}));
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
