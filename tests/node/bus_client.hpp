// A test client on a real DDS bus (loopback UDP): publishes slices, requests, goals and poses,
// and collects what the node publishes. No mocks: it is a second participant.
//
// Isolation: each test process picks its domain from its pid, and every topic name carries the
// pid and the test's tag, so concurrent runs never see each other even if two pids share a
// domain.
#pragma once

#include <fastdds/rtps/common/WriteParams.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "geometry_msgs/msg/PoseStampedPubSubTypes.h"
#include "nav_msgs/msg/OccupancyGridPubSubTypes.h"
#include "nav_msgs/msg/PathPubSubTypes.h"
#include "paper_config.hpp"
#include "vnsba/node/config.hpp"
#include "vnsba/node/convert.hpp"
#include "vnsba/node/dds.hpp"
#include "vnsba/node/planner_node.hpp"
#include "vnsba_msgs/msg/PlanRequestPubSubTypes.h"
#include "vnsba_msgs/msg/PlanStatusPubSubTypes.h"
#include "vnsba_msgs/msg/PlannerDebugPubSubTypes.h"

namespace vnsba::test {

using namespace std::chrono_literals;
using node::PathMsg;
using node::PlannerDebugMsg;
using node::PlanStatusMsg;

inline int test_domain() {
  return 1 + static_cast<int>(getpid() % 200);
}

// A config on this process's domain with topics unique to `tag`.
inline node::NodeConfig test_config(const std::string& tag) {
  node::NodeConfig cfg = paper_test_config();
  cfg.domain_id = test_domain();
  const std::string p = "t" + std::to_string(getpid()) + "_" + tag + "_";
  auto& t = cfg.topics;
  for (std::string* name :
       {&t.projected_map, &t.goal_pose, &t.robot_pose, &t.plan_request, &t.plan, &t.plan_status,
        &t.planner_debug, &t.octomap, &t.plan_raw, &t.plan_pruned, &t.expansions_forward,
        &t.expansions_backward, &t.meeting_point, &t.tf, &t.tf_static, &t.clock,
        &t.compute_path_to_pose, &t.compute_path_through_poses, &t.is_path_valid}) {
    *name = p + std::string(node::without_leading_slash(*name));
  }
  cfg.planner.settings.max_planning_time = std::chrono::seconds(10);
  return cfg;
}

// The YAML that gives a process (node, slicer, recorder) the same domain and topics as `cfg`.
inline std::string config_yaml(const node::NodeConfig& cfg) {
  const auto& t = cfg.topics;
  return "domain_id: " + std::to_string(cfg.domain_id) + "\ntopics:\n" +
         "  projected_map: " + t.projected_map + "\n  goal_pose: " + t.goal_pose +
         "\n  robot_pose: " + t.robot_pose + "\n  plan_request: " + t.plan_request +
         "\n  plan: " + t.plan + "\n  plan_status: " + t.plan_status +
         "\n  planner_debug: " + t.planner_debug + "\n  octomap: " + t.octomap + "\n";
}

template <class Msg>
class Collector : public node::dds::DataReaderListener {
 public:
  void on_data_available(node::dds::DataReader* reader) override {
    Msg msg;
    node::dds::SampleInfo info;
    while (reader->take_next_sample(&msg, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      std::lock_guard<std::mutex> lock(mutex_);
      received_.push_back(std::move(msg));
      msg = Msg();
      cv_.notify_all();
    }
  }
  // Waits until `pred(all received)` holds.
  template <class Pred>
  bool wait(Pred pred, std::chrono::milliseconds timeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    return cv_.wait_for(lock, timeout, [&] { return pred(received_); });
  }
  std::vector<Msg> snapshot() {
    std::lock_guard<std::mutex> lock(mutex_);
    return received_;
  }
  // Removes and returns everything received so far.
  std::vector<Msg> take_all() {
    std::lock_guard<std::mutex> lock(mutex_);
    return std::exchange(received_, {});
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<Msg> received_;
};

class BusClient {
 public:
  explicit BusClient(const node::NodeConfig& cfg) : cfg_(cfg) {
    participant_ = node::Participant::create(cfg.domain_id, "vnsba_test_client", nullptr,
                                             cfg.localhost_only, {}, cfg.discovery_servers)
                       .value();
    auto name = [&](const std::string& n) { return node::dds_topic_name(cfg_, n); };
    using node::TopicQos;
    slice_ = participant_
                 ->writer(participant_
                              ->topic<nav_msgs::msg::dds_::OccupancyGrid_PubSubType>(
                                  name(cfg.topics.projected_map))
                              .value(),
                          node::writer_qos(TopicQos::kLatched, true))
                 .value();
    request_ = participant_
                   ->writer(participant_
                                ->topic<vnsba_msgs::msg::dds_::PlanRequest_PubSubType>(
                                    name(cfg.topics.plan_request))
                                .value(),
                            node::writer_qos(TopicQos::kEvents, false))
                   .value();
    goal_ = participant_
                ->writer(participant_
                             ->topic<geometry_msgs::msg::dds_::PoseStamped_PubSubType>(
                                 name(cfg.topics.goal_pose))
                             .value(),
                         node::writer_qos(TopicQos::kEvents, false))
                .value();
    robot_pose_ = participant_
                      ->writer(participant_
                                   ->topic<geometry_msgs::msg::dds_::PoseStamped_PubSubType>(
                                       name(cfg.topics.robot_pose))
                                   .value(),
                               node::writer_qos(TopicQos::kLatest, false))
                      .value();
    status_reader_ = participant_
                         ->reader(participant_
                                      ->topic<vnsba_msgs::msg::dds_::PlanStatus_PubSubType>(
                                          name(cfg.topics.plan_status))
                                      .value(),
                                  node::reader_qos(TopicQos::kStatus), &statuses)
                         .value();
    path_reader_ =
        participant_
            ->reader(
                participant_->topic<nav_msgs::msg::dds_::Path_PubSubType>(name(cfg.topics.plan))
                    .value(),
                node::reader_qos(TopicQos::kLatest), &paths)
            .value();
    if (subscribe_debug_) {
      debug_reader_ = participant_
                          ->reader(participant_
                                       ->topic<vnsba_msgs::msg::dds_::PlannerDebug_PubSubType>(
                                           name(cfg.topics.planner_debug))
                                       .value(),
                                   node::reader_qos(TopicQos::kDebug), &debug)
                          .value();
    }
  }
  ~BusClient() { participant_->shutdown(); }

  // Waits until the node's readers and writers have matched ours.
  bool wait_for_node(std::chrono::milliseconds timeout = 10s) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < end) {
      node::dds::SubscriptionMatchedStatus sub;
      status_reader_->get_subscription_matched_status(sub);
      // The debug reader too: the node publishes debug only while a reader is matched, so a
      // plan sent before that match would have none.
      node::dds::SubscriptionMatchedStatus debug_sub;
      if (debug_reader_ != nullptr) debug_reader_->get_subscription_matched_status(debug_sub);
      // The path reader too: `plan` is volatile, so a path published before that match is lost.
      node::dds::SubscriptionMatchedStatus path_sub;
      path_reader_->get_subscription_matched_status(path_sub);
      if (node::matched_readers(request_) > 0 && node::matched_readers(goal_) > 0 &&
          (node::matched_readers(robot_pose_) > 0 || !node_reads_robot_pose_stamped()) &&
          sub.current_count > 0 && path_sub.current_count > 0 &&
          (debug_reader_ == nullptr || debug_sub.current_count > 0)) {
        return true;
      }
      std::this_thread::sleep_for(10ms);
    }
    return false;
  }

