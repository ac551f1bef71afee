// vnsba_plan as a process: a plan and its picture from a map file, and exit codes with messages
// naming the option for bad input.
#include <gtest/gtest.h>
#include <octomap/OcTree.h>
#include <tinyxml2.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <sstream>

#include "node/child_process.hpp"
#include "svg_test_support.hpp"
#include "temp_dir.hpp"
#include "vnsba/core/path_poses.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/core/planner_registry.hpp"
#include "vnsba/maps/map_io.hpp"
#include "vnsba/maps/octomap_slice.hpp"
#include "vnsba/records/run_record.hpp"

namespace vnsba::test {
namespace {

const std::string kPlan = VNSBA_PLAN_BINARY;
const std::string kRooms = VNSBA_FIXTURE_DIR "/maps/rooms_32.map";
const std::string kSourceConfigDir = VNSBA_SOURCE_DIR "/config";

// vnsba_plan as these tests mean it: the paper's setting (--paper) unless the arguments give a
// config, so that the core oracles below (bare PlannerSettings, GridBuildOptions) plan the same
// problem. Without either the tool reads default.yaml: tested on its own below.
std::pair<int, std::string> run_plan(std::vector<std::string> args) {
  if (std::find(args.begin(), args.end(), "--config") == args.end() &&
      std::find(args.begin(), args.end(), "--paper") == args.end())
    args.push_back("--paper");
  return run_to_exit(kPlan, args);
}

std::pair<int, std::string> run_plan_as_given(const std::vector<std::string>& args) {
  return run_to_exit(kPlan, args);
}

// The clearance as vnsba_plan prints it: metres with 3 decimals, "inf" without obstacles.
std::string printed_clearance(double clearance_m) {
  if (std::isnan(clearance_m)) return "nan";
  if (std::isinf(clearance_m)) return "inf";
  char text[32];
  std::snprintf(text, sizeof text, "%.3f", clearance_m);
  return text;
}

// The line vnsba_plan prints for what core plans with these settings (up to the time).
std::string printed_line(const std::shared_ptr<const core::GridMap>& map,
                         const core::PlanQuery& query, core::PlannerKind kind,
                         const core::PlannerSettings& settings) {
  const core::PlanResult r = core::plan_once(map, query, core::make_options(kind, settings));
  char line[200];
  std::snprintf(line, sizeof line,
                "%s %s length_m=%.3f clearance_m=%s turns=%d turn_angle_deg=%.1f expanded=%lld",
                std::string(core::to_string(kind)).c_str(),
                std::string(core::to_string(r.status.code)).c_str(), r.metrics.length_m,
                printed_clearance(r.metrics.clearance_m).c_str(), r.metrics.turns,
                r.metrics.turn_angle_deg, static_cast<long long>(r.metrics.expanded));
  return line;
}

// The value of `key=` on the result line, or nullopt when the line lacks it.
std::optional<std::string> field(const std::string& output, const std::string& key) {
  const size_t at = output.find(" " + key + "=");
  if (at == std::string::npos) return std::nullopt;
  const size_t begin = at + key.size() + 2;
  return output.substr(begin, output.find_first_of(" \n", begin) - begin);
}

// `name` in a fresh directory of its own (not made: what vnsba_plan writes there).
std::string temp_file(const std::string& name) {
  return (FreshTempDir("plan_" + name) / name).string();
}

// A file in a folder that does not exist, in an empty directory of its own: nothing can have made
// it, and nothing can be written there.
std::string unreachable_file(const std::string& name) {
  return (FreshTempDir("plan_unreachable") / "no_such_dir" / name).string();
}

// The poses file: one `x y yaw` per line.
std::vector<core::Pose2> read_poses(const std::string& path) {
  std::vector<core::Pose2> poses;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    std::istringstream fields(line);
    core::Pose2 p;
    EXPECT_TRUE(fields >> p.x >> p.y >> p.yaw) << line;
    std::string rest;
    EXPECT_FALSE(fields >> rest) << "more than x y yaw: " << line;
    poses.push_back(p);
  }
  return poses;
}

double angle_difference(double a, double b) {
  return std::abs(std::remainder(a - b, 2.0 * M_PI));
}

TEST(VnsbaPlan, PlansAndDrawsTheRun) {
  const std::string svg = temp_file("plan") + ".svg";
  // Metres on a Moving AI map are cells (1 m cells, origin 0, rows counted from the bottom).
  const auto [code, output] =
      run_plan({kRooms, "--start", "2.5", "2.5", "--goal", "29.5", "13.5", "--svg", svg});
  ASSERT_EQ(code, 0) << output;
  EXPECT_NE(output.find("vns_bastar OK"), std::string::npos) << output;
  tinyxml2::XMLDocument doc;
  ASSERT_EQ(doc.LoadFile(svg.c_str()), tinyxml2::XML_SUCCESS);
  const auto* root = doc.RootElement();
  EXPECT_GT(data_count(find_id(root, "expanded-forward")), 0);
  EXPECT_GT(data_count(find_id(root, "expanded-backward")), 0);
  const auto path = decode_polylines(find_id(root, "final-path"), 16);
  ASSERT_EQ(path.size(), 1u);
  EXPECT_NEAR(path[0].front().x(), 2.5, 1e-3);
  EXPECT_NEAR(path[0].back().y(), 13.5, 1e-3);
  std::remove(svg.c_str());
}

TEST(VnsbaPlan, CellsAndOtherPlanners) {
  const auto [code, output] = run_plan(
      {kRooms, "--cells", "--start", "2", "2", "--goal", "29", "13", "--planner", "astar"});
  ASSERT_EQ(code, 0) << output;
  EXPECT_NE(output.find("astar OK"), std::string::npos) << output;
}

// The planner flags become core::make_options(--planner, the flags given): the tool plans what
// core plans with those settings, and a flag left out follows the chosen planner's paper
// configuration.
TEST(VnsbaPlan, PlannerFlagsAreSettingsOnTopOfThePlannersPaperConfiguration) {
  auto map = std::make_shared<const core::GridMap>(
      core::GridMap::build(maps::load_movingai_map(kRooms).value()).value());
  const core::PlanQuery query{{2, 2}, {29, 13}};
  auto printed = [&](core::PlannerKind kind, const core::PlannerSettings& settings) {
    const std::string line = printed_line(map, query, kind, settings);
    EXPECT_NE(line.find(" OK "), std::string::npos) << line;
    return line;
  };
  struct Case {
    std::vector<std::string> flags;
    core::PlannerKind kind;
    core::PlannerSettings settings;
  };
  std::vector<Case> cases(6);
  cases[0] = {{}, core::PlannerKind::kVnsBaStar, {}};
  cases[1] = {{"--no-prune", "--no-smooth"}, core::PlannerKind::kVnsBaStar, {}};
  cases[1].settings.prune = cases[1].settings.smooth = false;
  cases[2] = {{"--no-prune"}, core::PlannerKind::kVnsBaStar, {}};
  cases[2].settings.prune = false;
  cases[3] = {{"--planner", "astar", "--prune", "--smooth"}, core::PlannerKind::kAStar, {}};
  cases[3].settings.prune = cases[3].settings.smooth = true;
  cases[4] = {{"--planner", "astar", "--neighborhood", "8-11-13", "--corner-policy", "touch"},
              core::PlannerKind::kAStar,
              {}};
  cases[4].settings.neighborhood = core::Neighborhood::kEightElevenThirteen;
  cases[4].settings.corner_policy = core::CornerPolicy::kTouch;
  cases[5] = {{"--omega", "1", "--eta", "0"}, core::PlannerKind::kVnsBaStar, {}};
  cases[5].settings.omega = 1.0;
  cases[5].settings.eta = 0.0;
  for (const Case& c : cases) {
    std::vector<std::string> args = {kRooms, "--cells", "--start", "2", "2", "--goal", "29", "13"};
    std::string flags;
    for (const std::string& f : c.flags) {
      args.push_back(f);
      flags += f + " ";
    }
    SCOPED_TRACE(flags);
    const std::string expected = printed(c.kind, c.settings);
    // Each case plans differently from its planner's paper configuration, so a dropped flag
    // shows.
    if (!c.flags.empty()) {
      EXPECT_NE(expected, printed(c.kind, {}));
    }
    const auto [code, output] = run_plan(args);
    ASSERT_EQ(code, 0) << output;
    EXPECT_NE(output.find(expected), std::string::npos) << "expected: " << expected << "\n"
                                                        << output;
  }
}

TEST(VnsbaPlan, ReadsMapServerAndOctoMapFiles) {
  // map_server: a 8-bit P5 image with its YAML (the whole map is checked by the map_io tests).
  const auto [code, output] =
      run_plan({VNSBA_FIXTURE_DIR "/map_server/p5_8bit.yaml", "--cells", "--start", "0", "0",
                "--goal", "0", "0", "--planner", "astar"});
  EXPECT_TRUE(code == 0 || code == 1) << output;  // a plan ran: OK or a planner status
  EXPECT_NE(output.find("astar "), std::string::npos) << output;

  const std::string bt = VNSBA_DATA_DIR "/octomap/geb079.bt";
  if (!std::ifstream(bt)) GTEST_SKIP() << bt << " is absent (third-party data beside the project)";
  const std::string svg = temp_file("plan_bt") + ".svg";
  // A band at hip height, both ends in the building's long corridor would need the map: just
  // require the slice to load and a planner answer with a picture of the map.
  const auto [bt_code, bt_output] = run_plan({bt, "--z-min", "0.3", "--z-max", "1.2", "--start",
                                              "0", "0", "--goal", "1", "1", "--svg", svg});
  EXPECT_TRUE(bt_code == 0 || bt_code == 1) << bt_output;
  tinyxml2::XMLDocument doc;
  ASSERT_EQ(doc.LoadFile(svg.c_str()), tinyxml2::XML_SUCCESS);
  EXPECT_GT(data_count(find_id(doc.RootElement(), "map-occupied")), 100);
  std::remove(svg.c_str());
}

// simple.bt (a 1 m test tree of the OctoMap project) has leaves spanning its whole key space,
// 65,536 m across: sliced whole it is refused, naming the file and the options that fix it; with
// --bounds (x_min,y_min,x_max,y_max in metres, as vnsba_slicer takes them) vnsba_plan plans on a
// part of it, exactly what core plans on the slice of that area.
TEST(VnsbaPlan, BoundsPlanOnAPartOfATreeTooLargeToSliceWhole) {
  const std::string bt = VNSBA_DATA_DIR "/octomap/simple.bt";
  if (!std::ifstream(bt)) GTEST_SKIP() << bt << " is absent (third-party data beside the project)";
  const auto [whole_code, whole] = run_plan({bt, "--start", "0", "0", "--goal", "1", "1"});
  EXPECT_EQ(whole_code, 2) << whole;
  for (const std::string& part : {bt + ": the slice would have ", std::string("--bounds"),
                                  std::string("--resolution"), std::string("the tree's extent")})
    EXPECT_NE(whole.find(part), std::string::npos) << part << " not in: " << whole;

  maps::SliceOptions area;  // vnsba_plan's default band
  area.bounds = maps::SliceBounds{-10, -10, 10, 10};
  const auto tree = maps::load_octree(bt);
  ASSERT_TRUE(tree) << tree.error().message;
  const auto slice = maps::slice_octree(**tree, area);
  ASSERT_TRUE(slice) << slice.error().message;
  auto map = std::make_shared<const core::GridMap>(core::GridMap::build(*slice).value());
  // The first and the last free cell in row order, as start and goal.
  std::optional<core::Cell> first, last;
  for (int32_t y = 0; y < map->height(); ++y)
    for (int32_t x = 0; x < map->width(); ++x)
      if (map->free({x, y})) {
        if (!first) first = core::Cell{x, y};
        last = core::Cell{x, y};
      }
  ASSERT_TRUE(first && last && *first != *last) << "no two free cells in the area";
  const core::PlanQuery query{*first, *last};
  const std::string expected =
      printed_line(map, query, core::PlannerKind::kVnsBaStar, core::PlannerSettings{});
  ASSERT_NE(expected.find(" OK "), std::string::npos) << "the area holds a path: " << expected;
  const Eigen::Vector2d start = map->cell_centre_world(*first),
                        goal = map->cell_centre_world(*last);
  auto metres = [](double v) { return std::to_string(v); };
  for (const std::vector<std::string>& bounds :
       {std::vector<std::string>{"--bounds", "-10,-10,10,10"},
        std::vector<std::string>{"--bounds", "-10", "-10", "10", "10"}}) {
    std::vector<std::string> args = {
        bt,       "--start",        metres(start.x()), metres(start.y()),
        "--goal", metres(goal.x()), metres(goal.y())};
    args.insert(args.end(), bounds.begin(), bounds.end());
    const auto [code, output] = run_plan(args);
    EXPECT_EQ(code, 0) << output;
    EXPECT_NE(output.find(expected), std::string::npos) << "expected: " << expected << "\n"
                                                        << output;
  }

  struct Case {
    std::vector<std::string> args;
    std::string named;
  };
  for (const Case& c : {
           Case{{bt, "--bounds", "-10,-10,10"}, "--bounds"},
           Case{{bt, "--bounds", "10,-10,-10,10"}, "--bounds = 10,-10,-10,10 m is empty"},
           Case{{bt, "--bounds", "-10,-10,nan,10"}, "--bounds"},
           Case{{kRooms, "--bounds", "0,0,5,5"}, "--bounds: only for OctoMap files"},
           Case{{kRooms, "--z-min", "0.5"}, "--z-min: only for OctoMap files"},
       }) {
    std::vector<std::string> args = c.args;
    for (const char* a : {"--start", "1", "1", "--goal", "2", "2"}) args.push_back(a);
    const auto [code, output] = run_plan(args);
    EXPECT_EQ(code, 2) << output;
    EXPECT_NE(output.find(c.named), std::string::npos) << c.named << ": " << output;
  }
}

TEST(VnsbaPlan, PlannerFailuresExitOneWithTheStatus) {
  const auto [code, output] =
      run_plan({kRooms, "--cells", "--start", "2", "2", "--goal", "0", "0"});
  EXPECT_EQ(code, 1) << output;
  EXPECT_NE(output.find("GOAL_OCCUPIED"), std::string::npos) << output;
}

TEST(VnsbaPlan, BadInputExitsTwoNamingTheOption) {
  struct Case {
    std::vector<std::string> args;
    const char* named;
  };
  const std::string unwritable_svg = unreachable_file("x.svg");
  for (const Case& c : {
           Case{{kRooms, "--start", "1", "1", "--goal", "2", "2", "--planner", "dijkstra"},
                "--planner"},
           Case{{kRooms, "--start", "-5", "1", "--goal", "2", "2"}, "--start"},
           Case{{kRooms, "--start", "1", "1", "--goal", "nan", "2"}, "--goal"},
           Case{{kRooms, "--cells", "--start", "1.5", "1", "--goal", "2", "2"}, "--start"},
           Case{{kRooms, "--start", "1", "1"}, "--goal"},
           Case{{VNSBA_FIXTURE_DIR "/maps/none.map", "--start", "1", "1", "--goal", "2", "2"},
                "none.map"},
           Case{{VNSBA_FIXTURE_DIR "/config/empty.yaml", "--start", "1", "1", "--goal", "2", "2"},
                "empty.yaml"},
           Case{{kRooms, "--start", "2", "2", "--goal", "3", "3", "--svg", unwritable_svg},
                "--svg"},
           Case{{kRooms, "--start", "2", "2", "--goal", "3", "3", "--neighborhood", "4"},
                "--neighborhood"},
           Case{{kRooms, "--start", "2", "2", "--goal", "3", "3", "--corner-policy", "sometimes"},
                "--corner-policy"},
           Case{{kRooms, "--start", "2", "2", "--goal", "3", "3", "--omega", "-1"}, "--omega"},
           Case{{kRooms, "--start", "2", "2", "--goal", "3", "3", "--omega", "0", "--eta", "0"},
                "omega and eta"},
       }) {
    const auto [code, output] = run_plan(c.args);
    EXPECT_EQ(code, 2) << output;
    EXPECT_NE(output.find(c.named), std::string::npos) << c.named << ": " << output;
  }
}

// Issue 31: an unknown flag is named first, with the flag it was probably meant to be, and exits 2
// as every other usage error.
TEST(VnsbaPlan, AnUnknownFlagIsNamedWithTheNearestKnownOne) {
  for (const auto& [args, said] : {
           std::pair<std::vector<std::string>, std::string>{
               {kRooms, "--strat", "1", "1", "--goal", "2", "2"},
               "unknown option --strat (did you mean --start?)"},
           {{kRooms, "--start", "1", "1", "--goal", "2", "2", "--robot-radius-m", "0.3"},
            "unknown option --robot-radius-m (did you mean --robot-radius?)"},
           {{kRooms, "--start", "1", "1", "--goal", "2", "2", "--no-such-flag"},
            "unknown option --no-such-flag"},
       }) {
    const auto [code, output] = run_plan(args);
    EXPECT_EQ(code, 2) << output;
    EXPECT_NE(output.find(said), std::string::npos) << said << " not in:\n" << output;
  }
}

// Issue 31: a slicing value from --config is blamed on its key and file, not on a flag nobody
// gave; a flag given is named as the flag. geb079.bt's leaves are `leaf` metres, so 1.5 leaves
// is no whole multiple of them.
TEST(VnsbaPlan, ASliceValueFromTheConfigIsNamedByItsKey) {
  const std::string bt = VNSBA_DATA_DIR "/octomap/geb079.bt";
  if (!std::ifstream(bt)) GTEST_SKIP() << bt << " is absent (third-party data beside the project)";
  const auto tree = maps::load_octree(bt);
  ASSERT_TRUE(tree) << tree.error().message;
  char resolution[32];
  std::snprintf(resolution, sizeof resolution, "%.6f", 1.5 * (*tree)->getResolution());
  const std::string config = write_temp_file(
      "plan_slicer.yaml", std::string("slicer:\n  resolution: ") + resolution + "\n");
  const std::vector<std::string> query = {bt,   "--start", "2",        "-6",  "--goal",
                                          "16", "-6.5",    "--config", config};
  const auto [code, output] = run_plan(query);
  EXPECT_EQ(code, 2) << output;
  EXPECT_NE(output.find("slicer.resolution in " + config), std::string::npos) << output;
  EXPECT_EQ(output.find("--resolution"), std::string::npos) << output;

  std::vector<std::string> with_flag = query;
  with_flag.insert(with_flag.end(), {"--resolution", resolution});
  const auto [flag_code, flag_output] = run_plan(with_flag);
  EXPECT_EQ(flag_code, 2) << flag_output;
  EXPECT_NE(flag_output.find("--resolution is"), std::string::npos) << flag_output;
  EXPECT_EQ(flag_output.find("slicer.resolution"), std::string::npos) << flag_output;
  std::remove(config.c_str());
}

// Every new option is refused (exit 2) for a value outside its core range, naming the option and
// its unit; --path-spacing and --goal-yaw only mean something with --poses.
TEST(VnsbaPlan, NewOptionsRefuseBadValuesNamingTheOptionAndUnit) {
  struct Case {
    std::vector<std::string> flags;
    std::vector<std::string> named;
  };
  const std::string poses = temp_file("bad_poses");
  for (const Case& c : {
           Case{{"--inflation-radius", "-1"}, {"--inflation-radius", "metres"}},
           Case{{"--inflation-radius", "inf"}, {"--inflation-radius", "metres"}},
           Case{{"--robot-radius", "1", "--inflation-radius", "0.5"},
                {"--inflation-radius", "--robot-radius", "metres"}},
           Case{{"--cost-scaling-factor", "-2"}, {"--cost-scaling-factor", "per metre"}},
           Case{{"--cost-weight", "-1"}, {"--cost-weight", "[0, 1000]"}},
           Case{{"--cost-weight", "2000"}, {"--cost-weight", "[0, 1000]"}},
           Case{{"--goal-tolerance", "-0.5"}, {"--goal-tolerance", "metres in [0, 100]"}},
           Case{{"--goal-tolerance", "101"}, {"--goal-tolerance", "metres in [0, 100]"}},
           Case{{"--start-tolerance", "nan"}, {"--start-tolerance", "metres in [0, 100]"}},
           Case{{"--poses", poses, "--path-spacing", "0"}, {"--path-spacing", "metres"}},
           Case{{"--poses", poses, "--path-spacing", "-1"}, {"--path-spacing", "metres"}},
           Case{{"--poses", poses, "--path-spacing", "1e-9"}, {"--path-spacing", "poses"}},
           Case{{"--poses", poses, "--goal-yaw", "inf"}, {"--goal-yaw", "radians"}},
           Case{{"--path-spacing", "0.5"}, {"--path-spacing: only with --poses"}},
           Case{{"--goal-yaw", "1"}, {"--goal-yaw: only with --poses"}},
       }) {
    std::vector<std::string> args = {kRooms, "--start", "2.5", "2.5", "--goal", "29.5", "13.5"};
    std::string flags;
    for (const std::string& f : c.flags) {
      args.push_back(f);
      flags += f + " ";
    }
    SCOPED_TRACE(flags);
    const auto [code, output] = run_plan(args);
    EXPECT_EQ(code, 2) << output;
    for (const std::string& part : c.named)
      EXPECT_NE(output.find(part), std::string::npos) << part << " not in: " << output;
  }
  std::remove(poses.c_str());
}

// --inflation-radius and --cost-scaling-factor go into the map's build, --cost-weight into the
// planner settings: the tool prints what core plans on that map with those settings.
TEST(VnsbaPlan, CostOptionsAreTheMapBuildAndPlannerSettings) {
  core::GridBuildOptions build;
  build.inflation_radius = 4.0;
  build.cost_scaling_factor = 0.5;
  auto grid = maps::load_movingai_map(kRooms).value();
  auto costly = std::make_shared<const core::GridMap>(core::GridMap::build(grid, build).value());
  auto plain = std::make_shared<const core::GridMap>(core::GridMap::build(grid).value());
  ASSERT_TRUE(costly->has_costs());
  const core::PlanQuery query{{2, 2}, {29, 13}};
  core::PlannerSettings settings;
  settings.cost_weight = 20.0;
  const std::string expected = printed_line(costly, query, core::PlannerKind::kVnsBaStar, settings);
  ASSERT_NE(expected.find(" OK "), std::string::npos) << expected;
  EXPECT_NE(expected, printed_line(plain, query, core::PlannerKind::kVnsBaStar, {}));
  const auto [code, output] =
      run_plan({kRooms, "--cells", "--start", "2", "2", "--goal", "29", "13", "--inflation-radius",
                "4", "--cost-scaling-factor", "0.5", "--cost-weight", "20"});
  ASSERT_EQ(code, 0) << output;
  EXPECT_NE(output.find(expected), std::string::npos) << "expected: " << expected << "\n" << output;
}

// clearance_m comes right after length_m: positive metres on a map with walls, inf without any.
TEST(VnsbaPlan, PrintsTheClearance) {
  const auto [code, output] = run_plan({kRooms, "--start", "2.5", "2.5", "--goal", "29.5", "13.5"});
  ASSERT_EQ(code, 0) << output;
  const auto clearance = field(output, "clearance_m");
  ASSERT_TRUE(clearance) << output;
  EXPECT_GT(std::stod(*clearance), 0.0) << output;
  EXPECT_TRUE(std::isfinite(std::stod(*clearance))) << output;
  const size_t length = output.find(" length_m="), after = output.find(" clearance_m=");
  ASSERT_NE(length, std::string::npos);
  EXPECT_EQ(output.find(' ', length + 1), after) << "clearance_m right after length_m: " << output;
  EXPECT_EQ(output.find(" start_moved_m="), std::string::npos) << output;
  EXPECT_EQ(output.find(" goal_moved_m="), std::string::npos) << output;

  const std::string open = temp_file("open") + ".map";
  std::ofstream(open) << "type octile\nheight 4\nwidth 6\nmap\n......\n......\n......\n......\n";
  const auto [open_code, open_output] =
      run_plan({open, "--cells", "--start", "0", "0", "--goal", "5", "3"});
  ASSERT_EQ(open_code, 0) << open_output;
  EXPECT_EQ(field(open_output, "clearance_m"), std::optional<std::string>("inf")) << open_output;
  std::remove(open.c_str());
}

// --poses writes core::path_poses of the world path: consecutive poses at most the spacing apart
// (default the map's 1 m resolution), each yaw the heading to the next pose, the last --goal-yaw
// when given (else the heading of the segment arriving at it).
TEST(VnsbaPlan, PosesAreAtMostTheSpacingApartWithTheTangentAsYaw) {
  const std::string poses_file = temp_file("poses");
  struct Case {
    std::vector<std::string> flags;
    double spacing;
    std::optional<double> goal_yaw;
  };
  for (const Case& c :
       {Case{{}, 1.0, std::nullopt}, Case{{"--path-spacing", "0.3"}, 0.3, std::nullopt},
        Case{{"--path-spacing", "0.25", "--goal-yaw", "2.5"}, 0.25, 2.5},
        Case{{"--goal-yaw", "-4"}, 1.0, -4.0 + 2.0 * M_PI}}) {
    std::vector<std::string> args = {kRooms, "--start", "2.5",     "2.5",     "--goal",
                                     "29.5", "13.5",    "--poses", poses_file};
    args.insert(args.end(), c.flags.begin(), c.flags.end());
    SCOPED_TRACE(::testing::PrintToString(c.flags));
    const auto [code, output] = run_plan(args);
    ASSERT_EQ(code, 0) << output;
    const std::vector<core::Pose2> poses = read_poses(poses_file);
    ASSERT_GE(poses.size(), 30u);  // 27 m across and 11 m up, at most 1 m apart
    EXPECT_NEAR(poses.front().x, 2.5, 1e-6);
    EXPECT_NEAR(poses.front().y, 2.5, 1e-6);
    EXPECT_NEAR(poses.back().x, 29.5, 1e-6);
    EXPECT_NEAR(poses.back().y, 13.5, 1e-6);
    double length = 0.0;
    for (size_t i = 0; i + 1 < poses.size(); ++i) {
      const double dx = poses[i + 1].x - poses[i].x, dy = poses[i + 1].y - poses[i].y;
      const double d = std::hypot(dx, dy);
      length += d;
      // 1e-6 of slack, plus the printed precision (each coordinate rounded to 1e-6).
      EXPECT_LE(d, c.spacing + 1e-6 + 2e-6) << "poses " << i << " and " << i + 1;
      ASSERT_GT(d, 0.0) << "duplicate pose " << i;
      // The heading error the rounding of both ends can cause: about 1.5e-6 / d.
      EXPECT_LE(angle_difference(poses[i].yaw, std::atan2(dy, dx)), 2e-6 / d + 2e-6)
          << "pose " << i;
    }
    const core::Pose2& last = poses.back();
    if (c.goal_yaw) {
      EXPECT_NEAR(last.yaw, *c.goal_yaw, 1e-6);
    } else {
      const core::Pose2& before = poses[poses.size() - 2];
      const double d = std::hypot(last.x - before.x, last.y - before.y);
      EXPECT_LE(angle_difference(last.yaw, std::atan2(last.y - before.y, last.x - before.x)),
                2e-6 / d + 2e-6);
    }
    for (const core::Pose2& p : poses) EXPECT_TRUE(p.yaw > -M_PI - 1e-6 && p.yaw <= M_PI + 1e-6);
    const auto length_m = field(output, "length_m");
    ASSERT_TRUE(length_m) << output;
    EXPECT_NEAR(length, std::stod(*length_m), 1e-3 + 1e-5 * static_cast<double>(poses.size()));
  }
  // A failed plan leaves an empty file (no stale poses of an earlier run).
  const auto [code, output] =
      run_plan({kRooms, "--cells", "--start", "2", "2", "--goal", "0", "0", "--poses", poses_file});
  EXPECT_EQ(code, 1) << output;
  EXPECT_TRUE(read_poses(poses_file).empty());
  std::remove(poses_file.c_str());
}

// A goal inside a wall (x = 15 is the rooms map's middle wall): refused naming the layer without
// tolerance, moved to the nearest free cell centre with it, measured from the requested point.
TEST(VnsbaPlan, GoalToleranceMovesABlockedGoalToTheNearestFreeCell) {
  const std::vector<std::string> args = {kRooms, "--start", "2.5", "2.5", "--goal", "15.3", "2.5"};
  const auto [blocked_code, blocked] = run_plan(args);
  EXPECT_EQ(blocked_code, 1) << blocked;
  EXPECT_NE(blocked.find("GOAL_OCCUPIED"), std::string::npos) << blocked;
  EXPECT_NE(blocked.find("occupied cell"), std::string::npos) << blocked;  // the layer
  EXPECT_EQ(field(blocked, "clearance_m"), std::optional<std::string>("nan")) << blocked;

  std::vector<std::string> tolerant = args;
  const std::string poses_file = temp_file("tolerant_poses");
  for (const char* a : {"--goal-tolerance", "1", "--poses", poses_file.c_str()})
    tolerant.push_back(a);
  const auto [code, output] = run_plan(tolerant);
  ASSERT_EQ(code, 0) << output;
  EXPECT_NE(output.find("vns_bastar OK"), std::string::npos) << output;
  // (14.5, 2.5) is 0.8 m from the requested (15.3, 2.5); (16.5, 2.5) is 1.2 m.
  const auto moved = field(output, "goal_moved_m");
  ASSERT_TRUE(moved) << output;
  EXPECT_GT(std::stod(*moved), 0.0);
  EXPECT_EQ(*moved, "0.800") << output;
  EXPECT_EQ(output.find(" start_moved_m="), std::string::npos) << output;
  const std::vector<core::Pose2> poses = read_poses(poses_file);
  ASSERT_FALSE(poses.empty());
  EXPECT_NEAR(poses.back().x, 14.5, 1e-6);
  EXPECT_NEAR(poses.back().y, 2.5, 1e-6);
  std::remove(poses_file.c_str());

  // Too little tolerance: the status says so, with the layer.
  std::vector<std::string> short_reach = args;
  short_reach.push_back("--goal-tolerance");
  short_reach.push_back("0.5");
  const auto [short_code, short_output] = run_plan(short_reach);
  EXPECT_EQ(short_code, 1) << short_output;
  EXPECT_NE(short_output.find("occupied cell"), std::string::npos) << short_output;
  EXPECT_NE(short_output.find("goal_tolerance"), std::string::npos) << short_output;
}

// A goal outside the map is refused by the tool without tolerance and planned to the nearest
// free cell with it (core resolves it from the cell containing the requested point).
TEST(VnsbaPlan, GoalToleranceBringsAGoalOutsideTheMapIn) {
  // Column 31 is the border wall; (30.5, 5.5) is the nearest free centre to (33, 5.5): 2.5 m.
  const std::vector<std::string> args = {kRooms, "--start", "2.5", "2.5", "--goal", "33", "5.5"};
  const auto [outside_code, outside] = run_plan(args);
  EXPECT_EQ(outside_code, 2) << outside;
  // In metres, as given, with the map's rectangle: rooms_32 is 32 x 16 cells of 1 m at (0, 0).
  EXPECT_NE(outside.find("--goal (33.000, 5.500) m is outside the map [0.000, 32.000] x "
                         "[0.000, 16.000] m"),
            std::string::npos)
      << outside;
  EXPECT_NE(outside.find("--goal-tolerance"), std::string::npos) << outside;

  std::vector<std::string> tolerant = args;
  tolerant.push_back("--goal-tolerance");
  tolerant.push_back("3");
  const auto [code, output] = run_plan(tolerant);
  ASSERT_EQ(code, 0) << output;
  EXPECT_EQ(field(output, "goal_moved_m"), std::optional<std::string>("2.500")) << output;

  tolerant.back() = "1";
  const auto [far_code, far] = run_plan(tolerant);
  EXPECT_EQ(far_code, 1) << far;
  EXPECT_NE(far.find("GOAL_OUTSIDE_MAP"), std::string::npos) << far;
  // Metres, as the node words it (core's message names the cell), never cells.
  EXPECT_NE(far.find("goal (33.000, 5.500) m is outside the map [0.000, 32.000] x "
                     "[0.000, 16.000] m; no free cell within goal_tolerance 1 m"),
            std::string::npos)
      << far;
  EXPECT_EQ(far.find("cells)"), std::string::npos) << far;
}

// --start-tolerance moves a start blocked by inflation only (--robot-radius) to a free cell.
TEST(VnsbaPlan, StartToleranceMovesAStartOutOfInflation) {
  // (1.5, 1.5) is 1 m from the walls' cell centres: inflated by a 1 m robot radius.
  // The goal stays in the same room: a 1 m radius closes the rooms map's doors.
  const std::vector<std::string> args = {kRooms, "--start",        "1.5", "1.5", "--goal", "12.5",
                                         "2.5",  "--robot-radius", "1"};
  const auto [blocked_code, blocked] = run_plan(args);
  EXPECT_EQ(blocked_code, 1) << blocked;
  EXPECT_NE(blocked.find("START_OCCUPIED"), std::string::npos) << blocked;
  EXPECT_NE(blocked.find("inflation"), std::string::npos) << blocked;

  std::vector<std::string> tolerant = args;
  tolerant.push_back("--start-tolerance");
  tolerant.push_back("2");
  const auto [code, output] = run_plan(tolerant);
  ASSERT_EQ(code, 0) << output;
  const auto moved = field(output, "start_moved_m");
  ASSERT_TRUE(moved) << output;
  EXPECT_GT(std::stod(*moved), 0.0);
  EXPECT_LE(std::stod(*moved), 2.0);
  EXPECT_EQ(output.find(" goal_moved_m="), std::string::npos) << output;
}

// The result line without its times (time_us= and what --repeat adds), for comparing two runs.
std::string without_times(const std::string& output) {
  const size_t newline = output.find('\n');
  std::string line = output.substr(0, newline);
  for (const char* key : {" time_us=", " repeats=", " first_time_us=", " median_time_us="}) {
    const size_t at = line.find(key);
    if (at == std::string::npos) continue;
    const size_t end = line.find(' ', at + 1);
    line.erase(at, end == std::string::npos ? std::string::npos : end - at);
  }
  return line;
}

// --config FILE: its planner and map keys plan exactly as the same values given as flags (the
// oracle is the flag run), and a flag given beside the config overrides its key.
TEST(VnsbaPlan, ConfigKeysPlanAsTheSameFlags) {
  const std::string config = write_temp_file("plan_config.yaml",
                                             "planner:\n"
                                             "  name: astar\n"
                                             "  neighborhood: \"8-11-13\"\n"
                                             "  prune: true\n"
                                             "  smooth: true\n"
                                             "  cost_weight: 2.0\n"
                                             "  goal_tolerance: 0.5\n"
                                             "map:\n"
                                             "  robot_radius: 0.5\n"
                                             "  inflation_radius: 2.0\n"
                                             "  cost_scaling_factor: 1.5\n");
  const std::vector<std::string> query = {kRooms,   "--start", "2.5", "2.5",
                                          "--goal", "29.5",    "13.5"};
  const std::vector<std::string> as_flags = {
      "--neighborhood",        "8-11-13", "--prune",        "--smooth", "--cost-weight",      "2",
      "--goal-tolerance",      "0.5",     "--robot-radius", "0.5",      "--inflation-radius", "2",
      "--cost-scaling-factor", "1.5",     "--smoother",     "relax"};
  auto with = [&](std::vector<std::string> a, const std::vector<std::string>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
  };
  const auto [config_code, config_output] = run_plan(with(query, {"--config", config}));
  ASSERT_EQ(config_code, 0) << config_output;
  const auto [flag_code, flag_output] =
      run_plan(with(with(query, as_flags), {"--planner", "astar"}));
  ASSERT_EQ(flag_code, 0) << flag_output;
  EXPECT_EQ(config_output.rfind("astar OK", 0), 0u) << config_output;  // planner.name was read
  EXPECT_EQ(without_times(config_output), without_times(flag_output));

  // Flags override: the config's planner and smoothing replaced.
  const auto [override_code, override_output] =
      run_plan(with(query, {"--config", config, "--planner", "vns_bastar", "--no-smooth"}));
  ASSERT_EQ(override_code, 0) << override_output;
  std::vector<std::string> override_flags = as_flags;
  override_flags[3] = "--no-smooth";
  const auto [oracle_code, oracle_output] =
      run_plan(with(with(query, override_flags), {"--planner", "vns_bastar"}));
  ASSERT_EQ(oracle_code, 0) << oracle_output;
  EXPECT_EQ(override_output.rfind("vns_bastar OK", 0), 0u) << override_output;
  EXPECT_EQ(without_times(override_output), without_times(oracle_output));
  std::remove(config.c_str());
}

// --planner auto is the planner core::recommended_planner names for the options, pruned and
// smoothed: the same line as asking for that planner with --prune --smooth.
TEST(VnsbaPlan, AutoIsJpsWithoutCostsAndTheCostAwareChoiceWithThem) {
  const std::vector<std::string> query = {kRooms,   "--start", "2.5", "2.5",
                                          "--goal", "29.5",    "13.5"};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = query;
    args.insert(args.end(), extra.begin(), extra.end());
    return run_plan(args);
  };
  const std::vector<std::string> costs = {"--cost-weight", "2", "--inflation-radius", "2"};
  for (const bool with_costs : {false, true}) {
    SCOPED_TRACE(with_costs ? "with costs" : "without costs");
    const std::string expected(core::to_string(core::recommended_planner(
        with_costs ? 2.0 : 0.0, core::Neighborhood::kEight, core::CornerPolicy::kNever)));
    std::vector<std::string> auto_args = {"--planner", "auto"};
    std::vector<std::string> named_args = {"--planner", expected, "--prune", "--smooth"};
    if (with_costs) {
      auto_args.insert(auto_args.end(), costs.begin(), costs.end());
      named_args.insert(named_args.end(), costs.begin(), costs.end());
    }
    const auto [auto_code, auto_output] = with(auto_args);
    ASSERT_EQ(auto_code, 0) << auto_output;
    EXPECT_EQ(auto_output.rfind(expected + " OK", 0), 0u) << auto_output;
    const auto [named_code, named_output] = with(named_args);
    ASSERT_EQ(named_code, 0) << named_output;
    EXPECT_EQ(without_times(auto_output), without_times(named_output));
  }
  EXPECT_EQ(core::recommended_planner(0.0, core::Neighborhood::kEight, core::CornerPolicy::kNever),
            core::PlannerKind::kJps);
  EXPECT_TRUE(core::supports_costs(
      core::recommended_planner(2.0, core::Neighborhood::kEight, core::CornerPolicy::kNever)));
  // An unknown name lists auto among the known ones.
  const auto [bad_code, bad_output] = with({"--planner", "automatic"});
  EXPECT_EQ(bad_code, 2);
  EXPECT_NE(bad_output.find("known: auto,"), std::string::npos) << bad_output;
}

