// vnsba_recorder as a process next to a real node over loopback DDS: one picture and one record
// per request, geometry equal to what the node published, a clean SIGINT that writes what it
// heard, and bad data for one run that does not stop the others.
#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include "bus_client.hpp"
#include "child_process.hpp"
#include "render/svg_test_support.hpp"
#include "vnsba/maps/map_io.hpp"
#include "vnsba/node/planner_node.hpp"
#include "vnsba/records/run_record.hpp"

namespace vnsba::test {
namespace {

namespace fs = std::filesystem;
const std::string kRecorder = VNSBA_RECORDER_BINARY;

fs::path fresh_dir(const std::string& tag) {
  const fs::path dir =
      fs::path(::testing::TempDir()) / ("recorder_" + std::to_string(getpid()) + "_" + tag);
  fs::remove_all(dir);
  return dir;
}

// The rooms fixture at 0.5 m per cell with its origin at (-3, 2) m (so metres and cells differ),
// plus a free cell walled in on all sides: cell (29, 2) is unreachable.
core::OccupancyGrid rooms_slice() {
  core::OccupancyGrid grid =
      maps::load_movingai_map(VNSBA_FIXTURE_DIR "/maps/rooms_32.map").value();
  grid.resolution = 0.5;
  grid.origin_x = -3.0;
  grid.origin_y = 2.0;
  for (int y = 1; y <= 3; ++y)
    for (int x = 28; x <= 30; ++x) grid.data[y * grid.width + x] = (x == 29 && y == 2) ? 0 : 100;
  return grid;
}

// World centre of a cell of rooms_slice().
std::pair<double, double> centre(int x, int y) {
  return {-3.0 + (x + 0.5) * 0.5, 2.0 + (y + 0.5) * 0.5};
}

nlohmann::json read_json(const fs::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in, nullptr, false);
}

TEST(RecorderProcess, WritesOnePictureAndOneRecordPerRequest) {
  const node::NodeConfig cfg = test_config("rec");
  node::PlannerNode planner_node(cfg);
  ASSERT_TRUE(planner_node.start().is_ok());
  BusClient client(cfg);
  ASSERT_TRUE(client.wait_for_node());
  const core::OccupancyGrid grid = rooms_slice();
  client.publish_slice(grid);
  ASSERT_TRUE(planner_node.wait_for_map(std::chrono::seconds(10)));

  const fs::path out = fresh_dir("five");
  const std::string config = write_temp_file("rec.yaml", config_yaml(cfg));
  ChildProcess recorder(kRecorder, {"--out", out.string(), "--config", config, "--runs", "5"});
  ASSERT_TRUE(recorder.wait_for_output("planner_debug matched", 15s)) << recorder.output();
  ASSERT_TRUE(recorder.wait_for_output("plan_status matched", 15s)) << recorder.output();
  ASSERT_TRUE(recorder.wait_for_output("plan_request matched", 15s)) << recorder.output();
  ASSERT_TRUE(recorder.wait_for_output("goal_pose matched", 15s)) << recorder.output();
  // The node's writers learn of the recorder's readers at about the same time; a short margin
  // keeps the debug of the first request from racing that discovery.
  std::this_thread::sleep_for(500ms);

  const auto [sx, sy] = centre(2, 2);
  const auto [gx, gy] = centre(29, 13);
  const auto [wx, wy] = centre(0, 0);   // the outer wall
  const auto [px, py] = centre(29, 2);  // the walled-in cell
  client.publish_request("ok-1", sx, sy, gx, gy);
  ASSERT_TRUE(client.wait_status("ok-1"));
  client.publish_request("into-wall", sx, sy, wx, wy);
  ASSERT_TRUE(client.wait_status("into-wall"));
  client.publish_request("walled-in", sx, sy, px, py, "astar");
  ASSERT_TRUE(client.wait_status("walled-in"));
  client.publish_request("bad pose/1", NAN, sy, gx, gy);
  ASSERT_TRUE(client.wait_status("bad pose/1"));
  client.publish_robot_pose(sx, sy);
  std::this_thread::sleep_for(200ms);  // robot_pose is keep-last: let it land before the goal
  client.publish_goal(gx, gy);
  ASSERT_TRUE(client.wait_status("goal-1"));

  ASSERT_EQ(recorder.wait(), 0) << recorder.output();
  const std::map<std::string, std::string> expected = {{"ok-1", "OK"},
                                                       {"into-wall", "GOAL_OCCUPIED"},
                                                       {"walled-in", "NO_VALID_PATH"},
                                                       {"bad pose/1", "INVALID_REQUEST"},
                                                       {"goal-1", "OK"}};
  size_t svgs = 0, records = 0;
  for (const auto& entry : fs::directory_iterator(out)) {
    svgs += entry.path().extension() == ".svg";
    records += entry.path().extension() == ".json";
  }
  EXPECT_EQ(svgs, expected.size());
  EXPECT_EQ(records, expected.size());

  const auto statuses = client.statuses.snapshot();
  const auto debugs = client.debug.snapshot();
  for (const auto& [id, code_name] : expected) {
    const std::string stem = records::safe_file_stem(id);
    SCOPED_TRACE(id);
    auto record = records::run_record_from_json(read_json(out / (stem + ".json")));
    ASSERT_TRUE(record) << record.error().message;
    EXPECT_EQ(record->request_id, id);
    ASSERT_TRUE(record->status);
    EXPECT_EQ(record->status->code_name, code_name);
    ASSERT_TRUE(record->request);
    EXPECT_EQ(record->request->source, id == "goal-1" ? "goal_pose" : "plan_request");
    ASSERT_TRUE(record->map);
    auto map = maps::load_map_server((out / record->map->file).string());
    ASSERT_TRUE(map) << map.error().message;
    EXPECT_EQ(map->width, grid.width);
    EXPECT_EQ(map->height, grid.height);
    EXPECT_EQ(map->data, grid.data);

    tinyxml2::XMLDocument doc;
    ASSERT_EQ(doc.LoadFile((out / (stem + ".svg")).c_str()), tinyxml2::XML_SUCCESS);
    const auto* root = doc.RootElement();
    EXPECT_EQ(decode_runs(find_id(root, "map-occupied"), grid.height).size(),
              static_cast<size_t>(std::count(grid.data.begin(), grid.data.end(), 100)));

    // The record's path and metrics are the node's.
    const PlanStatusMsg* status = nullptr;
    for (const auto& s : statuses)
      if (s.request_id() == id) status = &s;
    ASSERT_NE(status, nullptr);
    EXPECT_EQ(record->status->metrics.expanded, status->expanded());
    EXPECT_EQ(record->status->metrics.turns, status->turns());
    ASSERT_EQ(record->path.size(), status->path().poses().size());
    for (size_t i = 0; i < record->path.size(); ++i) {
      EXPECT_DOUBLE_EQ(record->path[i].x(), status->path().poses()[i].pose().position().x());
      EXPECT_DOUBLE_EQ(record->path[i].y(), status->path().poses()[i].pose().position().y());
    }
    EXPECT_EQ(data_count(find_id(root, "final-path")), static_cast<long>(record->path.size()));
    if (code_name == "OK") {
      ASSERT_FALSE(record->path.empty());
      // Picture coordinates are cells: the path's first point is the start cell's centre.
      const auto drawn = decode_polylines(find_id(root, "final-path"), grid.height);
      ASSERT_EQ(drawn.size(), 1u);
      EXPECT_NEAR(drawn[0].front().x(), 2.5, 1e-3);
      EXPECT_NEAR(drawn[0].front().y(), 2.5, 1e-3);
    }
    // Expansions drawn = the cells of the debug message the node published for this id.
    const PlannerDebugMsg* debug = nullptr;
    for (const auto& d : debugs)
      if (d.request_id() == id) debug = &d;
    if (debug != nullptr) {
      ASSERT_TRUE(record->debug) << "the recorder missed the debug data the client got";
      std::set<std::pair<int, int>> forward;
      for (const auto& c : debug->expanded_forward()) forward.insert({c.x(), c.y()});
      EXPECT_EQ(decode_runs(find_id(root, "expanded-forward"), grid.height), forward);
      EXPECT_EQ(data_count(find_id(root, "expanded-backward")),
                static_cast<long>(std::set<std::pair<int, int>>([&] {
                                    std::set<std::pair<int, int>> b;
                                    for (const auto& c : debug->expanded_backward())
                                      b.insert({c.x(), c.y()});
                                    return b;
                                  }())
                                      .size()));
    } else {
      EXPECT_TRUE(code_name != "OK" && code_name != "NO_VALID_PATH")
          << "the node publishes debug data for every search that ran";
    }
  }
  // goal_pose goals: the recorder pairs them with the robot pose as the start.
  auto goal_record = records::run_record_from_json(read_json(out / "goal-1.json"));
  ASSERT_TRUE(goal_record && goal_record->request && goal_record->request->goal);
  EXPECT_NEAR(goal_record->request->goal->x(), gx, 1e-9);
  ASSERT_TRUE(goal_record->request->start);
  EXPECT_NEAR(goal_record->request->start->x(), sx, 1e-9);

  // `render` redraws a record into the same picture.
  const fs::path redrawn = out / "redrawn.svg.out";
  const auto [code, output] =
      run_to_exit(kRecorder, {"render", (out / "ok-1.json").string(), "--out", redrawn.string()});
  ASSERT_EQ(code, 0) << output;
  std::ifstream a(out / "ok-1.svg"), b(redrawn);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(a), {}),
            std::string(std::istreambuf_iterator<char>(b), {}));
  fs::remove_all(out);
}