  // Both sides of the match: wait_for_node(), then the node's side, which discovery does not
  // make symmetric: its `plan` and `plan_status` writers have matched readers. Both topics are
  // volatile, so a path or a status written before that is lost to a reader; the node holds the
  // answers to a request for its requester, but not what this client reads of others' answers.
  bool wait_for_match(const node::PlannerNode& planner, std::chrono::milliseconds timeout = 10s) {
    if (!wait_for_node(timeout)) return false;
    const auto end = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      const node::PlannerNode::Stats stats = planner.stats();
      if (stats.plan_readers > 0 && stats.status_readers > 0) return true;
      if (std::chrono::steady_clock::now() > end) return false;
      std::this_thread::sleep_for(10ms);
    }
  }

  // Whether the node reads PoseStamped robot poses (our robot_pose writer's type) at all.
  bool node_reads_robot_pose_stamped() const {
    return cfg_.robot_pose_source == node::RobotPoseSource::kTopic &&
           cfg_.robot_pose_type == node::RobotPoseType::kPoseStamped;
  }

  void publish_slice(const core::OccupancyGrid& grid, const std::string& frame = "map") {
    auto msg = node::to_slice_msg(grid, frame, node::now_msg());
    slice_->write(&msg);
  }
  void publish_slice_msg(node::OccupancyGridMsg msg) { slice_->write(&msg); }

  // Each returns the request's sample identity, which its status carries.
  node::RequestIdentity publish_request(const std::string& id, double sx, double sy, double gx,
                                        double gy, const std::string& planner = "",
                                        const std::string& frame = "map") {
    node::PlanRequestMsg msg;
    msg.id(id);
    msg.start(node::to_pose_msg(sx, sy, 0.0, frame, node::now_msg()));
    msg.goal(node::to_pose_msg(gx, gy, 0.0, frame, node::now_msg()));
    msg.planner(planner);
    return publish_request_msg(std::move(msg));
  }
  node::RequestIdentity publish_request_msg(node::PlanRequestMsg msg) {
    eprosima::fastrtps::rtps::WriteParams params;
    EXPECT_TRUE(node::write_sample(request_, &msg, params)) << "request write failed";
    return node::identity_of(params, node::wire::SUBJECT_REQUEST);
  }

