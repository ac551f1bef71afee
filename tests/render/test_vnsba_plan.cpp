// vnsba_plan as a process: a plan and its picture from a map file, and exit codes with messages
// naming the option for bad input.
#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>

#include "node/child_process.hpp"
#include "svg_test_support.hpp"
#include "vnsba/core/path_poses.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/maps/map_io.hpp"
#include "vnsba/maps/octomap_slice.hpp"

namespace vnsba::test {
namespace {

const std::string kPlan = VNSBA_PLAN_BINARY;
const std::string kRooms = VNSBA_FIXTURE_DIR "/maps/rooms_32.map";

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

std::string temp_file(const std::string& name) {
  return ::testing::TempDir() + "/plan_" + name + "_" + std::to_string(getpid());
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
  const std::string svg = ::testing::TempDir() + "/plan_" + std::to_string(getpid()) + ".svg";
  // Metres on a Moving AI map are cells (1 m cells, origin 0, rows counted from the bottom).
  const auto [code, output] =
      run_to_exit(kPlan, {kRooms, "--start", "2.5", "2.5", "--goal", "29.5", "13.5", "--svg", svg});
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
  const auto [code, output] = run_to_exit(
      kPlan, {kRooms, "--cells", "--start", "2", "2", "--goal", "29", "13", "--planner", "astar"});
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
    const auto [code, output] = run_to_exit(kPlan, args);
    ASSERT_EQ(code, 0) << output;
    EXPECT_NE(output.find(expected), std::string::npos) << "expected: " << expected << "\n"
                                                        << output;
  }
}

TEST(VnsbaPlan, ReadsMapServerAndOctoMapFiles) {
  // map_server: a 8-bit P5 image with its YAML (the whole map is checked by the map_io tests).
  const auto [code, output] =
      run_to_exit(kPlan, {VNSBA_FIXTURE_DIR "/map_server/p5_8bit.yaml", "--cells", "--start", "0",
                          "0", "--goal", "0", "0", "--planner", "astar"});
  EXPECT_TRUE(code == 0 || code == 1) << output;  // a plan ran: OK or a planner status
  EXPECT_NE(output.find("astar "), std::string::npos) << output;

  const std::string bt = VNSBA_DATA_DIR "/octomap/geb079.bt";
  if (!std::ifstream(bt)) GTEST_SKIP() << bt << " is absent (third-party data beside the project)";
  const std::string svg = ::testing::TempDir() + "/plan_bt_" + std::to_string(getpid()) + ".svg";
  // A band at hip height, both ends in the building's long corridor would need the map: just
  // require the slice to load and a planner answer with a picture of the map.
  const auto [bt_code, bt_output] =
      run_to_exit(kPlan, {bt, "--z-min", "0.3", "--z-max", "1.2", "--start", "0", "0", "--goal",
                          "1", "1", "--svg", svg});
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
  const auto [whole_code, whole] =
      run_to_exit(kPlan, {bt, "--start", "0", "0", "--goal", "1", "1"});
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
    const auto [code, output] = run_to_exit(kPlan, args);
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
    const auto [code, output] = run_to_exit(kPlan, args);
    EXPECT_EQ(code, 2) << output;
    EXPECT_NE(output.find(c.named), std::string::npos) << c.named << ": " << output;
  }
}

TEST(VnsbaPlan, PlannerFailuresExitOneWithTheStatus) {
  const auto [code, output] =
      run_to_exit(kPlan, {kRooms, "--cells", "--start", "2", "2", "--goal", "0", "0"});
  EXPECT_EQ(code, 1) << output;
  EXPECT_NE(output.find("GOAL_OCCUPIED"), std::string::npos) << output;
}

TEST(VnsbaPlan, BadInputExitsTwoNamingTheOption) {
  struct Case {
    std::vector<std::string> args;
    const char* named;
  };
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
           Case{
               {kRooms, "--start", "2", "2", "--goal", "3", "3", "--svg", "/nonexistent-dir/x.svg"},
               "--svg"},
           Case{{kRooms, "--start", "2", "2", "--goal", "3", "3", "--neighborhood", "4"},
                "--neighborhood"},
           Case{{kRooms, "--start", "2", "2", "--goal", "3", "3", "--corner-policy", "sometimes"},
                "--corner-policy"},
           Case{{kRooms, "--start", "2", "2", "--goal", "3", "3", "--omega", "-1"}, "--omega"},
           Case{{kRooms, "--start", "2", "2", "--goal", "3", "3", "--omega", "0", "--eta", "0"},
                "omega and eta"},
       }) {
    const auto [code, output] = run_to_exit(kPlan, c.args);
    EXPECT_EQ(code, 2) << output;
    EXPECT_NE(output.find(c.named), std::string::npos) << c.named << ": " << output;
  }
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
    const auto [code, output] = run_to_exit(kPlan, args);
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
  const auto [code, output] = run_to_exit(
      kPlan, {kRooms, "--cells", "--start", "2", "2", "--goal", "29", "13", "--inflation-radius",
              "4", "--cost-scaling-factor", "0.5", "--cost-weight", "20"});
  ASSERT_EQ(code, 0) << output;
  EXPECT_NE(output.find(expected), std::string::npos) << "expected: " << expected << "\n" << output;
}