// Issue 45: the shortest command plans for the node's robot. Without --config vnsba_plan reads
// default.yaml, as the node does (the oracle: the same file given with --config); --paper plans
// the paper's setting (the oracle: config/paper.yaml, which spells that setting out), and the two
// flags together are refused.
// The planners come from the registry: --list-planners names each with what it searches with,
// and each plans when --planner names it, whatever planners there are.
TEST(VnsbaPlan, ListsAndPlansEveryRegisteredPlanner) {
  const auto [code, listing] = run_plan_as_given({"--list-planners"});
  ASSERT_EQ(code, 0) << listing;
  for (const core::PlannerDescriptor* planner : core::registered_planners()) {
    const std::string name(planner->name);
    SCOPED_TRACE(name);
    EXPECT_NE(listing.find(name + " (" + std::string(planner->paper_name) +
                           "): " + std::string(planner->summary)),
              std::string::npos)
        << listing;
    const auto [plan_code, output] =
        run_plan({kRooms, "--start", "2.5", "2.5", "--goal", "29.5", "13.5", "--planner", name});
    EXPECT_EQ(plan_code, 0) << output;
    EXPECT_NE(output.find(name), std::string::npos) << output;
  }
  EXPECT_NE(listing.find("its own options: omega, eta"), std::string::npos) << listing;
}

