// A PlannerNode in this process serving both Nav2 actions, a bus client that feeds it maps and
// an ActionClient of each action, in one wire mapping (rmw_fastrtps's or rmw_cyclonedds's) and
// the base config's ROS 2 distribution (ros.distro): the fixture of the action tests
// (test_actions.cpp) and the distribution tests (test_distros.cpp).
#pragma once

#include <chrono>
#include <memory>
#include <string>
#include <utility>

#include "bus_client.hpp"
#include "vnsba/node/action_client.hpp"
#include "vnsba/node/planner_node.hpp"

namespace vnsba::test {

struct ActionRun {
  ActionRun(const std::string& tag, node::WireMapping mapping, node::NodeConfig cfg_in = {})
      : cfg(configure(tag, mapping, std::move(cfg_in))), node(cfg), client(cfg) {
    participant = node::Participant::create(cfg.domain_id, "vnsba_action_client").value();
    to_pose = node::ActionClient::create(
                  *participant, node::ros_topic_name(cfg, cfg.topics.compute_path_to_pose),
                  node::ActionKind::kComputePathToPose, mapping, cfg.ros_distro)
                  .value();
    through = node::ActionClient::create(
                  *participant, node::ros_topic_name(cfg, cfg.topics.compute_path_through_poses),
                  node::ActionKind::kComputePathThroughPoses, mapping, cfg.ros_distro)
                  .value();
  }
  ~ActionRun() {
    node.stop();
    to_pose.reset();
    through.reset();
    participant->shutdown();
  }
  static node::NodeConfig configure(const std::string& tag, node::WireMapping mapping,
                                    node::NodeConfig base) {
    node::NodeConfig cfg = test_config(tag);
    cfg.planner = base.planner;
    if (!cfg.planner.settings.max_planning_time)
      cfg.planner.settings.max_planning_time = std::chrono::seconds(10);
    cfg.map = base.map;
    cfg.preempt = base.preempt;
    cfg.queue_capacity = base.queue_capacity;
    cfg.actions = base.actions;
    cfg.ros_distro = base.ros_distro;
    // A Fast DDS client is announced as eProsima's: the node would answer it in rmw_fastrtps's
    // mapping. Told so, it answers every client in rmw_cyclonedds's.
    cfg.actions.reply_mapping = mapping == node::WireMapping::kRequestHeader
                                    ? node::ReplyMapping::kCycloneDds
                                    : node::ReplyMapping::kAuto;
    return cfg;
  }
  bool start(const core::OccupancyGrid& grid) {
    const core::Status s = node.start();
    EXPECT_TRUE(s.is_ok()) << s.message;
    if (!s.is_ok() || !client.wait_for_match(node)) return false;
    client.publish_slice(grid);
    return node.wait_for_map(20s) && to_pose->wait_for_server(10s) && through->wait_for_server(10s);
  }
  node::NodeConfig cfg = paper_test_config();
  node::PlannerNode node;
  BusClient client;
  std::unique_ptr<node::Participant> participant;
  std::unique_ptr<node::ActionClient> to_pose;
  std::unique_ptr<node::ActionClient> through;
};

}  // namespace vnsba::test
