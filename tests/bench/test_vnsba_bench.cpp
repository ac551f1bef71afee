// vnsba_bench as a process (paper, sweep, movingai --csv, bad input) and its helpers.
#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>

#include "bench/common.hpp"
#include "bench/costs.hpp"
#include "bench/large.hpp"
#include "bench/movingai.hpp"
#include "bench/paper.hpp"
#include "bench/sweep.hpp"
#include "node/child_process.hpp"
#include "temp_dir.hpp"
#include "vnsba/core/planner_options.hpp"
#include "vnsba/maps/map_io.hpp"
#include "vnsba/node/config.hpp"

namespace vnsba::test {
namespace {

namespace fs = std::filesystem;
const std::string kBench = VNSBA_BENCH_BINARY;

// A fresh, empty folder of its own (temp_dir.hpp).
std::string fresh_folder(const std::string& name) {
  return FreshTempDir("bench_" + name).string();
}

std::vector<std::string> split(const std::string& line, char separator) {
  std::vector<std::string> fields;
  std::stringstream in(line);
  std::string field;
  while (std::getline(in, field, separator)) fields.push_back(field);
  if (!line.empty() && line.back() == separator) fields.emplace_back();
  return fields;
}

TEST(BenchHelpers, ImprovementRateIsThePapersFormula) {
  EXPECT_DOUBLE_EQ(bench::improvement_rate_percent(10, 4), 60.0);
  EXPECT_DOUBLE_EQ(bench::improvement_rate_percent(10, 15), -50.0);
  EXPECT_DOUBLE_EQ(bench::improvement_rate_percent(0, 0), 0.0);
  EXPECT_TRUE(std::isnan(bench::improvement_rate_percent(0, 3)));
}

TEST(BenchHelpers, Statistics) {
  EXPECT_DOUBLE_EQ(bench::median({5, 1, 3}), 3);
  EXPECT_DOUBLE_EQ(bench::median({4, 1, 3, 2}), 2.5);
  EXPECT_TRUE(std::isnan(bench::median({})));
  std::vector<double> hundred;
  for (int i = 1; i <= 100; ++i) hundred.push_back(i);
  EXPECT_DOUBLE_EQ(bench::percentile(hundred, 95), 95);
  EXPECT_DOUBLE_EQ(bench::percentile(hundred, 100), 100);
  EXPECT_DOUBLE_EQ(bench::percentile({7}, 95), 7);
  EXPECT_DOUBLE_EQ(bench::mean({1, 2, 6}), 3);
}

// The headline speed figure pairs each query's two times; the ratio of medians pairs unrelated
// queries and can point the other way.
TEST(BenchHelpers, MedianOfPerQueryRatiosIsNotTheRatioOfMedians) {
  const std::vector<double> astar = {1, 2, 100, 4, 8};
  const std::vector<double> other = {3, 1, 50, 12, 24};  // per query: 3, 0.5, 0.5, 3, 3
  std::vector<double> brute;
  for (size_t i = 0; i < astar.size(); ++i) brute.push_back(other[i] / astar[i]);
  std::sort(brute.begin(), brute.end());
  EXPECT_DOUBLE_EQ(bench::median_of_ratios(other, astar), brute[brute.size() / 2]);
  EXPECT_DOUBLE_EQ(bench::median_of_ratios(other, astar), 3.0);
  // The ratio of medians (12 / 4) says the same here by chance; with one query changed it differs.
  const std::vector<double> other2 = {3, 1, 50, 1, 24};  // per query: 3, 0.5, 0.5, 0.25, 3
  EXPECT_DOUBLE_EQ(bench::median_of_ratios(other2, astar), 0.5);
  EXPECT_DOUBLE_EQ(bench::median(other2) / bench::median(astar), 3.0 / 4.0);
  // Unpaired or unusable entries are left out.
  EXPECT_DOUBLE_EQ(bench::median_of_ratios({2, NAN, 5}, {1, 1, 0}), 2.0);
  EXPECT_TRUE(std::isnan(bench::median_of_ratios({}, {})));
}

TEST(BenchHelpers, PlannerListNamesTheUnknownPlanner) {
  auto ok = bench::parse_planner_list("astar,vns_bastar,astar");
  ASSERT_TRUE(ok);
  EXPECT_EQ(ok->size(), 2u);
  auto bad = bench::parse_planner_list("astar,dijkstra");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("'dijkstra'"), std::string::npos) << bad.error().message;
}

TEST(BenchHelpers, MapClassFromManifestOrName) {
  // Without a MANIFEST.tsv (an empty folder), from the name alone.
  const std::string none = fresh_folder("no_manifest");
  EXPECT_EQ(bench::movingai_map_class(none, "Berlin_0_256.map"), "street");
  EXPECT_EQ(bench::movingai_map_class(none, "maze512-4-0.map"), "maze");
  EXPECT_EQ(bench::movingai_map_class(none, "16room_000.map"), "room");
  EXPECT_EQ(bench::movingai_map_class(none, "random512-20-0.map"), "random");
  EXPECT_EQ(bench::movingai_map_class(none, "den312d.map"), "game");
  const std::string dir = VNSBA_DATA_DIR "/movingai";
  if (!fs::exists(dir + "/MANIFEST.tsv")) GTEST_SKIP() << dir << "/MANIFEST.tsv is absent";
  EXPECT_EQ(bench::movingai_map_class(dir, "AR0011SR.map"), "game");  // bg512
  EXPECT_EQ(bench::movingai_map_class(dir, "Boston_0_512.map"), "street");
  EXPECT_EQ(bench::movingai_map_class(dir, "8room_000.map"), "room");
}

TEST(VnsbaBench, PaperWritesEveryTableAndFigure) {
  const std::string out = fresh_folder("paper");
  const auto [code, output] = run_to_exit(kBench, {"paper", "--out", out, "--repetitions", "3"});
  ASSERT_EQ(code, 0) << output;
  for (const auto& file : bench::paper_output_files()) {
    SCOPED_TRACE(file);
    ASSERT_TRUE(fs::exists(out + "/" + file));
    EXPECT_GT(fs::file_size(out + "/" + file), 100u);
    if (fs::path(file).extension() == ".svg") {
      tinyxml2::XMLDocument doc;
      EXPECT_EQ(doc.LoadFile((out + "/" + file).c_str()), tinyxml2::XML_SUCCESS);
    }
  }
  // Figure 12: four maps x the paper's four baselines (jps is not one of them).
  const int planners = static_cast<int>(vnsba::core::all_planner_kinds().size());
  tinyxml2::XMLDocument doc;
  ASSERT_EQ(doc.LoadFile((out + "/figure12_overall_improvement.svg").c_str()),
            tinyxml2::XML_SUCCESS);
  int bars = 0;
  std::function<void(const tinyxml2::XMLElement*)> walk = [&](const tinyxml2::XMLElement* e) {
    for (; e != nullptr; e = e->NextSiblingElement()) {
      if (const char* c = e->Attribute("class"); c != nullptr && std::string(c) == "bar") ++bars;
      walk(e->FirstChildElement());
    }
  };
  walk(doc.RootElement());
  EXPECT_EQ(bars, 16);
  // The tables name every planner and all of Tables 2-6.
  std::ifstream tables(out + "/paper_tables.md");
  const std::string text((std::istreambuf_iterator<char>(tables)), {});
  for (const char* needle : {"Table 2", "Table 3", "Table 4", "Table 5", "Table 6", "VNS-BA*",
                             "improved BA*", "+prune+smooth", "search only"})
    EXPECT_NE(text.find(needle), std::string::npos) << needle;
  // CSV: a header and one row per map, planner and configuration (4 x planners x 2), all OK.
  std::ifstream csv(out + "/paper_results.csv");
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line.rfind("map,planner,config,status,", 0), 0u) << line;
  int rows = 0;
  while (std::getline(csv, line)) {
    ++rows;
    EXPECT_EQ(split(line, ',')[3], "OK") << line;
  }
  EXPECT_EQ(rows, 4 * planners * 2);
  fs::remove_all(out);
}

