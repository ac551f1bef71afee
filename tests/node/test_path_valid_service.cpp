// is_path_valid over loopback, with real participants: a node serving nav2_msgs/srv/IsPathValid
// of Jazzy (Humble's is the same) or Kilted, and a ServiceClient in either mapping whose types
// are registered under the ROS 2 names written out here (so a node that named them otherwise
// would not match). Oracle: the test's own map, each pose's cell looked up by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "bus_client.hpp"
#include "nav2_msgs/srv/IsPathValidPubSubTypes.h"
#include "nav2_msgs_kilted/srv/IsPathValidPubSubTypes.h"
#include "vnsba/node/planner_node.hpp"
#include "vnsba/node/service_client.hpp"

namespace vnsba::test {
namespace {

using node::RosDistro;
using node::WireMapping;

// Each type under the ROS 2 name rmw gives it, written out (Kilted's come from the module
// nav2_msgs_kilted, whose generated name differs).
struct ValidRequestType : nav2_msgs::srv::dds_::IsPathValid_Request_PubSubType {
  ValidRequestType() { setName("nav2_msgs::srv::dds_::IsPathValid_Request_"); }
};
struct ValidResponseType : nav2_msgs::srv::dds_::IsPathValid_Response_PubSubType {
  ValidResponseType() { setName("nav2_msgs::srv::dds_::IsPathValid_Response_"); }
};
struct KiltedValidRequestType : nav2_msgs_kilted::srv::dds_::IsPathValid_Request_PubSubType {
  KiltedValidRequestType() { setName("nav2_msgs::srv::dds_::IsPathValid_Request_"); }
};
struct KiltedValidResponseType : nav2_msgs_kilted::srv::dds_::IsPathValid_Response_PubSubType {
  KiltedValidResponseType() { setName("nav2_msgs::srv::dds_::IsPathValid_Response_"); }
};

// 20 x 10 cells of 0.1 m at the origin: a wall at x = 10 (all rows but 4..5), unknown cells at
// (15..16, 7..8).
core::OccupancyGrid walled_map() {
  core::OccupancyGrid g;
  g.width = 20;
  g.height = 10;
  g.resolution = 0.1;
  g.data.assign(200, core::kOccupancyFree);
  for (int y = 0; y < 10; ++y)
    if (y < 4 || y > 5) g.data[static_cast<size_t>(y * 20 + 10)] = 100;
  for (int y = 7; y <= 8; ++y)
    for (int x = 15; x <= 16; ++x) g.data[static_cast<size_t>(y * 20 + x)] = -1;
  return g;
}

// The oracle's view of the cell under (x, y) metres: off the map counts as blocked.
enum class OracleCell { kFree, kBlocked, kUnknown };
OracleCell oracle_cell(const core::OccupancyGrid& g, double x, double y) {
  const double gx = x / g.resolution, gy = y / g.resolution;
  if (!(gx >= 0 && gy >= 0 && gx < g.width && gy < g.height)) return OracleCell::kBlocked;
  const int v = g.at(static_cast<int>(gx), static_cast<int>(gy));
  return v < 0 ? OracleCell::kUnknown : v == 0 ? OracleCell::kFree : OracleCell::kBlocked;
}

struct Answer {
  bool is_valid = false;
  std::vector<int32_t> indices;
};

struct ServiceParam {
  RosDistro distro;
  WireMapping mapping;
};

class PathValidService : public ::testing::TestWithParam<ServiceParam> {
 protected:
  void SetUp() override {
    const ServiceParam p = GetParam();
    cfg = test_config(std::string("ipv_") + node::distro_name(p.distro));
    cfg.ros_distro = p.distro;
    cfg.actions.max_result_poses = 100;
    cfg.actions.reply_mapping = p.mapping == WireMapping::kRequestHeader
                                    ? node::ReplyMapping::kCycloneDds
                                    : node::ReplyMapping::kAuto;
    node = std::make_unique<node::PlannerNode>(cfg);
    bus = std::make_unique<BusClient>(cfg);
    participant = node::Participant::create(cfg.domain_id, "vnsba_path_valid_client").value();
    const std::string name = node::ros_topic_name(cfg, cfg.topics.is_path_valid);
    client = p.distro == RosDistro::kKilted
                 ? node::ServiceClient::create<KiltedValidRequestType, KiltedValidResponseType>(
                       *participant, name, p.mapping)
                       .value()
                 : node::ServiceClient::create<ValidRequestType, ValidResponseType>(*participant,
                                                                                    name, p.mapping)
                       .value();
  }
  void TearDown() override {
    node->stop();
    client.reset();
    participant->shutdown();
  }