TEST(VnsbaPlan, WithoutConfigPlansAsDefaultYamlAndPaperAsThePaper) {
  const std::vector<std::string> query = {kRooms,   "--start", "2.5", "2.5",
                                          "--goal", "29.5",    "13.5"};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = query;
    args.insert(args.end(), extra.begin(), extra.end());
    return run_plan_as_given(args);
  };
  const auto [bare_code, bare_output] = with({});
  ASSERT_EQ(bare_code, 0) << bare_output;
  const auto [default_code, default_output] =
      with({"--config", kSourceConfigDir + "/default.yaml"});
  ASSERT_EQ(default_code, 0) << default_output;
  EXPECT_EQ(without_times(bare_output), without_times(default_output));

  const auto [paper_code, paper_output] = with({"--paper"});
  ASSERT_EQ(paper_code, 0) << paper_output;
  const auto [paper_file_code, paper_file_output] =
      with({"--config", kSourceConfigDir + "/paper.yaml"});
  ASSERT_EQ(paper_file_code, 0) << paper_file_output;
  EXPECT_EQ(without_times(paper_output), without_times(paper_file_output));
  EXPECT_EQ(paper_output.rfind("vns_bastar OK", 0), 0u) << paper_output;
  // default.yaml's robot plans with costs: another planner (auto's cost-aware choice), so
  // another line.
  EXPECT_NE(without_times(bare_output), without_times(paper_output));

  const auto [both_code, both_output] =
      with({"--paper", "--config", kSourceConfigDir + "/default.yaml"});
  EXPECT_EQ(both_code, 2) << both_output;
  EXPECT_NE(both_output.find("--paper"), std::string::npos) << both_output;
  EXPECT_NE(both_output.find("--config"), std::string::npos) << both_output;
}

