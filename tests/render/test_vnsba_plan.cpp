// vnsba_plan as a process: a plan and its picture from a map file, and exit codes with messages
// naming the option for bad input.
#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <fstream>

#include "node/child_process.hpp"
#include "svg_test_support.hpp"

namespace vnsba::test {
namespace {

const std::string kPlan = VNSBA_PLAN_BINARY;
const std::string kRooms = VNSBA_FIXTURE_DIR "/maps/rooms_32.map";

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
       }) {
    const auto [code, output] = run_to_exit(kPlan, c.args);
    EXPECT_EQ(code, 2) << output;
    EXPECT_NE(output.find(c.named), std::string::npos) << c.named << ": " << output;
  }
}

}  // namespace
}  // namespace vnsba::test