// clearance_m comes right after length_m: positive metres on a map with walls, inf without any.
TEST(VnsbaPlan, PrintsTheClearance) {
  const auto [code, output] =
      run_to_exit(kPlan, {kRooms, "--start", "2.5", "2.5", "--goal", "29.5", "13.5"});
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
      run_to_exit(kPlan, {open, "--cells", "--start", "0", "0", "--goal", "5", "3"});
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
    const auto [code, output] = run_to_exit(kPlan, args);
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
  const auto [code, output] = run_to_exit(
      kPlan, {kRooms, "--cells", "--start", "2", "2", "--goal", "0", "0", "--poses", poses_file});
  EXPECT_EQ(code, 1) << output;
  EXPECT_TRUE(read_poses(poses_file).empty());
  std::remove(poses_file.c_str());
}

// A goal inside a wall (x = 15 is the rooms map's middle wall): refused naming the layer without
// tolerance, moved to the nearest free cell centre with it, measured from the requested point.
TEST(VnsbaPlan, GoalToleranceMovesABlockedGoalToTheNearestFreeCell) {
  const std::vector<std::string> args = {kRooms, "--start", "2.5", "2.5", "--goal", "15.3", "2.5"};
  const auto [blocked_code, blocked] = run_to_exit(kPlan, args);
  EXPECT_EQ(blocked_code, 1) << blocked;
  EXPECT_NE(blocked.find("GOAL_OCCUPIED"), std::string::npos) << blocked;
  EXPECT_NE(blocked.find("occupied cell"), std::string::npos) << blocked;  // the layer
  EXPECT_EQ(field(blocked, "clearance_m"), std::optional<std::string>("nan")) << blocked;

  std::vector<std::string> tolerant = args;
  const std::string poses_file = temp_file("tolerant_poses");
  for (const char* a : {"--goal-tolerance", "1", "--poses", poses_file.c_str()})
    tolerant.push_back(a);
  const auto [code, output] = run_to_exit(kPlan, tolerant);
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
  const auto [short_code, short_output] = run_to_exit(kPlan, short_reach);
  EXPECT_EQ(short_code, 1) << short_output;
  EXPECT_NE(short_output.find("occupied cell"), std::string::npos) << short_output;
  EXPECT_NE(short_output.find("goal_tolerance"), std::string::npos) << short_output;
}

// A goal outside the map is refused by the tool without tolerance and planned to the nearest
// free cell with it (core resolves it from the cell containing the requested point).
TEST(VnsbaPlan, GoalToleranceBringsAGoalOutsideTheMapIn) {
  // Column 31 is the border wall; (30.5, 5.5) is the nearest free centre to (33, 5.5): 2.5 m.
  const std::vector<std::string> args = {kRooms, "--start", "2.5", "2.5", "--goal", "33", "5.5"};
  const auto [outside_code, outside] = run_to_exit(kPlan, args);
  EXPECT_EQ(outside_code, 2) << outside;
  EXPECT_NE(outside.find("--goal is outside the map"), std::string::npos) << outside;
  EXPECT_NE(outside.find("--goal-tolerance"), std::string::npos) << outside;

  std::vector<std::string> tolerant = args;
  tolerant.push_back("--goal-tolerance");
  tolerant.push_back("3");
  const auto [code, output] = run_to_exit(kPlan, tolerant);
  ASSERT_EQ(code, 0) << output;
  EXPECT_EQ(field(output, "goal_moved_m"), std::optional<std::string>("2.500")) << output;

  tolerant.back() = "1";
  const auto [far_code, far] = run_to_exit(kPlan, tolerant);
  EXPECT_EQ(far_code, 1) << far;
  EXPECT_NE(far.find("GOAL_OUTSIDE_MAP"), std::string::npos) << far;
}

// --start-tolerance moves a start blocked by inflation only (--robot-radius) to a free cell.
TEST(VnsbaPlan, StartToleranceMovesAStartOutOfInflation) {
  // (1.5, 1.5) is 1 m from the walls' cell centres: inflated by a 1 m robot radius.
  // The goal stays in the same room: a 1 m radius closes the rooms map's doors.
  const std::vector<std::string> args = {kRooms, "--start",        "1.5", "1.5", "--goal", "12.5",
                                         "2.5",  "--robot-radius", "1"};
  const auto [blocked_code, blocked] = run_to_exit(kPlan, args);
  EXPECT_EQ(blocked_code, 1) << blocked;
  EXPECT_NE(blocked.find("START_OCCUPIED"), std::string::npos) << blocked;
  EXPECT_NE(blocked.find("inflation"), std::string::npos) << blocked;

  std::vector<std::string> tolerant = args;
  tolerant.push_back("--start-tolerance");
  tolerant.push_back("2");
  const auto [code, output] = run_to_exit(kPlan, tolerant);
  ASSERT_EQ(code, 0) << output;
  const auto moved = field(output, "start_moved_m");
  ASSERT_TRUE(moved) << output;
  EXPECT_GT(std::stod(*moved), 0.0);
  EXPECT_LE(std::stod(*moved), 2.0);
  EXPECT_EQ(output.find(" goal_moved_m="), std::string::npos) << output;
}

}  // namespace
}  // namespace vnsba::test