TEST(VnsbaBench, SweepWritesTablesAndHeatMaps) {
  const std::string out = fresh_folder("sweep");
  const auto [code, output] = run_to_exit(kBench, {"sweep", "--out", out, "--repetitions", "1"});
  ASSERT_EQ(code, 0) << output;
  for (const auto& file : bench::sweep_output_files()) {
    SCOPED_TRACE(file);
    ASSERT_TRUE(fs::exists(out + "/" + file));
    if (fs::path(file).extension() == ".svg") {
      tinyxml2::XMLDocument doc;
      ASSERT_EQ(doc.LoadFile((out + "/" + file).c_str()), tinyxml2::XML_SUCCESS);
      int cells = 0;
      std::function<void(const tinyxml2::XMLElement*)> walk = [&](const tinyxml2::XMLElement* e) {
        for (; e != nullptr; e = e->NextSiblingElement()) {
          if (const char* c = e->Attribute("class"); c != nullptr && std::string(c) == "cell")
            ++cells;
          walk(e->FirstChildElement());
        }
      };
      walk(doc.RootElement());
      EXPECT_EQ(cells, 121);
    }
  }
  // 4 maps x 121 pairs, plus the header.
  std::ifstream csv(out + "/sweep_results.csv");
  int lines = 0;
  for (std::string line; std::getline(csv, line);) ++lines;
  EXPECT_EQ(lines, 1 + 4 * 121);
  EXPECT_NE(output.find("rank of 0.5 / 0.5"), std::string::npos) << output;
  fs::remove_all(out);
}