  void publish_goal(double x, double y) {
    auto msg = node::to_pose_msg(x, y, 0.0, "map", node::now_msg());
    node::write_sample(goal_, &msg);
  }
  void publish_robot_pose(double x, double y) {
    auto msg = node::to_pose_msg(x, y, 0.0, "map", node::now_msg());
    robot_pose_->write(&msg);
  }

  std::optional<PlanStatusMsg> wait_status(const std::string& id,
                                           std::chrono::milliseconds timeout = 15s) {
    std::optional<PlanStatusMsg> found;
    statuses.wait(
        [&](const std::vector<PlanStatusMsg>& all) {
          for (const auto& s : all) {
            if (s.request_id() == id) {
              found = s;
              return true;
            }
          }
          return false;
        },
        timeout);
    return found;
  }

  // The status answering the request sent with `identity`.
  std::optional<PlanStatusMsg> wait_status_for(const node::RequestIdentity& identity,
                                               std::chrono::milliseconds timeout = 15s) {
    std::optional<PlanStatusMsg> found;
    statuses.wait(
        [&](const std::vector<PlanStatusMsg>& all) {
          for (const auto& s : all) {
            if (s.request_writer_guid() == identity.writer_guid &&
                s.request_sequence_number() == identity.sequence_number) {
              found = s;
              return true;
            }
          }
          return false;
        },
        timeout);
    return found;
  }
  // The first report about a slice (SUBJECT_MAP) after the first `skip` ones.
  std::optional<PlanStatusMsg> wait_map_report(size_t skip = 0,
                                               std::chrono::milliseconds timeout = 15s) {
    std::optional<PlanStatusMsg> found;
    statuses.wait(
        [&](const std::vector<PlanStatusMsg>& all) {
          size_t seen = 0;
          for (const auto& s : all) {
            if (s.subject() == node::wire::SUBJECT_MAP && seen++ == skip) {
              found = s;
              return true;
            }
          }
          return false;
        },
        timeout);
    return found;
  }

  Collector<PlanStatusMsg> statuses;
  Collector<PathMsg> paths;
  Collector<PlannerDebugMsg> debug;

 private:
  node::NodeConfig cfg_;
  bool subscribe_debug_ = true;
  std::unique_ptr<node::Participant> participant_;
  node::dds::DataWriter* slice_ = nullptr;
  node::dds::DataWriter* request_ = nullptr;
  node::dds::DataWriter* goal_ = nullptr;
  node::dds::DataWriter* robot_pose_ = nullptr;
  node::dds::DataReader* status_reader_ = nullptr;
  node::dds::DataReader* path_reader_ = nullptr;
  node::dds::DataReader* debug_reader_ = nullptr;
};

// A node and a BusClient on `cfg`, started and matched.
struct Running {
  explicit Running(node::NodeConfig cfg) : config(std::move(cfg)), node(config), client(config) {}
  node::NodeConfig config;
  node::PlannerNode node;
  BusClient client;
  bool start() {
    const core::Status s = node.start();
    EXPECT_TRUE(s.is_ok()) << s.message;
    return s.is_ok() && client.wait_for_match(node);
  }
  // start(), then `grid` as the node's map.
  bool start_with_map(const core::OccupancyGrid& grid) {
    if (!start()) return false;
    client.publish_slice(grid);
    return node.wait_for_map(10s);
  }
};

// An open `width` x `height` map of `resolution`-metre cells, every cell free.
inline core::OccupancyGrid free_room(int width, int height, double resolution) {
  core::OccupancyGrid g;
  g.width = width;
  g.height = height;
  g.resolution = resolution;
  g.data.assign(static_cast<size_t>(width) * static_cast<size_t>(height), core::kOccupancyFree);
  return g;
}

// The oracle of a planned path: every point of every segment, sampled 1/64 cell apart, lies in a
// free cell of `g` (the grid the node was given), and the path is not empty.
inline bool path_free(const core::OccupancyGrid& g, const node::PathMsg& path) {
  const auto& poses = path.poses();
  auto free_at = [&](double x, double y) {
    const int cx = static_cast<int>(std::floor((x - g.origin_x) / g.resolution));
    const int cy = static_cast<int>(std::floor((y - g.origin_y) / g.resolution));
    return cx >= 0 && cy >= 0 && cx < g.width && cy < g.height && g.at(cx, cy) < 65;
  };
  for (size_t i = 0; i + 1 < poses.size(); ++i) {
    const auto& a = poses[i].pose().position();
    const auto& b = poses[i + 1].pose().position();
    const double len = std::hypot(b.x() - a.x(), b.y() - a.y()) / g.resolution;
    const int n = std::max(2, static_cast<int>(std::ceil(len * 64)) + 1);
    for (int k = 0; k < n; ++k) {
      const double t = static_cast<double>(k) / (n - 1);
      if (!free_at(a.x() + t * (b.x() - a.x()), a.y() + t * (b.y() - a.y()))) return false;
    }
  }
  return !poses.empty();
}

}  // namespace vnsba::test
