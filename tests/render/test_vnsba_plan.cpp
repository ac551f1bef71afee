// vnsba_plan as a process: a plan and its picture from a map file, and exit codes with messages
// naming the option for bad input.
#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>

#include "node/child_process.hpp"
#include "svg_test_support.hpp"
#include "vnsba/core/map_io.hpp"
#include "vnsba/core/octomap_slice.hpp"
#include "vnsba/core/planner.hpp"

namespace vnsba::test {
namespace {

const std::string kPlan = VNSBA_PLAN_BINARY;
const std::string kRooms = VNSBA_FIXTURE_DIR "/maps/rooms_32.map";

// The line vnsba_plan prints for what core plans with these settings (up to the time).
std::string printed_line(const std::shared_ptr<const core::GridMap>& map,
                         const core::PlanQuery& query, core::PlannerKind kind,
                         const core::PlannerSettings& settings) {
  const core::PlanResult r = core::plan_once(map, query, core::make_options(kind, settings));
  char line[160];
  std::snprintf(line, sizeof line, "%s %s length_m=%.3f turns=%d turn_angle_deg=%.1f expanded=%lld",
                std::string(core::to_string(kind)).c_str(),
                std::string(core::to_string(r.status.code)).c_str(), r.metrics.length_m,
                r.metrics.turns, r.metrics.turn_angle_deg,
                static_cast<long long>(r.metrics.expanded));
  return line;
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
      core::GridMap::build(core::load_movingai_map(kRooms).value()).value());
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

  core::SliceOptions area;  // vnsba_plan's default band
  area.bounds = core::SliceBounds{-10, -10, 10, 10};
  const auto tree = core::load_octree(bt);
  ASSERT_TRUE(tree) << tree.error().message;
  const auto slice = core::slice_octree(**tree, area);
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

}  // namespace
}  // namespace vnsba::test