// `large` on the real maps at their own size (factor 1, two queries each): a table row per map,
// size and planner, every plan found, and bad options refused by name (exit 2).
TEST(VnsbaBench, LargeRowsPerMapAndPlannerAndItsOptions) {
  const std::string maps = VNSBA_DATA_DIR "/movingai";
  for (const char* name : {"Boston_0_512", "16room_000", "random512-20-0"})
    if (!fs::exists(maps + "/" + name + ".map"))
      GTEST_SKIP() << name << ".map is absent: the Moving AI data beside the project is needed";
  const auto [code, output] = run_to_exit(kBench, {"large", "--maps", maps, "--sizes", "512",
                                                   "--queries", "2", "--planners", "astar,jps"});
  ASSERT_EQ(code, 0) << output;
  for (const char* row : {"| Boston_0_512 (street, scaled) | 512² | astar | 2 | 0 |",
                          "| Boston_0_512 (street, scaled) | 512² | jps | 2 | 0 |",
                          "| 16room_000 (room, scaled) | 512² | jps | 2 | 0 |",
                          "| random512-20-0 (random, tiled) | 512² | jps | 2 | 0 |"})
    EXPECT_NE(output.find(row), std::string::npos) << row << "\n" << output;
  for (const std::vector<std::string>& bad :
       {std::vector<std::string>{"large", "--maps", maps, "--sizes", "1000"},
        std::vector<std::string>{"large", "--maps", maps, "--queries", "0"},
        std::vector<std::string>{"large", "--maps", maps, "--planners", "astr"}}) {
    const auto [bad_code, message] = run_to_exit(kBench, bad);
    EXPECT_EQ(bad_code, 2) << message;
    EXPECT_NE(message.find(bad[3]), std::string::npos) << message;
  }
}

// The cells of one row of a Markdown table whose first cells are `prefix` ("| map | cells |"),
// trimmed; empty when no row starts so.
std::vector<std::string> table_row(const std::string& output, const std::string& prefix) {
  std::istringstream lines(output);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind(prefix, 0) != 0) continue;
    std::vector<std::string> cells;
    for (std::string cell : split(line.substr(1), '|')) {
      cell.erase(0, cell.find_first_not_of(' '));
      cell.erase(cell.find_last_not_of(' ') + 1);
      cells.push_back(cell);
    }
    if (!cells.empty() && cells.back().empty()) cells.pop_back();
    return cells;
  }
  return {};
}

// `large --memory` at the maps' own size: a row per map and planner from its own process, every
// plan found, and the memory figures real: the RSS with the map holds the baseline and the map's
// arrays (the GridMap column, checked against GridMap::bytes of the same map built here), the
// peak holds both, and bytes / cell is the peak over the cells.
TEST(VnsbaBench, LargeMemoryRunsEachPlannerInItsOwnProcess) {
  const std::string maps = VNSBA_DATA_DIR "/movingai";
  for (const char* name : {"Boston_0_512", "16room_000", "random512-20-0"})
    if (!fs::exists(maps + "/" + name + ".map"))
      GTEST_SKIP() << name << ".map is absent: the Moving AI data beside the project is needed";
  const auto [code, output] =
      run_to_exit(kBench, {"large", "--memory", "--maps", maps, "--sizes", "512", "--queries", "2",
                           "--planners", "astar,jps"});
  ASSERT_EQ(code, 0) << output;
  // The map's own size, from an independent build of the same source map (factor 1: the grown
  // map is the source at 5 cm cells, the same cells).
  auto source = bench::load_map_with_scenarios(maps + "/16room_000.map");
  ASSERT_TRUE(source) << source.error().message;
  core::GridBuildOptions build;
  auto room_map =
      core::GridMap::build(bench::grow_grid(source->grid, 1, bench::Growth::kScaled), build);
  ASSERT_TRUE(room_map) << room_map.error().message;
  const double room_map_mib = static_cast<double>(room_map->bytes()) / (1 << 20);
  for (const char* planner : {"astar", "jps"}) {
    for (const char* map : {"Boston_0_512 (street, scaled)", "16room_000 (room, scaled)",
                            "random512-20-0 (random, tiled)"}) {
      // map, cells, planner, queries, failed, p50, p95, expanded, baseline, GridMap, RSS with
      // map, search, peak, bytes / cell
      const auto row = table_row(output, std::string("| ") + map + " | 512² | " + planner + " |");
      ASSERT_EQ(row.size(), 14u) << map << " " << planner << "\n" << output;
      EXPECT_EQ(row[3], "2");
      EXPECT_EQ(row[4], "0");
      const double baseline = std::stod(row[8]), grid_map = std::stod(row[9]),
                   with_map = std::stod(row[10]), peak = std::stod(row[12]),
                   bytes_per_cell = std::stod(row[13]);
      EXPECT_GT(baseline, 0.0) << map << " " << planner;
      EXPECT_GT(grid_map, 0.0);
      if (std::string(map).rfind("16room", 0) == 0) {
        EXPECT_NEAR(grid_map, room_map_mib, 0.05);
      }
      // The map's arrays are resident (built: every byte written) above the baseline.
      EXPECT_GE(with_map + 0.1, baseline + grid_map) << map << " " << planner;
      EXPECT_GE(peak, with_map) << map << " " << planner;
      EXPECT_GE(peak + 0.1, baseline + grid_map) << map << " " << planner;
      EXPECT_NEAR(bytes_per_cell, peak * (1 << 20) / (512.0 * 512.0), 0.5);
      if (row[11] != "n/a") {
        EXPECT_GE(std::stod(row[11]), 0.0);
      }
    }
  }
}