// SIGINT: the recorder stops reading and writes every run it heard of, even without a status.
TEST(RecorderProcess, SigintWritesWhatItHeard) {
  const node::NodeConfig cfg = test_config("recint");
  const fs::path out = fresh_dir("sigint");
  const std::string config = write_temp_file("recint.yaml", config_yaml(cfg));
  ChildProcess recorder(kRecorder, {"--out", out.string(), "--config", config});
  BusClient client(cfg);  // no node on these topics: requests get no status
  ASSERT_TRUE(recorder.wait_for_output("plan_request matched", 15s)) << recorder.output();
  std::this_thread::sleep_for(300ms);
  client.publish_request("unanswered", 1.0, 1.0, 2.0, 2.0);
  // Nothing is written while the run waits for its status...
  std::this_thread::sleep_for(1s);
  EXPECT_FALSE(fs::exists(out / "unanswered.json"));
  recorder.signal(SIGINT);
  ASSERT_EQ(recorder.wait(), 0) << recorder.output();
  auto record = records::run_record_from_json(read_json(out / "unanswered.json"));
  ASSERT_TRUE(record) << record.error().message;
  EXPECT_FALSE(record->status);
  ASSERT_TRUE(record->request && record->request->goal);
  EXPECT_DOUBLE_EQ(record->request->goal->y(), 2.0);
  tinyxml2::XMLDocument doc;
  ASSERT_EQ(doc.LoadFile((out / "unanswered.svg").c_str()), tinyxml2::XML_SUCCESS);
  EXPECT_EQ(data_count(find_id(doc.RootElement(), "start")), 1);
  fs::remove_all(out);
}