// A bad config is refused with every error the loader finds, each naming its key.
TEST(VnsbaPlan, BadConfigNamesEveryKey) {
  const std::string config = write_temp_file("plan_bad_config.yaml",
                                             "planner:\n  name: dijkstra\n"
                                             "map:\n  robot_radius: -1\n");
  const auto [code, output] =
      run_plan({kRooms, "--start", "2.5", "2.5", "--goal", "29.5", "13.5", "--config", config});
  EXPECT_EQ(code, 2) << output;
  EXPECT_NE(output.find("planner.name"), std::string::npos) << output;
  EXPECT_NE(output.find("map.robot_radius"), std::string::npos) << output;
  const auto [missing_code, missing_output] =
      run_plan({kRooms, "--start", "2.5", "2.5", "--goal", "29.5", "13.5", "--config",
                unreachable_file("none.yaml")});
  EXPECT_EQ(missing_code, 2) << missing_output;
  EXPECT_NE(missing_output.find("none.yaml"), std::string::npos) << missing_output;
  std::remove(config.c_str());
}

const std::string kTinyMap = VNSBA_FIXTURE_DIR "/maps/tiny.map";
const std::string kTinyScen = VNSBA_FIXTURE_DIR "/maps/tiny.map.scen";

// The output line of a .scen line, by its line number in the file.
std::optional<std::string> scenario_line(const std::string& output, int line) {
  const std::string key = "line=" + std::to_string(line) + " ";
  std::istringstream in(output);
  for (std::string l; std::getline(in, l);)
    if (l.rfind(key, 0) == 0) return " " + l;
  return std::nullopt;
}