  // A path of poses at `xy` in `frame`.
  node::PathMsg path_of(const std::vector<std::pair<double, double>>& xy,
                        const std::string& frame = "map") {
    node::PathMsg path;
    path.header().frame_id(frame);
    for (const auto& [x, y] : xy) path.poses().push_back(node::to_pose_msg(x, y, 0.0, frame, {}));
    return path;
  }
  std::optional<Answer> ask(const node::PathMsg& path, uint8_t max_cost = 254,
                            bool unknown_as_obstacle = false) {
    std::optional<Answer> out;
    auto take = [&](const auto& reply) {
      if (reply) out = Answer{reply->is_valid(), reply->invalid_pose_indices()};
    };
    if (GetParam().distro == RosDistro::kKilted) {
      nav2_msgs_kilted::srv::dds_::IsPathValid_Request_ request;
      request.path(path);
      request.max_cost(max_cost);
      request.consider_unknown_as_obstacle(unknown_as_obstacle);
      take(client->call<nav2_msgs_kilted::srv::dds_::IsPathValid_Response_>(request, 10s));
    } else {
      nav2_msgs::srv::dds_::IsPathValid_Request_ request;
      request.path(path);
      take(client->call<nav2_msgs::srv::dds_::IsPathValid_Response_>(request, 10s));
    }
    return out;
  }
  // The invalid poses from `first` on; unknown cells count with `unknown_blocks`.
  std::vector<int32_t> oracle(const std::vector<std::pair<double, double>>& xy, size_t first,
                              bool unknown_blocks) {
    std::vector<int32_t> out;
    for (size_t i = first; i < xy.size(); ++i) {
      const OracleCell cell = oracle_cell(grid, xy[i].first, xy[i].second);
      if (cell == OracleCell::kBlocked || (cell == OracleCell::kUnknown && unknown_blocks))
        out.push_back(static_cast<int32_t>(i));
    }
    return out;
  }