// A run with nonsense on the wire (absurd debug geometry, cells far outside, NaN path points)
// is still recorded, and the run after it too.
TEST(RecorderProcess, BadDataInOneRunDoesNotStopTheOthers) {
  const node::NodeConfig cfg = test_config("recbad");
  const fs::path out = fresh_dir("bad");
  const std::string config = write_temp_file("recbad.yaml", config_yaml(cfg));
  ChildProcess recorder(
      kRecorder, {"--out", out.string(), "--config", config, "--runs", "2", "--debug-wait", "0.2"});
  auto bus = node::Participant::create(cfg.domain_id, "fake_node").value();
  auto status_writer = bus->writer(bus->topic<vnsba_msgs::msg::dds_::PlanStatus_PubSubType>(
                                          node::dds_topic_name(cfg, cfg.topics.plan_status))
                                       .value(),
                                   node::writer_qos(node::TopicQos::kStatus, false))
                           .value();
  auto debug_writer = bus->writer(bus->topic<vnsba_msgs::msg::dds_::PlannerDebug_PubSubType>(
                                         node::dds_topic_name(cfg, cfg.topics.planner_debug))
                                      .value(),
                                  node::writer_qos(node::TopicQos::kDebug, false))
                          .value();
  ASSERT_TRUE(recorder.wait_for_output("planner_debug matched", 15s)) << recorder.output();
  ASSERT_TRUE(recorder.wait_for_output("plan_status matched", 15s)) << recorder.output();
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (node::matched_readers(debug_writer) == 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(10ms);

  PlannerDebugMsg junk_debug;
  junk_debug.request_id("junk");
  junk_debug.info().width(4000000000u);
  junk_debug.info().height(3);
  junk_debug.info().resolution(std::nanf(""));
  vnsba_msgs::msg::dds_::GridCell_ far;
  far.x(INT32_MIN);
  far.y(INT32_MAX);
  junk_debug.expanded_forward({far, far});
  junk_debug.raw_path({far});
  junk_debug.has_meeting_cell(true);
  junk_debug.meeting_cell(far);
  ASSERT_TRUE(debug_writer->write(&junk_debug));
  PathMsg bad_path;
  bad_path.poses().resize(3);
  bad_path.poses()[1].pose().position().x(NAN);
  bad_path.poses()[2].pose().position().x(1e300);
  const node::RequestIdentity request;  // the recorder keys runs by request_id
  PlanStatusMsg junk = node::to_status_msg("junk", &request, {node::wire::OK, ""}, "vns_bastar",
                                           nullptr, node::now_msg(), bad_path);
  ASSERT_TRUE(status_writer->write(&junk));
  PlanStatusMsg fine = node::to_status_msg("fine", &request, {node::wire::NO_VALID_PATH, "no path"},
                                           "astar", nullptr, node::now_msg(), PathMsg());
  ASSERT_TRUE(status_writer->write(&fine));

  ASSERT_EQ(recorder.wait(), 0) << recorder.output();
  for (const char* id : {"junk", "fine"}) {
    auto record = records::run_record_from_json(read_json(out / (std::string(id) + ".json")));
    ASSERT_TRUE(record) << id << ": " << record.error().message;
    tinyxml2::XMLDocument doc;
    EXPECT_EQ(doc.LoadFile((out / (std::string(id) + ".svg")).c_str()), tinyxml2::XML_SUCCESS)
        << id;
  }
  // What cannot be drawn is said, naming the field.
  EXPECT_NE(recorder.output().find("run 'junk': debug: "), std::string::npos) << recorder.output();
  bus->shutdown();
  fs::remove_all(out);
}

// `render` refuses a record whose geometry cannot be drawn: exit 2, the file and the JSON field
// named, no picture written. Bad memory limits are refused the same way (no DDS is started).
TEST(RecorderRender, RefusesARecordItCannotDrawAndWritesNoPicture) {
  const fs::path dir = fresh_dir("render_bad");
  fs::create_directories(dir);
  records::RunRecord r;
  r.request_id = "bad";
  records::MapReference map;
  map.width = 4;
  map.height = 2;
  for (const double resolution : {-0.5, std::nan("")}) {
    map.resolution = resolution;
    r.map = map;
    const fs::path json = dir / "bad.json", svg = dir / "bad.svg";
    std::ofstream(json) << records::to_json(r).dump(1);
    const auto [code, output] =
        run_to_exit(kRecorder, {"render", json.string(), "--out", svg.string()});
    EXPECT_EQ(code, 2) << output;
    // NaN is written as null, and said to be null (issue 31: "got nan").
    const std::string said = std::isnan(resolution) ? ": map.resolution is null"
                                                    : ": map: resolution must be finite and > 0";
    EXPECT_NE(output.find(json.string() + said), std::string::npos) << output;
    EXPECT_FALSE(fs::exists(svg)) << resolution;
  }
  for (const char* bad : {"0", "-1", "nan"}) {
    const auto [code, output] =
        run_to_exit(kRecorder, {"--out", dir.string(), "--max-open-mb", bad, "--duration", "1"});
    EXPECT_EQ(code, 2) << output;
    EXPECT_NE(output.find("--max-open-mb"), std::string::npos) << output;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace vnsba::test