// The scenario lines of a .scen file as written: x y of start and goal, rows from the top.
std::vector<std::vector<std::string>> scen_fields(const std::string& path) {
  std::vector<std::vector<std::string>> rows;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);  // "version 1"
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::vector<std::string> row{std::istream_iterator<std::string>(fields), {}};
    if (row.size() == 9) rows.push_back(row);
  }
  return rows;
}

// --scen runs each line as written: with A* every grid path cost is the file's optimum (the
// oracle), the start and goal printed are the file's own numbers (rows from the top), and the
// summary counts them all. Without MAP, the map the .scen names beside it is used.
TEST(VnsbaPlan, ScenarioLinesAsWrittenMatchTheirOptima) {
  auto scenarios = maps::load_movingai_scenarios(kTinyScen);
  ASSERT_TRUE(scenarios) << scenarios.error().message;
  const auto fields = scen_fields(kTinyScen);
  ASSERT_EQ(fields.size(), scenarios->size());
  for (const bool with_map : {true, false}) {
    std::vector<std::string> args = {"--scen", kTinyScen, "--planner", "astar"};
    if (with_map) args.insert(args.begin(), kTinyMap);
    const auto [code, output] = run_plan(args);
    ASSERT_EQ(code, 0) << output;
    for (size_t i = 0; i < scenarios->size(); ++i) {
      const maps::MovingAiScenario& s = (*scenarios)[i];
      const auto line = scenario_line(output, s.line);
      ASSERT_TRUE(line) << "line " << s.line << ": " << output;
      EXPECT_NE(line->find(" astar OK "), std::string::npos) << *line;
      const double cost = std::stod(field(*line, "cost_cells").value_or("nan"));
      EXPECT_LE(std::abs(cost - s.optimal_length),
                std::max(1e-6 * s.optimal_length, s.optimal_resolution))
          << *line;
      EXPECT_EQ(field(*line, "optimum"), "matched") << *line;
      EXPECT_EQ(field(*line, "scen_start"), fields[i][4] + "," + fields[i][5]) << *line;
      EXPECT_EQ(field(*line, "scen_goal"), fields[i][6] + "," + fields[i][7]) << *line;
    }
    const std::string n = std::to_string(scenarios->size());
    const size_t summary = output.find("summary ");
    ASSERT_NE(summary, std::string::npos) << output;
    const std::string summary_line = output.substr(summary - 1);
    EXPECT_EQ(field(summary_line, "scenarios"), n);
    EXPECT_EQ(field(summary_line, "ok"), n);
    EXPECT_EQ(field(summary_line, "matched_optimum"), n);
  }
}