  const core::OccupancyGrid grid = walled_map();
  node::NodeConfig cfg = paper_test_config();
  std::unique_ptr<node::PlannerNode> node;
  std::unique_ptr<BusClient> bus;
  std::unique_ptr<node::Participant> participant;
  std::unique_ptr<node::ServiceClient> client;
};

TEST_P(PathValidService, AnswersAsNav2sPlannerServerOnTheNodesMap) {
  const bool kilted = GetParam().distro == RosDistro::kKilted;
  ASSERT_TRUE(node->start().is_ok());
  ASSERT_TRUE(client->wait_for_server(10s)) << "no is_path_valid server matched";
  const std::vector<std::pair<double, double>> across = {{0.55, 0.15}, {0.95, 0.15}, {1.05, 0.15},
                                                         {1.05, 0.45}, {1.25, 0.25}, {1.55, 0.75},
                                                         {1.65, 0.85}, {2.5, 0.5},   {1.85, 0.15}};
  // No map yet: invalid, nothing listed.
  auto none = ask(path_of(across));
  ASSERT_TRUE(none.has_value()) << "no reply before the first map";
  EXPECT_FALSE(none->is_valid);
  EXPECT_TRUE(none->indices.empty());

  ASSERT_TRUE(bus->wait_for_match(*node));
  bus->publish_slice(grid);
  ASSERT_TRUE(node->wait_for_map(20s));

  // Through the gap: valid.
  const std::vector<std::pair<double, double>> gap = {
      {0.55, 0.45}, {0.95, 0.45}, {1.05, 0.45}, {1.35, 0.55}};
  auto through = ask(path_of(gap));
  ASSERT_TRUE(through.has_value());
  EXPECT_TRUE(through->is_valid);
  EXPECT_TRUE(through->indices.empty());

  // Across the wall, past unknown cells, off the map: the oracle's poses. Humble and Jazzy take
  // the map's unknown cells (allow_unknown false) as invalid; Kilted as its request says.
  auto got = ask(path_of(across));
  ASSERT_TRUE(got.has_value());
  const auto want = oracle(across, 0, !kilted);
  EXPECT_EQ(got->indices, want);
  EXPECT_FALSE(got->is_valid);
  if (kilted) {
    auto unknown = ask(path_of(across), 254, true);
    ASSERT_TRUE(unknown.has_value());
    EXPECT_EQ(unknown->indices, oracle(across, 0, true));
    // max_cost 0: every pose's cost (free: 0) reaches it.
    auto all = ask(path_of(across), 0, false);
    ASSERT_TRUE(all.has_value());
    EXPECT_EQ(all->indices.size(), across.size());
  }

  // The robot beside pose 4: poses 0..3 are behind it.
  bus->publish_robot_pose(1.26, 0.25);
  bool from_robot = false;
  for (int attempt = 0; attempt < 50 && !from_robot; ++attempt) {
    auto later = ask(path_of(across));
    from_robot = later && later->indices == oracle(across, 4, !kilted);
    if (!from_robot) std::this_thread::sleep_for(50ms);
  }
  EXPECT_TRUE(from_robot) << "the check does not start at the pose closest to the robot";

  // Another frame; too many poses (actions.max_result_poses 100): invalid, nothing listed.
  auto odom = ask(path_of(gap, "odom"));
  ASSERT_TRUE(odom.has_value());
  EXPECT_FALSE(odom->is_valid);
  EXPECT_TRUE(odom->indices.empty());
  std::vector<std::pair<double, double>> many(101, {0.55, 0.45});
  auto too_many = ask(path_of(many));
  ASSERT_TRUE(too_many.has_value());
  EXPECT_FALSE(too_many->is_valid);
  EXPECT_TRUE(too_many->indices.empty());
  // An empty path is invalid (Nav2).
  auto empty = ask(path_of({}));
  ASSERT_TRUE(empty.has_value());
  EXPECT_FALSE(empty->is_valid);

  // A request announcing 2^31 poses in a few bytes is dropped undecoded; the service goes on.
  nav2_msgs::srv::dds_::IsPathValid_Request_ small;
  node::RequestHeader header{};
  node::RawSample raw = node::encode_request(small, GetParam().mapping, header);
  // The pose count follows the path's header: its stamp (8 bytes) and its empty frame_id (a
  // length of 1, the terminating zero, padding to 4: 8 bytes); Kilted's request ends with
  // max_cost and the flag after the poses.
  const size_t at = 4 + (GetParam().mapping == WireMapping::kRequestHeader ? 16 : 0) + 8 + 8;
  std::vector<uint8_t> bytes = raw.bytes;
  bytes.resize(at + 4 + (kilted ? 2 : 0), 0);
  const uint32_t huge = 1u << 31;
  std::memcpy(bytes.data() + at, &huge, 4);
  raw.bytes = bytes;
  client->send_raw(raw);
  auto after = ask(path_of(gap));
  ASSERT_TRUE(after.has_value()) << "no reply after a malformed request";
  EXPECT_TRUE(after->is_valid);
  EXPECT_EQ(client->duplicate_replies(), 0u);
}

std::string service_param_name(const ::testing::TestParamInfo<ServiceParam>& info) {
  return std::string(node::distro_name(info.param.distro)) +
         (info.param.mapping == WireMapping::kRequestHeader ? "RequestHeader" : "SampleIdentity");
}

INSTANTIATE_TEST_SUITE_P(
    IsPathValid, PathValidService,
    ::testing::Values(ServiceParam{RosDistro::kJazzy, WireMapping::kSampleIdentity},
                      ServiceParam{RosDistro::kJazzy, WireMapping::kRequestHeader},
                      ServiceParam{RosDistro::kKilted, WireMapping::kSampleIdentity},
                      ServiceParam{RosDistro::kKilted, WireMapping::kRequestHeader}),
    service_param_name);

}  // namespace
}  // namespace vnsba::test