// A child that fails (its map file is not a map) fails cleanly: its message names the file,
// the other maps' children still report, and the run exits 2 (bad input); the hidden child
// option refuses anything but one map, one size and one planner.
TEST(VnsbaBench, LargeMemoryReportsAFailingChild) {
  const std::string maps = VNSBA_DATA_DIR "/movingai";
  for (const char* name : {"Boston_0_512", "16room_000", "random512-20-0"})
    if (!fs::exists(maps + "/" + name + ".map"))
      GTEST_SKIP() << name << ".map is absent: the Moving AI data beside the project is needed";
  const std::string dir = fresh_folder("large_memory_bad");
  for (const char* name : {"Boston_0_512", "16room_000"})
    for (const char* suffix : {".map", ".map.scen"})
      fs::copy_file(maps + "/" + name + suffix, dir + "/" + name + suffix);
  fs::copy_file(maps + "/random512-20-0.map.scen", dir + "/random512-20-0.map.scen");
  std::ofstream(dir + "/random512-20-0.map") << "type octile\nheight 2\nwidth 2\nmap\n.x\n..\n";
  const auto [code, output] = run_to_exit(kBench, {"large", "--memory", "--maps", dir, "--sizes",
                                                   "512", "--queries", "1", "--planners", "jps"});
  EXPECT_EQ(code, 2) << output;
  EXPECT_NE(output.find("random512-20-0.map"), std::string::npos) << output;
  EXPECT_NE(output.find("random512-20-0 at 512 with jps: the child exited 2"), std::string::npos)
      << output;
  EXPECT_EQ(table_row(output, "| Boston_0_512 (street, scaled) | 512² | jps |").size(), 14u)
      << output;
  EXPECT_EQ(table_row(output, "| 16room_000 (room, scaled) | 512² | jps |").size(), 14u) << output;
  EXPECT_TRUE(table_row(output, "| random512-20-0 (random, tiled)").empty()) << output;
  const auto [child_code, message] =
      run_to_exit(kBench, {"large", "--maps", dir, "--sizes", "512", "1024", "--planners", "jps",
                           "--memory-child", "16room_000"});
  EXPECT_EQ(child_code, 2) << message;
  EXPECT_NE(message.find("one known map, one size and one planner"), std::string::npos) << message;
  fs::remove_all(dir);
}

// --write-maps: the grown map read back by the Moving AI loader is the grown grid (blocked
// exactly where the grid is), and its scenarios are the bench's queries in file rows, with our
// A*'s cost as their optimum (an independent exact planner).
TEST(VnsbaBench, LargeWriteMapsWritesTheGrownMapsAndQueries) {
  const std::string maps = VNSBA_DATA_DIR "/movingai";
  for (const char* name : {"Boston_0_512", "16room_000", "random512-20-0"})
    if (!fs::exists(maps + "/" + name + ".map"))
      GTEST_SKIP() << name << ".map is absent: the Moving AI data beside the project is needed";
  const std::string dir = fresh_folder("large_write_maps");
  const auto [code, output] = run_to_exit(
      kBench, {"large", "--maps", maps, "--sizes", "1024", "--queries", "2", "--write-maps", dir});
  ASSERT_EQ(code, 0) << output;
  auto source = maps::load_movingai_map(maps + "/16room_000.map");
  ASSERT_TRUE(source) << source.error().message;
  const core::OccupancyGrid grown = bench::grow_grid(*source, 2, bench::Growth::kScaled);
  auto written = maps::load_movingai_map(dir + "/16room_000-1024.map");
  ASSERT_TRUE(written) << written.error().message;
  ASSERT_EQ(written->width, 1024);
  ASSERT_EQ(written->height, 1024);
  size_t differing = 0;
  for (size_t i = 0; i < grown.data.size(); ++i)
    differing += (grown.data[i] >= 65) != (written->data[i] >= 65);
  EXPECT_EQ(differing, 0u);
  auto scenarios = maps::load_movingai_scenarios(dir + "/16room_000-1024.map.scen");
  ASSERT_TRUE(scenarios) << scenarios.error().message;
  ASSERT_EQ(scenarios->size(), 2u);
  auto grid_map = core::GridMap::build(*written);
  ASSERT_TRUE(grid_map) << grid_map.error().message;
  core::Planner planner(std::make_shared<const core::GridMap>(std::move(grid_map).value()));
  for (const maps::MovingAiScenario& s : *scenarios) {
    // Scaled: every endpoint at the centre of its 2 x 2 block (x and y odd).
    EXPECT_EQ(s.start.x % 2, 1);
    EXPECT_EQ(s.goal.y % 2, 1);
    const core::PlanResult r =
        planner.plan({s.start, s.goal}, core::make_options(core::PlannerKind::kAStar, {}));
    ASSERT_TRUE(r.status.is_ok()) << r.status.message;
    EXPECT_NEAR(r.metrics.raw_cost_cells, s.optimal_length, 1e-6 * s.optimal_length);
  }
  for (const char* name : {"Boston_0_512-1024.map", "random512-20-0-1024.map"}) {
    EXPECT_TRUE(fs::exists(dir + "/" + name)) << name;
    EXPECT_TRUE(fs::exists(dir + "/" + name + std::string(".scen"))) << name;
  }
  fs::remove_all(dir);
}