// A planner that is not exact on the Moving AI graph gets length ratios instead: each line's
// final length over the file's optimum, their mean and maximum in the summary.
TEST(VnsbaPlan, ScenarioSummaryOfOtherPlannersIsTheLengthRatio) {
  auto scenarios = maps::load_movingai_scenarios(kTinyScen);
  ASSERT_TRUE(scenarios);
  const auto [code, output] = run_plan({kTinyMap, "--scen", kTinyScen});
  ASSERT_EQ(code, 0) << output;
  double sum = 0.0, largest = 0.0;
  for (const maps::MovingAiScenario& s : *scenarios) {
    const auto line = scenario_line(output, s.line);
    ASSERT_TRUE(line) << output;
    EXPECT_EQ(field(*line, "optimum"), std::nullopt) << *line;
    const double ratio = std::stod(field(*line, "length_ratio").value_or("nan"));
    EXPECT_NEAR(ratio, std::stod(field(*line, "length_m").value_or("nan")) / s.optimal_length,
                1e-3);
    sum += ratio;
    largest = std::max(largest, ratio);
  }
  const std::string summary = output.substr(output.find("summary ") - 1);
  EXPECT_NEAR(std::stod(field(summary, "mean_length_ratio").value_or("nan")),
              sum / static_cast<double>(scenarios->size()), 1e-3);
  EXPECT_NEAR(std::stod(field(summary, "max_length_ratio").value_or("nan")), largest, 1e-4);
}

