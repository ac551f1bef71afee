// vnsba_slicer as a process: files to map_server maps, files and trees on the bus to slices the
// node plans on, and clear errors for bad files and options.
#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "bus_client.hpp"
#include "child_process.hpp"
#include "octomap_msgs/msg/OctomapPubSubTypes.h"
#include "vnsba/maps/map_io.hpp"
#include "vnsba/maps/octomap_slice.hpp"
#include "vnsba/node/planner_node.hpp"

namespace vnsba::test {
namespace {

const std::string kSlicer = VNSBA_SLICER_BINARY;

// A 6 m x 4 m room at 0.1 m: free air from z = 0.05 to 1.0 m, a wall at x = 3 m with a door at
// y in [3, 3.5) m, and a pillar. `extra` adds a second wall so a changed file slices differently.
std::shared_ptr<octomap::OcTree> room_tree(bool extra = false) {
  auto tree = std::make_shared<octomap::OcTree>(0.1);
  for (double x = 0.05; x < 6.0; x += 0.1) {
    for (double y = 0.05; y < 4.0; y += 0.1) {
      for (double z = 0.05; z < 1.0; z += 0.1) {
        const bool wall = std::abs(x - 3.05) < 0.01 && !(y > 3.0 && y < 3.5);
        const bool pillar = x > 1.0 && x < 1.4 && y > 1.0 && y < 1.4;
        const bool second = extra && std::abs(y - 2.05) < 0.01 && x < 2.5;
        tree->updateNode(octomap::point3d(x, y, z), wall || pillar || second);
      }
    }
  }
  return tree;
}

std::string write_tree(const octomap::OcTree& tree, const std::string& name) {
  const std::string path = ::testing::TempDir() + "/" + std::to_string(getpid()) + "_" + name;
  EXPECT_TRUE(const_cast<octomap::OcTree&>(tree).writeBinary(path));
  return path;
}

maps::SliceOptions band(double z_min, double z_max) {
  maps::SliceOptions o;
  o.z_min = z_min;
  o.z_max = z_max;
  return o;
}

TEST(SlicerProcess, FileToMapServerMapEqualsTheCoreSlice) {
  const auto tree = room_tree();
  const std::string bt = write_tree(*tree, "room.bt");
  const std::string out = ::testing::TempDir() + "/" + std::to_string(getpid()) + "_room.pgm";
  const auto [code, output] =
      run_to_exit(kSlicer, {bt, "--z-min", "0.2", "--z-max", "0.8", "--out", out, "--config",
                            VNSBA_CONFIG_DIR "/default.yaml"});
  ASSERT_EQ(code, 0) << output;
  auto loaded = maps::load_map_server(out.substr(0, out.size() - 4) + ".yaml");
  ASSERT_TRUE(loaded) << loaded.error().message;
  auto expected = maps::slice_octree(*tree, band(0.2, 0.8));
  ASSERT_TRUE(expected) << expected.error().message;
  EXPECT_EQ(loaded->width, expected->width);
  EXPECT_EQ(loaded->height, expected->height);
  EXPECT_NEAR(loaded->origin_x, expected->origin_x, 1e-9);
  EXPECT_NEAR(loaded->resolution, expected->resolution, 1e-9);
  EXPECT_EQ(loaded->data, expected->data);
}

TEST(SlicerProcess, BadFilesAndOptionsGiveClearErrors) {
  const std::string bt = write_tree(*room_tree(), "room_errors.bt");
  const std::string text = write_temp_file("not_a_tree.bt", "this is not an octree\n");
  const std::string small_limit = write_temp_file("small.yaml", "map:\n  max_cells: 100\n");
  struct Case {
    std::vector<std::string> args;
    std::string words;
  };
  const std::string def = VNSBA_CONFIG_DIR "/default.yaml";
  const std::vector<Case> cases = {
      {{"no/such/tree.bt", "--out", "x.pgm", "--config", def}, "no/such/tree.bt"},
      {{text, "--out", "x.pgm", "--config", def}, "not_a_tree.bt"},
      {{bt, "--z-min", "1.0", "--z-max", "0.5", "--out", "x.pgm", "--config", def},
       "--z-min <= --z-max"},
      {{bt, "--z-min", "5", "--z-max", "6", "--out", "x.pgm", "--config", def}, "height range"},
      {{bt, "--resolution", "0.15", "--out", "x.pgm", "--config", def}, "resolution"},
      {{bt, "--z-min", "0.2", "--z-max", "0.8", "--out", "x.pgm", "--config", small_limit},
       "max_cells"},
      {{bt, "--config", def}, "nothing to do"},
  };
  for (const Case& c : cases) {
    const auto [code, output] = run_to_exit(kSlicer, c.args);
    EXPECT_EQ(code, 2) << c.words << "\n" << output;
    EXPECT_NE(output.find(c.words), std::string::npos) << c.words << " not in:\n" << output;
  }
}

// Errors name where the value came from: the config key (slicer.resolution, map.max_cells, in
// metres and cells, with the file) or the flag; a slice too large names the tree's file and what
// makes it fit. --bounds takes x_min,y_min,x_max,y_max as one word or as four.
TEST(SlicerProcess, ErrorsNameTheFlagOrTheConfigKeyAndBoundsTakeCommas) {
  const std::string bt = write_tree(*room_tree(), "room_names.bt");
  const std::string coarse = write_temp_file("coarse.yaml", "slicer:\n  resolution: 0.15\n");
  const std::string small_limit = write_temp_file("small_names.yaml", "map:\n  max_cells: 100\n");
  const std::string out = ::testing::TempDir() + "/" + std::to_string(getpid()) + "_names.pgm";
  struct Case {
    std::vector<std::string> args;
    std::vector<std::string> words;
  };
  const std::vector<Case> cases = {
      {{bt, "--out", out, "--config", coarse},
       {bt + ": ", "slicer.resolution in " + coarse + " is 0.15 m, not a whole multiple",
        "leaf size 0.1 m"}},
      {{bt, "--resolution", "0.15", "--out", out, "--config", coarse}, {"--resolution is 0.15 m"}},
      {{bt, "--out", out, "--config", small_limit},
       {bt + ": the slice would have ", "map.max_cells in " + small_limit + " (100 cells)",
        "--bounds x_min,y_min,x_max,y_max (metres)", "slicer.resolution in " + small_limit,
        "the tree's extent ["}},
      {{bt, "--bounds", "2,0,1,1", "--out", out, "--config", small_limit},
       {"--bounds = 2,0,1,1 m is empty"}},
  };
  for (const Case& c : cases) {
    const auto [code, output] = run_to_exit(kSlicer, c.args);
    EXPECT_EQ(code, 2) << output;
    for (const std::string& w : c.words)
      EXPECT_NE(output.find(w), std::string::npos) << w << " not in:\n" << output;
  }
  // The same area, given either way, gives the same slice; it fits the small limit.
  std::vector<std::string> grids;
  for (const std::vector<std::string>& bounds :
       {std::vector<std::string>{"--bounds", "0,0,0.9,0.9"},
        std::vector<std::string>{"--bounds", "0", "0", "0.9", "0.9"}}) {
    std::vector<std::string> args = {bt, "--out", out, "--config", small_limit};
    args.insert(args.end(), bounds.begin(), bounds.end());
    const auto [code, output] = run_to_exit(kSlicer, args);
    ASSERT_EQ(code, 0) << output;
    auto loaded = maps::load_map_server(out.substr(0, out.size() - 4) + ".yaml");
    ASSERT_TRUE(loaded) << loaded.error().message;
    EXPECT_EQ(loaded->width, 9);
    EXPECT_EQ(loaded->height, 9);
    grids.emplace_back(loaded->data.begin(), loaded->data.end());
  }
  EXPECT_EQ(grids[0], grids[1]);
}

TEST(SlicerBus, FileToSlicerToNodeToPlan) {
  const node::NodeConfig cfg = test_config("slicer_file");
  const std::string config = write_temp_file("slicer_file.yaml", config_yaml(cfg));
  const std::string bt = write_tree(*room_tree(), "room_bus.bt");
  ChildProcess slicer(kSlicer, {bt, "--publish", "--watch", "--z-min", "0.2", "--z-max", "0.8",
                                "--config", config});
  node::PlannerNode planner_node(cfg);
  ASSERT_TRUE(planner_node.start().is_ok());
  ASSERT_TRUE(planner_node.wait_for_map(15s)) << slicer.output();
  BusClient client(cfg);
  ASSERT_TRUE(client.wait_for_node());
  // From the west side of the wall to the east side, through the door.
  client.publish_request("through-door", 1.0, 0.5, 5.0, 0.5);
  const auto status = client.wait_status("through-door");
  ASSERT_TRUE(status);
  ASSERT_EQ(node::code_name(status->code()), "OK") << status->message();
  bool went_through_door = false;
  for (const auto& pose : status->path().poses()) {
    const double x = pose.pose().position().x(), y = pose.pose().position().y();
    if (std::abs(x - 3.05) < 0.1) went_through_door |= y > 2.9 && y < 3.6;
  }
  EXPECT_TRUE(went_through_door) << "the path crossed the wall somewhere other than the door";

  // --watch: a changed file is sliced again and the node takes the new map.
  std::this_thread::sleep_for(1100ms);  // file times have coarse resolution on some filesystems
  write_tree(*room_tree(/*extra=*/true), "room_bus.bt");
  const auto end = std::chrono::steady_clock::now() + 15s;
  while (planner_node.stats().maps_accepted < 2 && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(50ms);
  EXPECT_GE(planner_node.stats().maps_accepted, 2u) << slicer.output();
  slicer.signal(SIGTERM);
  EXPECT_EQ(slicer.wait(), 0) << slicer.output();
}

TEST(SlicerBus, TreeOnTheBusBecomesASlice) {
  const node::NodeConfig cfg = test_config("slicer_tree");
  const std::string config = write_temp_file(
      "slicer_tree.yaml", config_yaml(cfg) + "slicer:\n  z_min: 0.2\n  z_max: 0.8\n");
  ChildProcess slicer(kSlicer, {"--subscribe", "--config", config});
  ASSERT_TRUE(slicer.wait_for_output("slicing the octomaps", 10s)) << slicer.output();

  auto participant = node::Participant::create(cfg.domain_id, "slicer_test").value();
  Collector<node::OccupancyGridMsg> slices;
  auto slice_topic = participant->topic<nav_msgs::msg::dds_::OccupancyGrid_PubSubType>(
      node::dds_topic_name(cfg, cfg.topics.projected_map));
  ASSERT_TRUE(
      participant->reader(*slice_topic, node::reader_qos(node::TopicQos::kLatched), &slices));
  auto tree_topic = participant->topic<octomap_msgs::msg::dds_::Octomap_PubSubType>(
      node::dds_topic_name(cfg, cfg.topics.octomap));
  auto writer = participant->writer(*tree_topic, node::writer_qos(node::TopicQos::kLatched, true));
  ASSERT_TRUE(writer);
  const auto tree = room_tree();
  node::OctomapMsg msg = node::to_octomap_msg(*tree, "map", node::now_msg());
  (*writer)->write(&msg);
  ASSERT_TRUE(slices.wait([](const auto& all) { return !all.empty(); }, 15s)) << slicer.output();
  const auto expected = maps::slice_octree(*tree, band(0.2, 0.8));
  ASSERT_TRUE(expected);
  auto received =
      node::from_slice_msg(std::move(slices.snapshot().front()), "map", int64_t{1} << 24);
  ASSERT_TRUE(received.status.ok()) << received.status.message;
  EXPECT_EQ(received.grid.width, expected->width);
  EXPECT_EQ(received.grid.height, expected->height);
  EXPECT_EQ(received.grid.data, expected->data);

  // A broken tree is refused with a message, and the slicer keeps running.
  node::OctomapMsg broken = msg;
  broken.data().resize(broken.data().size() / 3);
  (*writer)->write(&broken);
  EXPECT_TRUE(slicer.wait_for_output("octomap rejected", 10s)) << slicer.output();
  EXPECT_TRUE(slicer.running());
  participant->shutdown();
  slicer.signal(SIGINT);
  EXPECT_EQ(slicer.wait(), 0) << slicer.output();
}

}  // namespace
}  // namespace vnsba::test