// The demo scene (embedded), its slice with two random queries and a Moving AI folder, the three
// sides (binary / cost-aware / cost-aware + relax) for every planner asked for. The clearance the
// cost-aware sides report is at least the robot's radius (inflation keeps every path that far from
// obstacle centres, so from their squares at least radius - half a diagonal), and the relax
// smoother never lowers it.
TEST(VnsbaBench, CostsComparesThreeSidesOnTheSceneTheSlicesAndTheMaps) {
  const std::string dir = fresh_folder("costs");
  // 12 x 6 cells: a wall with a gap, so that costs have something to weigh.
  std::ofstream(dir + "/wall.map") << "type octile\nheight 6\nwidth 12\nmap\n"
                                      "............\n"
                                      "............\n"
                                      ".....@......\n"
                                      ".....@......\n"
                                      "............\n"
                                      "............\n";
  std::ofstream(dir + "/wall.map.scen")
      << "version 1\n0\twall.map\t12\t6\t0\t2\t11\t3\t11.41421356\n"
         "0\twall.map\t12\t6\t1\t0\t10\t5\t11.07106781\n";
  // A missing extra slice is skipped, naming it.
  const auto [code, output] = run_to_exit(
      kBench, {"costs", "--maps", dir, "--planners", "astar,vns_bastar,jps", "--repetitions", "1",
               "--slices", dir + "/absent.bt", "--slice-queries", "2"});
  ASSERT_EQ(code, 0) << output;
  // The default configuration's comparison comes first, then the table for choosing auto's
  // cost-aware planner (astar, the reference, and every cost-aware planner asked for; not jps).
  const size_t default_at = output.find("**The default configuration**");
  ASSERT_NE(default_at, std::string::npos) << output;
  EXPECT_LT(default_at, output.find("**Choosing the cost-aware planner of auto**"));
  EXPECT_LT(output.find("**Choosing the cost-aware planner of auto**"),
            output.find("**Demo scene**"));
  for (const char* row :
       {"\n| corridor | 1 |", "\n| demo routes | 3 |", "\n| geb079.bt random | 2 |",
        "\n| **all: demo routes + slices** | 5 |",
        "| demo routes + slices | astar | 5 | 1.00 | 1.00 |",
        "| demo routes + slices | vns_bastar | 5 |", "| Moving AI game | astar | 2 | 1.00 | 1.00 |",
        "| Moving AI game | vns_bastar | 2 |", "| Moving AI, all classes | vns_bastar | 2 |"})
    EXPECT_NE(output.find(row), std::string::npos) << row << "\n" << output;
  EXPECT_EQ(output.find("| demo routes + slices | jps"), std::string::npos) << output;
  for (const char* row :
       {"| astar | corridor |", "| vns_bastar | office_route |",
        "| jps (uniform costs) | hall_to_corridor |", "| geb079.bt | astar | 2 |",
        "| vns_bastar | geb079.bt random | 2 |", "| astar | **all: demo routes + slices** | 5 |",
        "| game | astar |", "| game | jps (uniform costs) |", "Cost-aware A* / binary A* time",
        "absent.bt"})
    EXPECT_NE(output.find(row), std::string::npos) << row << "\n" << output;
  // The per-route rows: planner, route, length, turns, turn angle, max curvature, clearance
  // (each binary / cost-aware / cost-aware + relax), ...
  for (const char* planner : {"astar", "vns_bastar", "jps (uniform costs)"}) {
    for (const vnsba::bench::Route& route : vnsba::bench::kDemoRoutes) {
      SCOPED_TRACE(std::string(planner) + " " + route.name);
      const size_t at = output.find(std::string("| ") + planner + " | " + route.name + " |");
      ASSERT_NE(at, std::string::npos) << output;
      const auto fields = split(output.substr(at, output.find('\n', at) - at), '|');
      ASSERT_GE(fields.size(), 14u);
      const auto clearance = split(fields[7], '/');
      ASSERT_EQ(clearance.size(), 3u) << fields[7];
      const double cost_aware = std::stod(clearance[1]), relaxed = std::stod(clearance[2]);
      EXPECT_GE(cost_aware, vnsba::bench::default_yaml_robot().robot_radius - 0.08 * M_SQRT1_2);
      EXPECT_GE(relaxed, cost_aware - 0.0015);                   // printed to 3 decimals
      EXPECT_EQ(split(fields[5], '/').size(), 3u) << fields[5];  // turn angle
      EXPECT_EQ(split(fields[6], '/').size(), 3u) << fields[6];  // max curvature
    }
  }
  for (const std::vector<std::string>& bad :
       {std::vector<std::string>{"costs", "--maps", dir, "--max-scenarios", "-1"},
        std::vector<std::string>{"costs", "--maps", dir, "--repetitions", "0"},
        std::vector<std::string>{"costs", "--maps", dir, "--planners", "astr"},
        std::vector<std::string>{"costs", "--maps", dir, "--slice-queries", "-1"},
        std::vector<std::string>{"costs", "--maps", dir, "--min-distance", "-1"},
        std::vector<std::string>{"costs", "--maps", dir, "--scene", dir + "/none.bt"}}) {
    const auto [bad_code, message] = run_to_exit(kBench, bad);
    EXPECT_EQ(bad_code, 2) << message;
    EXPECT_NE(message.find(bad[3]), std::string::npos) << message;
    EXPECT_NE(message.find(bad[4]), std::string::npos) << message;
  }
  fs::remove_all(dir);
}