TEST(VnsbaPlan, ScenIndexRunsOneLine) {
  auto scenarios = maps::load_movingai_scenarios(kTinyScen);
  ASSERT_TRUE(scenarios);
  ASSERT_GE(scenarios->size(), 2u);
  const auto [code, output] =
      run_plan({kTinyMap, "--scen", kTinyScen, "--scen-index", "1", "--planner", "jps"});
  ASSERT_EQ(code, 0) << output;
  EXPECT_TRUE(scenario_line(output, (*scenarios)[1].line)) << output;
  EXPECT_FALSE(scenario_line(output, (*scenarios)[0].line)) << output;
  EXPECT_EQ(field(output.substr(output.find("summary ") - 1), "scenarios"), "1") << output;
}

TEST(VnsbaPlan, BadScenarioInputExitsTwoNamingTheOption) {
  struct Case {
    std::vector<std::string> args;
    const char* named;
  };
  for (const Case& c : {
           Case{{kTinyMap, "--scen", kTinyScen, "--scen-index", "99"}, "--scen-index"},
           Case{{kTinyMap, "--scen", kTinyScen, "--start", "1", "1"}, "--start"},
           Case{{kTinyMap, "--scen", kTinyScen, "--svg", temp_file("scen.svg")}, "--svg"},
           Case{{kTinyMap, "--scen", VNSBA_FIXTURE_DIR "/maps/none.scen"}, "none.scen"},
           Case{{kRooms, "--scen", kTinyScen}, "line"},  // the lines are for a 6 x 4 map
           Case{{kRooms, "--start", "2", "2", "--goal", "3", "3", "--scen-index", "0"},
                "--scen-index"},
       }) {
    const auto [code, output] = run_plan(c.args);
    EXPECT_EQ(code, 2) << output;
    EXPECT_NE(output.find(c.named), std::string::npos) << c.named << ": " << output;
  }
}

