// vnsba_slicer as a process: files to map_server maps, files and trees on the bus to slices the
// node plans on, every map file vnsba_plan reads published over loopback DDS, and clear errors
// for bad files and options.
#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "bus_client.hpp"
#include "child_process.hpp"
#include "octomap_msgs/msg/OctomapPubSubTypes.h"
#include "temp_dir.hpp"
#include "vnsba/maps/map_file.hpp"
#include "vnsba/maps/map_io.hpp"
#include "vnsba/maps/octomap_slice.hpp"
#include "vnsba/node/planner_node.hpp"

namespace vnsba::test {
namespace {

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

// `tree` as `name` in a fresh directory of its own.
std::string write_tree(const octomap::OcTree& tree, const std::string& name) {
  const std::string path = (FreshTempDir("tree") / name).string();
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
  const std::string out = (FreshTempDir("slicer_out") / "room.pgm").string();
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
  // A tree that cannot exist and an --out no case may write, in an empty directory of their own.
  const std::filesystem::path dir = FreshTempDir("slicer_errors");
  const std::string missing = (dir / "no/such/tree.bt").string();
  const std::string x = (dir / "x.pgm").string();
  const std::vector<Case> cases = {
      {{missing, "--out", x, "--config", def}, missing},
      {{text, "--out", x, "--config", def}, "not_a_tree.bt"},
      {{bt, "--z-min", "1.0", "--z-max", "0.5", "--out", x, "--config", def}, "--z-min <= --z-max"},
      {{bt, "--z-min", "5", "--z-max", "6", "--out", x, "--config", def}, "height range"},
      {{bt, "--resolution", "0.15", "--out", x, "--config", def}, "resolution"},
      {{bt, "--z-min", "0.2", "--z-max", "0.8", "--out", x, "--config", small_limit}, "max_cells"},
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
  const std::string out = (FreshTempDir("slicer_out") / "names.pgm").string();
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
  EXPECT_TRUE(room_tree(/*extra=*/true)->writeBinary(bt));  // the watched file itself
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

// --- Every map file vnsba_plan reads, published ------------------------------------------------
// Each test writes a small map cell by cell, runs the slicer with --publish (and --out), takes
// the OccupancyGrid off the bus with a reader of its own and compares it with what the test wrote:
// the oracle is the file's cells and the documented meaning of each value, not a previous run.

// What the published map must be: row 0 at the bottom, as in the world.
struct ExpectedMap {
  int width = 0, height = 0;
  double resolution = 0.0, origin_x = 0.0, origin_y = 0.0;
  std::vector<int> values;  // width * height, row-major from the bottom row

  int at(int x, int y) const { return values[static_cast<size_t>(y * width + x)]; }
};

// The expected map of `rows` (top row first, as files and pictures read) through `value`.
template <class Cell, class Value>
ExpectedMap expected_from_rows(const std::vector<std::vector<Cell>>& rows, double resolution,
                               double origin_x, double origin_y, Value value) {
  ExpectedMap e;
  e.height = static_cast<int>(rows.size());
  e.width = static_cast<int>(rows.front().size());
  e.resolution = resolution;
  e.origin_x = origin_x;
  e.origin_y = origin_y;
  for (int y = 0; y < e.height; ++y)
    for (const Cell& cell : rows[static_cast<size_t>(e.height - 1 - y)])
      e.values.push_back(value(cell));
  return e;
}

std::vector<std::vector<char>> char_rows(const std::vector<std::string>& text) {
  std::vector<std::vector<char>> rows;
  for (const std::string& line : text) rows.emplace_back(line.begin(), line.end());
  return rows;
}

// `name` in a fresh directory of its own (not made: what the slicer writes there).
std::string temp_path(const std::string& name) {
  return (FreshTempDir("slicer") / name).string();
}

void expect_cells(const std::vector<int>& got, const ExpectedMap& e, const std::string& what) {
  ASSERT_EQ(got.size(), e.values.size()) << what;
  int wrong = 0;
  for (int y = 0; y < e.height; ++y)
    for (int x = 0; x < e.width; ++x)
      if (got[static_cast<size_t>(y * e.width + x)] != e.at(x, y) && ++wrong <= 10)
        ADD_FAILURE() << what << ": cell (" << x << ", " << y << ") is "
                      << got[static_cast<size_t>(y * e.width + x)] << ", expected " << e.at(x, y);
  EXPECT_EQ(wrong, 0) << what << ": cells that differ";
}

// A reader of this process for the maps published on `cfg`'s slice topic (transient local, as
// the node reads them).
class MapReader {
 public:
  explicit MapReader(const node::NodeConfig& cfg)
      : participant_(node::Participant::create(cfg.domain_id, "slicer_format_test").value()) {
    auto topic = participant_->topic<nav_msgs::msg::dds_::OccupancyGrid_PubSubType>(
        node::dds_topic_name(cfg, cfg.topics.projected_map));
    EXPECT_TRUE(topic &&
                participant_->reader(*topic, node::reader_qos(node::TopicQos::kLatched), &heard_));
  }
  ~MapReader() { participant_->shutdown(); }
  // Waits until `count` maps were heard.
  bool wait_for(size_t count) {
    return heard_.wait([count](const auto& all) { return all.size() >= count; }, 15s);
  }
  std::vector<node::OccupancyGridMsg> heard() { return heard_.snapshot(); }

 private:
  std::unique_ptr<node::Participant> participant_;
  Collector<node::OccupancyGridMsg> heard_;
};

void expect_map_msg(const node::OccupancyGridMsg& msg, const ExpectedMap& e,
                    const std::string& frame, const std::string& what) {
  EXPECT_EQ(msg.header().frame_id(), frame);
  EXPECT_EQ(msg.info().width(), static_cast<uint32_t>(e.width));
  EXPECT_EQ(msg.info().height(), static_cast<uint32_t>(e.height));
  EXPECT_FLOAT_EQ(msg.info().resolution(), static_cast<float>(e.resolution));
  EXPECT_NEAR(msg.info().origin().position().x(), e.origin_x, 1e-9);
  EXPECT_NEAR(msg.info().origin().position().y(), e.origin_y, 1e-9);
  EXPECT_EQ(msg.info().origin().orientation().w(), 1.0);
  expect_cells(std::vector<int>(msg.data().begin(), msg.data().end()), e, what);
}

// Runs `vnsba_slicer FILE --publish --out OUT [args]` on a domain and topics of its own, takes the
// map it publishes with a reader of this process, checks it against `published`, stops the slicer
// (SIGINT, exit 0) and checks the map_server file --out wrote against `written` and that the
// slicer's log says `said`.
void check_published(const std::string& tag, const std::string& file,
                     const std::vector<std::string>& args, const ExpectedMap& published,
                     const ExpectedMap& written, const std::string& extra_config = "",
                     const std::string& said = "") {
  const node::NodeConfig cfg = test_config(tag);
  const std::string config = write_temp_file(tag + ".yaml", config_yaml(cfg) + extra_config);
  MapReader reader(cfg);
  const std::string out = temp_path(tag + "_out.pgm");
  std::vector<std::string> all = {file, "--publish", "--out", out, "--config", config};
  all.insert(all.end(), args.begin(), args.end());
  ChildProcess slicer(kSlicer, all);
  ASSERT_TRUE(reader.wait_for(1)) << slicer.output();
  EXPECT_TRUE(slicer.running()) << "the slicer stopped serving the map\n" << slicer.output();
  slicer.signal(SIGINT);
  EXPECT_EQ(slicer.wait(), 0) << slicer.output();
  EXPECT_NE(slicer.output().find(said), std::string::npos) << said << " not in:\n"
                                                           << slicer.output();
  expect_map_msg(reader.heard().front(), published, cfg.frame_id, "published by " + file);

  auto saved = maps::load_map_server(out.substr(0, out.size() - 4) + ".yaml");
  ASSERT_TRUE(saved) << saved.error().message;
  EXPECT_EQ(saved->width, written.width);
  EXPECT_EQ(saved->height, written.height);
  EXPECT_NEAR(saved->resolution, written.resolution, 1e-9);
  EXPECT_NEAR(saved->origin_x, written.origin_x, 1e-9);
  EXPECT_NEAR(saved->origin_y, written.origin_y, 1e-9);
  expect_cells(std::vector<int>(saved->data.begin(), saved->data.end()), written,
               "written by --out for " + file);
}

// An OctoMap drawn in characters, one column of 0.25 m voxels per cell: '#' occupied in the band
// (z in [0.25, 0.5)), '.' free in the band, '^' free in the band under an occupied voxel above it
// (z in [1.25, 1.5)), '_' occupied below the band only (z in [-0.25, 0)), '?' no voxel at all.
// The grid's origin is (-0.5, 1.0); every border row and column has a voxel, so the tree's extent
// is the drawing's. Sliced at 0.3..0.9 m the cells are '#' occupied, '.' and '^' free, '_' and '?'
// unknown.
const std::vector<std::string> kTreeDrawing = {
    "#.?^_#",
    "..#...",
    "?#..?.",
    "#._.##",
};
constexpr double kTreeLeaf = 0.25, kTreeOriginX = -0.5, kTreeOriginY = 1.0;

std::shared_ptr<octomap::OcTree> drawn_tree() {
  auto tree = std::make_shared<octomap::OcTree>(kTreeLeaf);
  const int height = static_cast<int>(kTreeDrawing.size());
  for (int row = 0; row < height; ++row) {
    for (size_t col = 0; col < kTreeDrawing[static_cast<size_t>(row)].size(); ++col) {
      const double x = kTreeOriginX + (static_cast<double>(col) + 0.5) * kTreeLeaf;
      const double y = kTreeOriginY + (height - 1 - row + 0.5) * kTreeLeaf;
      const auto at = [&](double z) { return octomap::point3d(x, y, z); };
      switch (kTreeDrawing[static_cast<size_t>(row)][col]) {
        case '#':
          tree->updateNode(at(0.375), true);
          break;
        case '.':
          tree->updateNode(at(0.375), false);
          break;
        case '^':
          tree->updateNode(at(0.375), false);
          tree->updateNode(at(1.375), true);
          break;
        case '_':
          tree->updateNode(at(-0.125), true);
          break;
        default:
          break;
      }
    }
  }
  return tree;
}

ExpectedMap drawn_tree_slice() {
  return expected_from_rows(char_rows(kTreeDrawing), kTreeLeaf, kTreeOriginX, kTreeOriginY,
                            [](char c) {
                              return c == '#' ? 100 : (c == '.' || c == '^') ? 0 : -1;
                            });
}

TEST(SlicerFormats, BinaryOctoMapIsSlicedAndPublished) {
  const std::string bt = temp_path("drawn.bt");
  ASSERT_TRUE(drawn_tree()->writeBinary(bt));
  check_published("fmt_bt", bt, {"--z-min", "0.3", "--z-max", "0.9"}, drawn_tree_slice(),
                  drawn_tree_slice());
}

TEST(SlicerFormats, FullOctoMapIsSlicedAndPublished) {
  const std::string ot = temp_path("drawn.ot");
  ASSERT_TRUE(drawn_tree()->write(ot));
  check_published("fmt_ot", ot, {"--z-min", "0.3", "--z-max", "0.9"}, drawn_tree_slice(),
                  drawn_tree_slice());
}

// A Moving AI map has no resolution of its own: 1 m cells, origin (0, 0), as vnsba_plan reads it.
// '.', 'G', 'S' are passable (0), '@', 'O', 'T', 'W' not (100); the file's top line is the top row.
// Issue 18: --namespace puts the slice where a node in that namespace reads it.
TEST(SlicerBus, NamespaceReachesTheNodeOfThatNamespaceOnly) {
  node::NodeConfig cfg = test_config("slicer_ns");
  const std::string config = write_temp_file("slicer_ns.yaml", config_yaml(cfg));
  cfg.ros_namespace = "robot3";  // the node's; the slicer gets it from --namespace
  node::PlannerNode planner_node(cfg);
  ASSERT_TRUE(planner_node.start().is_ok());
  const std::string map =
      write_temp_file("slicer_ns.map", "type octile\nheight 2\nwidth 3\nmap\n...\n.@.\n");
  {
    ChildProcess other(kSlicer, {map, "--publish", "--config", config, "--namespace", "robot4"});
    EXPECT_FALSE(planner_node.wait_for_map(2s)) << "robot4's map reached robot3's node";
    other.signal(SIGTERM);
    EXPECT_EQ(other.wait(), 0) << other.output();
  }
  ChildProcess slicer(kSlicer, {map, "--publish", "--config", config, "--namespace", "/robot3"});
  EXPECT_TRUE(planner_node.wait_for_map(15s)) << slicer.output();
  slicer.signal(SIGTERM);
  EXPECT_EQ(slicer.wait(), 0) << slicer.output();
}

// Issue 18: with discovery.servers every executable is a Discovery Server client: the node, the
// slicer (a process) and a client find each other through fastdds-tools' server, and not
// without it.
TEST(DiscoveryServer, NodeSlicerAndClientFindEachOtherThroughTheServerOnly) {
  const std::string server_binary = VNSBA_DISCOVERY_SERVER;
  if (server_binary.empty())
    GTEST_SKIP()
        << "fast-discovery-server not found (fastdds-tools; tools/bootstrap.sh installs it)";
  const std::string port = std::to_string(20000 + getpid() % 20000);
  node::NodeConfig cfg = test_config("discovery_server");
  cfg.discovery_servers = {"127.0.0.1:" + port};
  const std::string config =
      write_temp_file("discovery_server.yaml",
                      config_yaml(cfg) + "discovery:\n  servers: [\"127.0.0.1:" + port + "\"]\n");
  node::PlannerNode planner_node(cfg);
  ASSERT_TRUE(planner_node.start().is_ok());
  BusClient client(cfg);
  EXPECT_FALSE(client.wait_for_node(2s)) << "matched with no server running";
  node::NodeConfig simple = cfg;
  simple.discovery_servers.clear();
  BusClient outsider(simple);

  ChildProcess server(server_binary, {"-i", "0", "-l", "127.0.0.1", "-p", port});
  ASSERT_TRUE(client.wait_for_node(15s)) << server.output();
  const std::string map =
      write_temp_file("discovery_server.map", "type octile\nheight 2\nwidth 3\nmap\n...\n...\n");
  ChildProcess slicer(kSlicer, {map, "--publish", "--config", config});
  ASSERT_TRUE(planner_node.wait_for_map(15s)) << slicer.output();
  client.publish_request("through-server", 0.5, 0.5, 2.5, 1.5);
  const auto status = client.wait_status("through-server");
  ASSERT_TRUE(status);
  EXPECT_EQ(node::code_name(status->code()), "OK") << status->message();
  // A participant with simple discovery (multicast) never meets the servers' clients.
  EXPECT_FALSE(outsider.wait_for_node(1s));
  slicer.signal(SIGTERM);
  EXPECT_EQ(slicer.wait(), 0) << slicer.output();
}

TEST(SlicerFormats, MovingAiMapIsPublishedAsItIs) {
  const std::vector<std::string> rows = {
      "@@@@@@@",
      "@..T..O",
      "@.G@S.@",
      "@W..@@@",
  };
  std::string text = "type octile\nheight " + std::to_string(rows.size()) + "\nwidth " +
                     std::to_string(rows.front().size()) + "\nmap\n";
  for (const std::string& row : rows) text += row + "\n";
  const std::string file = write_temp_file("formats.map", text);
  const ExpectedMap expected = expected_from_rows(char_rows(rows), 1.0, 0.0, 0.0, [](char c) {
    return std::string(".GS").find(c) != std::string::npos ? 0 : 100;
  });
  check_published("fmt_movingai", file, {}, expected, expected);
}

// A P5 image of `grey` (top row first, maxval 255) at `path`.
void write_pgm(const std::string& path, const std::vector<std::vector<int>>& grey) {
  std::string pgm =
      "P5\n" + std::to_string(grey.front().size()) + " " + std::to_string(grey.size()) + "\n255\n";
  for (const auto& row : grey)
    for (int v : row) pgm.push_back(static_cast<char>(v));
  std::ofstream(path, std::ios::binary) << pgm;
}

// A map_server map as map_saver and a user write one: an image and its YAML, which names it
// relative to its folder. Returns the YAML's path.
std::string write_map_server(const std::string& name, const std::vector<std::vector<int>>& grey,
                             const std::string& yaml_keys) {
  const std::filesystem::path dir = FreshTempDir("map_server");
  write_pgm((dir / (name + ".pgm")).string(), grey);
  const std::string yaml = (dir / (name + ".yaml")).string();
  std::ofstream(yaml) << "image: " << name + ".pgm\n" << yaml_keys;
  return yaml;
}

// Greys from black to white (top row first), across both thresholds of the YAML below.
const std::vector<std::vector<int>> kGreys = {
    {0, 254, 205, 255, 100, 30, 150},
    {254, 254, 0, 205, 180, 220, 120},
    {0, 0, 254, 254, 60, 240, 170},
};
constexpr double kOccupiedThresh = 0.65, kFreeThresh = 0.196;
const std::string kMapServerKeys =
    "resolution: 0.05\norigin: [-1.5, 2.25, 0.0]\nnegate: 0\noccupied_thresh: 0.65\n"
    "free_thresh: 0.196\n";

// map_server's reading of a grey sample: p = (255 - v) / 255, occupied (100) above
// occupied_thresh, free (0) below free_thresh; between them unknown (-1) in trinary mode and
// 100 * (p - free_thresh) / (occupied_thresh - free_thresh) rounded in scale mode (Nav2's).
int map_server_value(int grey, bool scale) {
  const double p = (255.0 - grey) / 255.0;
  EXPECT_GT(std::abs(p - kOccupiedThresh), 1e-9) << grey << " is on a threshold: pick another";
  EXPECT_GT(std::abs(p - kFreeThresh), 1e-9) << grey << " is on a threshold: pick another";
  if (p > kOccupiedThresh) return 100;
  if (p < kFreeThresh) return 0;
  if (!scale) return -1;
  const double value = 100.0 * (p - kFreeThresh) / (kOccupiedThresh - kFreeThresh);
  EXPECT_GT(std::abs(value - std::floor(value) - 0.5), 1e-6) << grey << " rounds either way";
  return static_cast<int>(std::lround(value));
}

// map_saver's trinary file of a published value, read back: occupied at or above the threshold,
// free at 0..25, unknown otherwise.
int map_saver_value(int value, int occupied_threshold) {
  if (value >= occupied_threshold) return 100;
  return value >= 0 && value <= 25 ? 0 : -1;
}

TEST(SlicerFormats, TrinaryMapServerMapIsPublishedAsItIs) {
  const std::string yaml = write_map_server("trinary", kGreys, kMapServerKeys + "mode: trinary\n");
  const ExpectedMap expected = expected_from_rows(
      kGreys, 0.05, -1.5, 2.25, [](int grey) { return map_server_value(grey, false); });
  check_published("fmt_trinary", yaml, {}, expected, expected);

  // The image given instead of its YAML reads the YAML beside it.
  const std::string pgm = yaml.substr(0, yaml.size() - 5) + ".pgm";
  const std::string out = temp_path("trinary_from_pgm_out.pgm");
  const auto [code, output] =
      run_to_exit(kSlicer, {pgm, "--out", out, "--config", VNSBA_CONFIG_DIR "/default.yaml"});
  ASSERT_EQ(code, 0) << output;
  auto saved = maps::load_map_server(out.substr(0, out.size() - 4) + ".yaml");
  ASSERT_TRUE(saved) << saved.error().message;
  expect_cells(std::vector<int>(saved->data.begin(), saved->data.end()), expected,
               "written by --out for " + pgm);
}

// Scale mode publishes map_server's graded values as they are (the node reads 1..threshold-1 as
// free cells with a cost); --out writes them as map_saver would save that map (trinary), which
// turns the graded cells between its free and occupied ranges unknown, and says so.
TEST(SlicerFormats, ScaleMapServerMapIsPublishedWithItsGradedValues) {
  const std::string yaml = write_map_server("scale", kGreys, kMapServerKeys + "mode: scale\n");
  const ExpectedMap expected = expected_from_rows(
      kGreys, 0.05, -1.5, 2.25, [](int grey) { return map_server_value(grey, true); });
  int graded = 0;
  for (int v : expected.values) graded += v > 0 && v < 100;
  ASSERT_GE(graded, 4) << "the greys must give graded values";
  constexpr int kThreshold = 70;
  ExpectedMap written = expected;
  int turned_unknown = 0;
  for (size_t i = 0; i < expected.values.size(); ++i) {
    written.values[i] = map_saver_value(expected.values[i], kThreshold);
    turned_unknown += expected.values[i] >= 0 && written.values[i] < 0;
  }
  ASSERT_GE(turned_unknown, 1) << "some graded value must lie between map_saver's ranges";
  check_published(
      "fmt_scale", yaml, {}, expected, written,
      "map:\n  occupied_threshold: " + std::to_string(kThreshold) + "\n",
      ": " + std::to_string(turned_unknown) + " cells with graded values are written as unknown");
}

// --watch follows a map_server map's image too: a new .pgm beside the YAML is published again.
TEST(SlicerFormats, WatchedMapServerMapIsRepublishedWhenItsImageChanges) {
  const std::string yaml = write_map_server("watched", kGreys, kMapServerKeys);
  const node::NodeConfig cfg = test_config("fmt_watch");
  const std::string config = write_temp_file("fmt_watch.yaml", config_yaml(cfg));
  MapReader reader(cfg);
  ChildProcess slicer(kSlicer, {yaml, "--publish", "--watch", "--config", config});
  ASSERT_TRUE(reader.wait_for(1)) << slicer.output();
  std::vector<std::vector<int>> inverted = kGreys;
  for (auto& row : inverted)
    for (int& v : row) v = 255 - v;
  std::this_thread::sleep_for(1100ms);  // file times have coarse resolution on some filesystems
  write_pgm(yaml.substr(0, yaml.size() - 5) + ".pgm", inverted);
  ASSERT_TRUE(reader.wait_for(2)) << slicer.output();
  slicer.signal(SIGTERM);
  EXPECT_EQ(slicer.wait(), 0) << slicer.output();
  const auto heard = reader.heard();
  expect_map_msg(heard.front(),
                 expected_from_rows(kGreys, 0.05, -1.5, 2.25,
                                    [](int grey) { return map_server_value(grey, false); }),
                 cfg.frame_id, "first map");
  expect_map_msg(heard.back(),
                 expected_from_rows(inverted, 0.05, -1.5, 2.25,
                                    [](int grey) { return map_server_value(grey, false); }),
                 cfg.frame_id, "the map after the image changed");
}

// A 2D map is published as it is: every slicing option given with one is refused, named, before
// anything is read or published.
TEST(SlicerProcess, SliceOptionsWithA2DMapAreRefusedByName) {
  const std::string movingai =
      write_temp_file("refuse.map", "type octile\nheight 1\nwidth 2\nmap\n.@\n");
  const std::string yaml = write_map_server("refuse", {{0, 254}}, kMapServerKeys);
  const std::string pgm = yaml.substr(0, yaml.size() - 5) + ".pgm";
  const std::vector<std::vector<std::string>> options = {
      {"--z-min", "0.2"},      {"--z-max", "1.0"},    {"--resolution", "0.1"},
      {"--bounds", "0,0,1,1"}, {"--remove-speckles"},
  };
  for (const std::string& file : {movingai, yaml, pgm}) {
    for (const auto& option : options) {
      std::vector<std::string> args = {file, "--publish", "--config",
                                       VNSBA_CONFIG_DIR "/default.yaml"};
      args.insert(args.end(), option.begin(), option.end());
      const auto [code, output] = run_to_exit(kSlicer, args);
      EXPECT_EQ(code, 2) << option[0] << " with " << file << "\n" << output;
      const std::string words = option[0] + ": only for OctoMap files (.bt, .ot), not " + file;
      EXPECT_NE(output.find(words), std::string::npos) << words << " not in:\n" << output;
      EXPECT_EQ(output.find("published the map"), std::string::npos) << output;
    }
  }
}

// A malformed 2D map is an error naming the file and the field, never a crash; so is a map over
// the node's map.max_cells, and an --out that would overwrite the map being read.
TEST(SlicerProcess, Bad2DMapsNameTheFileAndTheField) {
  const std::string def = VNSBA_CONFIG_DIR "/default.yaml";
  const std::string bad_char =
      write_temp_file("bad_char.map", "type octile\nheight 2\nwidth 2\nmap\n..\n.x\n");
  const std::string bad_height =
      write_temp_file("bad_height.map", "type octile\nheight two\nwidth 2\nmap\n..\n..\n");
  const std::string short_rows =
      write_temp_file("short_rows.map", "type octile\nheight 3\nwidth 2\nmap\n..\n");
  const std::string nan_resolution =
      write_map_server("nan_resolution", {{0, 254}}, "resolution: .nan\norigin: [0.0, 0.0, 0.0]\n");
  const std::string no_resolution =
      write_map_server("no_resolution", {{0, 254}}, "origin: [0.0, 0.0, 0.0]\n");
  const std::string no_image = write_temp_file(
      "no_image.yaml", "image: missing.pgm\nresolution: 0.1\norigin: [0.0, 0.0, 0.0]\n");
  const std::string truncated = write_map_server("truncated", {{0, 254}, {254, 0}}, kMapServerKeys);
  {
    const std::string image = truncated.substr(0, truncated.size() - 5) + ".pgm";
    std::ofstream(image, std::ios::binary) << "P5\n2 2\n255\n\x01";
  }
  const std::string big =
      write_temp_file("big.map", "type octile\nheight 2\nwidth 3\nmap\n...\n...\n");
  const std::string small_limit = write_temp_file("small_2d.yaml", "map:\n  max_cells: 5\n");
  const std::string yaml = write_map_server("own_out", {{0, 254}}, kMapServerKeys);
  const std::string own_pgm = yaml.substr(0, yaml.size() - 5) + ".pgm";
  struct Case {
    std::vector<std::string> args;
    std::vector<std::string> words;
  };
  const std::vector<Case> cases = {
      {{bad_char, "--publish", "--config", def}, {bad_char, "'x'"}},
      {{bad_height, "--publish", "--config", def}, {bad_height, "height"}},
      {{short_rows, "--out", temp_path("x.pgm"), "--config", def}, {short_rows, "rows"}},
      {{nan_resolution, "--publish", "--config", def}, {nan_resolution, "resolution"}},
      {{no_resolution, "--publish", "--config", def}, {no_resolution, "resolution"}},
      {{no_image, "--publish", "--config", def}, {"missing.pgm"}},
      {{truncated, "--publish", "--config", def}, {"truncated.pgm", "truncated"}},
      {{big, "--publish", "--config", small_limit},
       {big, "3 x 2 = 6 cells", "map.max_cells in " + small_limit + " (5 cells)"}},
      {{yaml, "--out", own_pgm, "--config", def}, {"--out " + own_pgm, "would overwrite"}},
  };
  for (const Case& c : cases) {
    const auto [code, output] = run_to_exit(kSlicer, c.args);
    EXPECT_EQ(code, 2) << c.args[0] << "\n" << output;
    for (const std::string& w : c.words)
      EXPECT_NE(output.find(w), std::string::npos) << w << " not in:\n" << output;
  }
  // The refused --out left the map as it was.
  auto still = maps::load_map_file(yaml);
  ASSERT_TRUE(still) << still.error().message;
  EXPECT_EQ(std::vector<int>(still->data.begin(), still->data.end()), (std::vector<int>{100, 0}));
}

}  // namespace
}  // namespace vnsba::test