// The default configuration `costs` compares is `planner.name: auto`'s: the cost-aware choice
// with the robot's costs, pruned, smoothed and relaxed, against jps on uniform costs, pruned and
// smoothed; the choice table's planners differ from the default only in the planner.
TEST(VnsbaBench, CostsDefaultConfigurationIsAutos) {
  using core::PathSmoother;
  const auto chosen =
      bench::default_config_options(bench::default_yaml_robot(), PathSmoother::kRelax);
  EXPECT_EQ(chosen.planner, core::kCostAwareChoice);
  EXPECT_TRUE(core::supports_costs(chosen.planner));
  EXPECT_TRUE(chosen.prune && chosen.smooth);
  EXPECT_EQ(chosen.smoother, PathSmoother::kRelax);
  EXPECT_EQ(chosen.cost_weight, bench::default_yaml_robot().cost_weight);
  EXPECT_EQ(chosen.goal_tolerance, bench::default_yaml_robot().goal_tolerance);
  const auto binary = bench::default_config_options(bench::RobotSettings{}, PathSmoother::kNone);
  EXPECT_EQ(binary.planner, core::PlannerKind::kJps);
  EXPECT_TRUE(binary.prune && binary.smooth);
  EXPECT_EQ(binary.smoother, PathSmoother::kNone);
  EXPECT_EQ(binary.cost_weight, 0.0);
  EXPECT_EQ(binary.goal_tolerance, 0.0);
  for (const core::PlannerKind kind : core::all_planner_kinds()) {
    if (!core::supports_costs(kind)) continue;
    SCOPED_TRACE(std::string(core::to_string(kind)));
    auto other = bench::cost_aware_relax_options(kind, bench::default_yaml_robot());
    EXPECT_EQ(other.planner, kind);
    EXPECT_TRUE(other.prune && other.smooth);
    EXPECT_EQ(other.smoother, PathSmoother::kRelax);
    EXPECT_EQ(other.cost_weight, chosen.cost_weight);
    EXPECT_EQ(other.goal_tolerance, chosen.goal_tolerance);
    EXPECT_EQ(other.start_tolerance, chosen.start_tolerance);
  }
}

// `costs` measures the demo's routes: every goal of tools/demo.sh expected OK is one of its
// routes, and every route is such a goal (read from the script's goals=( ... ) lines).
TEST(VnsbaBench, CostsRoutesAreTheDemosOkGoals) {
  std::ifstream script(VNSBA_DEMO_SCRIPT);
  ASSERT_TRUE(script) << VNSBA_DEMO_SCRIPT;
  std::string line;
  bool in_goals = false;
  std::set<std::string> demo_routes, bench_routes;
  auto key = [](double sx, double sy, double gx, double gy) {
    std::ostringstream out;
    out << sx << " " << sy << " " << gx << " " << gy;
    return out.str();
  };
  while (std::getline(script, line)) {
    if (line.rfind("goals=(", 0) == 0) {
      in_goals = true;
      continue;
    }
    if (!in_goals) continue;
    if (line == ")") break;
    std::istringstream fields(line.substr(line.find('"') + 1));
    std::string id, planner, status;
    double sx, sy, gx, gy;
    ASSERT_TRUE(fields >> id >> planner >> sx >> sy >> gx >> gy >> status) << line;
    if (status.rfind("OK", 0) == 0) demo_routes.insert(key(sx, sy, gx, gy));
  }
  ASSERT_GE(demo_routes.size(), 3u);
  for (const vnsba::bench::Route& r : vnsba::bench::kDemoRoutes)
    bench_routes.insert(key(r.start_x, r.start_y, r.goal_x, r.goal_y));
  EXPECT_EQ(bench_routes, demo_routes);
}