// --repeat N plans the query N times on one planner: the same plan each time (the line equals a
// single run's up to the times), with the first plan's time and the median of all N.
TEST(VnsbaPlan, RepeatReportsFirstAndMedianTimes) {
  const std::vector<std::string> query = {kRooms,   "--start", "2.5", "2.5",
                                          "--goal", "29.5",    "13.5"};
  const auto [single_code, single] = run_plan(query);
  ASSERT_EQ(single_code, 0) << single;
  std::vector<std::string> args = query;
  args.insert(args.end(), {"--repeat", "7"});
  const auto [code, output] = run_plan(args);
  ASSERT_EQ(code, 0) << output;
  EXPECT_EQ(without_times(output), without_times(single));
  EXPECT_EQ(field(output, "repeats"), "7") << output;
  const auto first = field(output, "first_time_us");
  const auto median = field(output, "median_time_us");
  ASSERT_TRUE(first && median) << output;
  EXPECT_GE(std::stoll(*first), 0);
  EXPECT_GE(std::stoll(*median), 0);
  EXPECT_EQ(field(output, "time_us"), first) << output;  // time_us stays the first plan's
  EXPECT_EQ(field(single, "repeats"), std::nullopt) << single;
  const auto [bad_code, bad] =
      run_plan({kRooms, "--start", "2.5", "2.5", "--goal", "29.5", "13.5", "--repeat", "0"});
  EXPECT_EQ(bad_code, 2) << bad;
  EXPECT_NE(bad.find("--repeat"), std::string::npos) << bad;
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// --json writes the run record the recorder writes: it reads back with run_record_from_json and
// records::render_record_file draws the same final path as the run's own --svg.
TEST(VnsbaPlan, JsonIsARunRecordThatRendersAsTheRun) {
  const std::string record_base = temp_file("record");
  const std::string json = record_base + ".json";
  const std::string svg = record_base + ".svg";
  const auto [code, output] = run_plan({kRooms, "--start", "2.5", "2.5", "--goal", "29.5", "13.5",
                                        "--robot-radius", "0.4", "--json", json, "--svg", svg});
  ASSERT_EQ(code, 0) << output;
  const auto parsed = nlohmann::json::parse(read_bytes(json), nullptr, false);
  ASSERT_FALSE(parsed.is_discarded());
  const auto record = records::run_record_from_json(parsed);
  ASSERT_TRUE(record) << record.error().message;
  ASSERT_TRUE(record->status && record->request && record->map && record->debug);
  EXPECT_EQ(record->status->code_name, "OK");
  EXPECT_EQ(record->status->code, 0);
  EXPECT_NEAR(record->status->metrics.length_m, std::stod(field(" " + output, "length_m").value()),
              5e-4);
  EXPECT_EQ(record->status->metrics.expanded, std::stoll(field(output, "expanded").value()));
  ASSERT_TRUE(record->request->start && record->request->goal);
  EXPECT_NEAR(record->request->start->x(), 2.5, 1e-9);
  EXPECT_NEAR(record->request->goal->y(), 13.5, 1e-9);
  EXPECT_EQ(record->map->width, 32);
  EXPECT_EQ(record->map->height, 16);
  EXPECT_DOUBLE_EQ(record->map->robot_radius, 0.4);
  ASSERT_GE(record->path.size(), 2u);
  EXPECT_NEAR(record->path.front().x(), 2.5, 1e-6);
  EXPECT_NEAR(record->path.back().y(), 13.5, 1e-6);
  // The options that shaped the path, as vnsba_plan ran them (vns_bastar's paper configuration:
  // pruned and smoothed, no costs), so the record's picture names them too.
  ASSERT_TRUE(record->options);
  EXPECT_EQ(record->options->prune, std::optional<bool>(true));
  EXPECT_EQ(record->options->smooth, std::optional<bool>(true));
  EXPECT_EQ(record->options->cost_weight, std::optional<double>(0.0));

  const auto rendered = records::render_record_file(json);
  ASSERT_TRUE(rendered) << rendered.error().message;
  tinyxml2::XMLDocument from_record, from_run;
  ASSERT_EQ(from_record.Parse(rendered->c_str()), tinyxml2::XML_SUCCESS);
  ASSERT_EQ(from_run.LoadFile(svg.c_str()), tinyxml2::XML_SUCCESS);
  const auto record_path = decode_polylines(find_id(from_record.RootElement(), "final-path"), 16);
  const auto run_path = decode_polylines(find_id(from_run.RootElement(), "final-path"), 16);
  ASSERT_EQ(record_path.size(), 1u);
  ASSERT_EQ(run_path.size(), 1u);
  ASSERT_EQ(record_path[0].size(), run_path[0].size());
  for (size_t i = 0; i < run_path[0].size(); ++i)
    EXPECT_LT((record_path[0][i] - run_path[0][i]).norm(), 1e-3) << i;
  EXPECT_EQ(data_count(find_id(from_record.RootElement(), "expanded-forward")),
            data_count(find_id(from_run.RootElement(), "expanded-forward")));
  for (const std::string& f : {json, svg, record_base + "_map.yaml", record_base + "_map.pgm"})
    std::remove(f.c_str());
}

// --png writes a PNG (signature, then IHDR) of the size the SVG of the same run declares; an
// unwritable file is exit 2 naming it.
TEST(VnsbaPlan, PngIsThePictureAtTheSvgsSize) {
  const std::string picture_base = temp_file("picture");
  const std::string png = picture_base + ".png";
  const std::string svg = picture_base + ".svg";
  const auto [code, output] = run_plan(
      {kRooms, "--start", "2.5", "2.5", "--goal", "29.5", "13.5", "--png", png, "--svg", svg});
  ASSERT_EQ(code, 0) << output;
  const std::string bytes = read_bytes(png);
  ASSERT_GE(bytes.size(), 24u);
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_EQ(bytes.substr(12, 4), "IHDR");
  tinyxml2::XMLDocument doc;
  ASSERT_EQ(doc.LoadFile(svg.c_str()), tinyxml2::XML_SUCCESS);
  EXPECT_EQ(big_endian(bytes, 16),
            static_cast<uint32_t>(std::ceil(doc.RootElement()->DoubleAttribute("width"))));
  EXPECT_EQ(big_endian(bytes, 20),
            static_cast<uint32_t>(std::ceil(doc.RootElement()->DoubleAttribute("height"))));
  std::remove(png.c_str());
  std::remove(svg.c_str());

  for (const char* option : {"--png", "--json"}) {
    // The message names the file or, for --json, the map beside it: the stem is in both.
    const std::string stem = unreachable_file("picture");
    const std::string bad = stem + (std::string(option) == "--png" ? ".png" : ".json");
    const auto [bad_code, bad_output] =
        run_plan({kRooms, "--start", "2.5", "2.5", "--goal", "29.5", "13.5", option, bad});
    EXPECT_EQ(bad_code, 2) << bad_output;
    EXPECT_NE(bad_output.find(stem), std::string::npos) << bad_output;
    EXPECT_NE(bad_output.find(option), std::string::npos) << bad_output;
  }
}

}  // namespace
}  // namespace vnsba::test