TEST(VnsbaBench, MovingAiCsvRowsAndOptimalAStar) {
  const std::string source = VNSBA_DATA_DIR "/movingai/arena.map";
  if (!fs::exists(source) || !fs::exists(source + ".scen"))
    GTEST_SKIP() << source << "(.scen) is absent: the Moving AI data beside the project is needed";
  const std::string dir = fresh_folder("movingai");
  fs::copy_file(source, dir + "/arena.map");
  fs::copy_file(source + ".scen", dir + "/arena.map.scen");
  const auto scenarios = maps::load_movingai_scenarios(dir + "/arena.map.scen");
  ASSERT_TRUE(scenarios);
  std::map<int, maps::MovingAiScenario> by_line;
  for (const auto& s : *scenarios) by_line[s.line] = s;

  const auto [code, output] =
      run_to_exit(kBench, {"movingai", "--maps", dir, "--planners", "astar,vns_bastar", "--csv"});
  ASSERT_EQ(code, 0) << output;
  std::stringstream lines(output);
  std::string line;
  ASSERT_TRUE(std::getline(lines, line));
  EXPECT_EQ(line,
            "map,scenario,planner,status,optimal,raw_cost,length,turns,turn_angle_deg,"
            "expanded,clearance_m,expanded_forward,expanded_backward,meeting_cell,raw_path_hash,"
            "waypoints_hash,path_hash,expansions_hash,search_time_us,time_us,cpu_time_us");
  size_t astar_rows = 0, vns_rows = 0, progress_lines = 0;
  while (std::getline(lines, line)) {
    // The per-map progress line goes to stderr, which this output includes; CSV rows have commas.
    if (line.find(',') == std::string::npos) {
      EXPECT_EQ(line, "arena (game): " + std::to_string(scenarios->size()) +
                          " scenarios x 2 configurations");
      ++progress_lines;
      continue;
    }
    const auto f = split(line, ',');
    ASSERT_EQ(f.size(), 21u) << line;
    EXPECT_EQ(f[0], "arena");
    EXPECT_EQ(f[3], "OK") << line;
    const int scenario_line = std::stoi(f[1]);
    ASSERT_EQ(by_line.count(scenario_line), 1u) << line;
    const auto& s = by_line[scenario_line];
    EXPECT_NEAR(std::stod(f[4]), s.optimal_length, 1e-6);
    // Each search's closed cells add up to the expansions; a unidirectional search has no
    // backward one and no meeting cell, a bidirectional one met somewhere.
    EXPECT_EQ(std::stoll(f[11]) + std::stoll(f[12]), std::stoll(f[9])) << line;
    if (f[2] == "astar") {
      ++astar_rows;
      EXPECT_LE(std::abs(std::stod(f[5]) - s.optimal_length),
                std::max(1e-6 * s.optimal_length, s.optimal_resolution))
          << line;
      EXPECT_EQ(f[12], "0") << line;
      EXPECT_EQ(f[13], "") << line;
    } else {
      EXPECT_EQ(f[2], "vns_bastar");
      ++vns_rows;
      EXPECT_GT(std::stoll(f[12]), 0) << line;
      EXPECT_NE(f[13].find(':'), std::string::npos) << line;
    }
    for (int hash = 14; hash <= 17; ++hash) EXPECT_EQ(f[hash].size(), 16u) << line;
    // arena has walls: every path keeps a positive, finite distance from them (metres = cells
    // on Moving AI maps); the wall and CPU times stay the last columns.
    const double clearance = std::stod(f[10]);
    EXPECT_TRUE(std::isfinite(clearance)) << line;
    EXPECT_GT(clearance, 0.0) << line;
    // The search is part of the plan: its time is positive and at most the plan's.
    EXPECT_GT(std::stod(f[18]), 0.0) << line;
    EXPECT_LE(std::stod(f[18]), std::stod(f[19])) << line;
    EXPECT_GE(std::stod(f[20]), 0.0);
  }
  EXPECT_EQ(astar_rows, scenarios->size());
  EXPECT_EQ(vns_rows, scenarios->size());
  EXPECT_EQ(progress_lines, 1u);

  // Baselines with pruning and smoothing: the same grid path, a final path no longer than it.
  const auto [post_code, post_output] =
      run_to_exit(kBench, {"movingai", "--maps", dir, "--planners", "astar", "--csv",
                           "--max-scenarios", "20", "--with-post-processing"});
  ASSERT_EQ(post_code, 0) << post_output;
  std::map<std::string, double> plain_cost;
  size_t post_rows = 0;
  std::stringstream post_lines(post_output);
  std::getline(post_lines, line);  // header
  while (std::getline(post_lines, line)) {
    if (line.find(',') == std::string::npos) continue;  // progress (stderr)
    const auto f = split(line, ',');
    ASSERT_EQ(f.size(), 21u) << line;
    if (f[2] == "astar") {
      plain_cost[f[1]] = std::stod(f[5]);
      continue;
    }
    ASSERT_EQ(f[2], "astar+prune+smooth") << line;
    ++post_rows;
    ASSERT_EQ(plain_cost.count(f[1]), 1u) << line;
    EXPECT_NEAR(std::stod(f[5]), plain_cost[f[1]], 1e-6) << line;
    EXPECT_LE(std::stod(f[6]), std::stod(f[5]) + 1e-6) << line;
  }
  EXPECT_EQ(post_rows, 20u);

  // --max-scenarios and the summary.
  const auto [summary_code, summary] =
      run_to_exit(kBench, {"movingai", "--maps", dir, "--max-scenarios", "10"});
  ASSERT_EQ(summary_code, 0) << summary;
  EXPECT_NE(summary.find("**game** (arena)"), std::string::npos) << summary;
  EXPECT_NE(summary.find("VNS-BA* (`vns_bastar`) | 10 | 100.0 %"), std::string::npos) << summary;
  // "clearance (cells)" follows "turn angle (deg)", and every planner's mean is a number > 0.
  EXPECT_NE(summary.find("| turn angle (deg) | clearance (cells) | expanded |"), std::string::npos)
      << summary;
  size_t rows = 0;
  for (std::stringstream table(summary); std::getline(table, line);) {
    if (line.find("| 10 | 100.0 %") == std::string::npos) continue;
    ++rows;
    const auto cells = split(line, '|');  // "", planner, plans, success, ratio, raw, turns, ...
    ASSERT_GE(cells.size(), 9u) << line;
    EXPECT_GT(std::stod(cells[8]), 0.0) << line;  // clearance (cells)
  }
  EXPECT_EQ(rows, core::all_planner_kinds().size()) << summary;
  fs::remove_all(dir);
}

TEST(VnsbaBench, BadInputExitsTwoNamingIt) {
  // A folder that cannot exist: in an empty directory of its own.
  const std::string missing = fresh_folder("missing") + "/no_such_folder";
  {
    const auto [code, output] = run_to_exit(kBench, {"movingai", "--maps", missing});
    EXPECT_EQ(code, 2);
    EXPECT_NE(output.find("--maps: no such folder: " + missing), std::string::npos) << output;
  }
  {
    const auto [code, output] = run_to_exit(kBench, {"optimality", "--maps", missing});
    EXPECT_EQ(code, 2);
    EXPECT_NE(output.find("--maps: no such folder: " + missing), std::string::npos) << output;
  }
  {
    // A file where the output folder should go.
    const std::string dir = fresh_folder("outfile");
    std::ofstream(dir + "/taken") << "x";
    const auto [code, output] =
        run_to_exit(kBench, {"paper", "--maps", VNSBA_PAPER_MAPS_DIR, "--out", dir + "/taken"});
    EXPECT_EQ(code, 2);
    EXPECT_NE(output.find("--out: cannot create folder " + dir + "/taken"), std::string::npos)
        << output;
    fs::remove_all(dir);
  }
  {
    const auto [code, output] =
        run_to_exit(kBench, {"movingai", "--maps", VNSBA_PAPER_MAPS_DIR, "--planners", "dijkstra"});
    EXPECT_EQ(code, 2);
    EXPECT_NE(output.find("dijkstra"), std::string::npos) << output;
  }
  {
    const std::string dir = fresh_folder("badmap");
    std::ofstream(dir + "/A.map") << "type octile\nheight 2\nwidth 2\nmap\n.?\n..\n";
    std::ofstream(dir + "/A.map.scen") << "version 1\n0\tA.map\t2\t2\t0\t0\t1\t1\t1.41421356\n";
    const auto [code, output] =
        run_to_exit(kBench, {"paper", "--maps", dir, "--out", dir + "/out"});
    EXPECT_EQ(code, 2);
    EXPECT_NE(output.find("A.map"), std::string::npos) << output;
    fs::remove_all(dir);
  }
  {
    const auto [code, output] = run_to_exit(kBench, {"paper", "--repetitions", "0"});
    EXPECT_EQ(code, 2);
    EXPECT_NE(output.find("--repetitions"), std::string::npos) << output;
  }
  {
    const auto [code, output] = run_to_exit(kBench, {"sweep", "--maps", missing});
    EXPECT_EQ(code, 2);
    EXPECT_NE(output.find("--maps: no such folder: " + missing), std::string::npos) << output;
  }
  {
    const auto [code, output] = run_to_exit(kBench, {"movingai", "--no-such-option"});
    EXPECT_EQ(code, 2) << output;
  }
}

// vnsba_bench costs compares against config/default.yaml's robot and slices the demo scene at
// its band: what it reads must be the file's as the node loads it from the source tree.
TEST(CostsBench, UsesDefaultYamlsRobotAndSliceBand) {
  const node::ConfigResult result =
      node::load_config(std::string(VNSBA_CONFIG_DIR) + "/default.yaml");
  ASSERT_TRUE(result.config.has_value());
  const node::NodeConfig& c = *result.config;
  const bench::RobotSettings& robot = bench::default_yaml_robot();
  EXPECT_EQ(robot.robot_radius, c.map.robot_radius);
  EXPECT_EQ(robot.inflation_radius, c.map.inflation_radius);
  EXPECT_EQ(robot.cost_scaling_factor, c.map.cost_scaling_factor);
  const core::PlannerOptions o = c.planner.options();
  EXPECT_EQ(robot.cost_weight, o.cost_weight);
  EXPECT_EQ(robot.goal_tolerance, o.goal_tolerance);
  EXPECT_EQ(robot.start_tolerance, o.start_tolerance);
  EXPECT_GT(robot.robot_radius, 0.0);  // a robot, not the paper's point
  EXPECT_EQ(bench::default_slice_band().z_min, c.slicer.z_min);
  EXPECT_EQ(bench::default_slice_band().z_max, c.slicer.z_max);
  EXPECT_EQ(c.slicer.resolution, 0.0);  // the bench slices at the tree's leaf size too
}

}  // namespace
}  // namespace vnsba::test
