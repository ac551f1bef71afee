// End-to-end latency of vnsba_node over loopback DDS, beside the core planning time of the same
// queries, so the middleware's share is visible. Prints tables; no pass/fail.
//
//   request published -> PlanStatus (with the path) received by the client, p50 and p99
//   core: core::Planner::plan() on the same map and query, in this process, p50 and p99
//   overhead: end-to-end p50 minus core p50
//
// Then the time from publishing a 4,000 x 4,000 slice (16 MB) to the node having it ready.
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "bench/indoor_map.hpp"
#include "nav_msgs/msg/OccupancyGridPubSubTypes.h"
#include "vnsba/node/action_client.hpp"
#include "vnsba/node/config.hpp"
#include "vnsba/node/convert.hpp"
#include "vnsba/node/dds.hpp"
#include "vnsba/node/planner_node.hpp"
#include "vnsba/node/security.hpp"
#include "vnsba_msgs/msg/PlanRequestPubSubTypes.h"
#include "vnsba_msgs/msg/PlanStatusPubSubTypes.h"

namespace {

using namespace vnsba;
using Clock = std::chrono::steady_clock;

class StatusWaiter : public node::dds::DataReaderListener {
 public:
  void on_data_available(node::dds::DataReader* reader) override {
    node::PlanStatusMsg msg;
    node::dds::SampleInfo info;
    while (reader->take_next_sample(&msg, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      std::lock_guard<std::mutex> lock(mutex_);
      last_id_ = msg.request_id();
      last_ok_ = msg.code() == node::wire::OK;
      received_at_ = Clock::now();
      cv_.notify_all();
    }
  }
  // Waits for the status of `id`; returns its arrival time, or nullopt after 30 s.
  std::optional<Clock::time_point> wait(const std::string& id, bool* ok) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (!cv_.wait_for(lock, std::chrono::seconds(30), [&] { return last_id_ == id; }))
      return std::nullopt;
    *ok = last_ok_;
    return received_at_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  std::string last_id_;
  bool last_ok_ = false;
  Clock::time_point received_at_;
};

using bench::indoor_map;
using bench::percentile;

// A private domain and topics for this process, so concurrent runs never meet.
void isolate(node::NodeConfig& cfg, const std::string& prefix) {
  cfg.domain_id = 1 + static_cast<int>(getpid() % 200);
  auto& t = cfg.topics;
  for (std::string* name :
       {&t.projected_map, &t.plan_request, &t.plan_status, &t.plan, &t.planner_debug, &t.goal_pose,
        &t.robot_pose, &t.octomap, &t.compute_path_to_pose, &t.compute_path_through_poses}) {
    *name = prefix + *name;
  }
}

// `count` start and goal cells drawn uniformly from `map` with `seed`, each pair one that
// `planner` plans with `options` (both free and connected: a robot's inflation parts some rooms
// of the indoor map). At most 100 draws a query, so a map without such pairs ends the loop.
std::vector<std::pair<core::Cell, core::Cell>> free_queries(const core::GridMap& map, int count,
                                                            unsigned seed, core::Planner& planner,
                                                            const core::PlannerOptions& options) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> x(0, map.width() - 1), y(0, map.height() - 1);
  std::vector<std::pair<core::Cell, core::Cell>> out;
  for (int draw = 0; static_cast<int>(out.size()) < count && draw < 100 * count; ++draw) {
    const core::Cell a{x(rng), y(rng)}, b{x(rng), y(rng)};
    if (!map.blocked(a) && !map.blocked(b) && planner.plan({a, b}, options).status.is_ok())
      out.emplace_back(a, b);
  }
  return out;
}

// A plan_request between the centres of two cells of `map`.
node::PlanRequestMsg request_between(const core::GridMap& map, const core::Cell& a,
                                     const core::Cell& b, const std::string& id) {
  const auto ca = map.cell_centre_world(a), cb = map.cell_centre_world(b);
  node::PlanRequestMsg request;
  request.id(id);
  request.start(node::to_pose_msg(ca.x(), ca.y(), 0, "map", node::now_msg()));
  request.goal(node::to_pose_msg(cb.x(), cb.y(), 0, "map", node::now_msg()));
  return request;
}

// config/default.yaml's configuration, as the node runs without a config file.
node::NodeConfig default_node_config() {
  const node::ConfigResult defaults = node::default_config();
  if (!defaults.config) {
    for (const std::string& error : defaults.errors) std::fprintf(stderr, "%s\n", error.c_str());
    std::exit(1);
  }
  return *defaults.config;
}

struct Setup {
  node::NodeConfig cfg = default_node_config();
  // With security, the slice comes from a participant with the slicer's enclave and requests
  // from one with send_goal's, as on a secured bus (each enclave's permissions allow only that).
  std::unique_ptr<node::Participant> map_client;
  std::unique_ptr<node::Participant> client;
  node::dds::DataWriter* slice = nullptr;
  node::dds::DataWriter* request = nullptr;
  node::dds::DataReader* status = nullptr;
  StatusWaiter waiter;
};

bool connect(Setup& s) {
  auto name = [&](const std::string& n) { return node::dds_topic_name(s.cfg, n); };
  // A participant with `enclave` (used only with security on) into `out`; false on failure.
  auto join = [&](const char* participant_name, const char* enclave,
                  std::unique_ptr<node::Participant>& out) {
    auto participant =
        node::Participant::create(s.cfg.domain_id, participant_name, nullptr, false,
                                  node::with_default_enclave(s.cfg.security, enclave));
    if (!participant) std::printf("%s\n", participant.error().message.c_str());
    if (participant) out = std::move(participant).value();
    return out != nullptr;
  };
  if (!join("vnsba_latency_bench", node::kSendGoalEnclave, s.client)) return false;
  node::Participant* map_client = s.client.get();
  if (s.cfg.security.enable) {
    if (!join("vnsba_latency_bench_map", node::kSlicerEnclave, s.map_client)) return false;
    map_client = s.map_client.get();
  }
  auto slice_topic = map_client->topic<nav_msgs::msg::dds_::OccupancyGrid_PubSubType>(
      name(s.cfg.topics.projected_map));
  auto request_topic = s.client->topic<vnsba_msgs::msg::dds_::PlanRequest_PubSubType>(
      name(s.cfg.topics.plan_request));
  auto status_topic =
      s.client->topic<vnsba_msgs::msg::dds_::PlanStatus_PubSubType>(name(s.cfg.topics.plan_status));
  if (!slice_topic || !request_topic || !status_topic) return false;
  s.slice =
      map_client->writer(*slice_topic, node::writer_qos(node::TopicQos::kLatched, true)).value();
  s.request =
      s.client->writer(*request_topic, node::writer_qos(node::TopicQos::kEvents, false)).value();
  s.status =
      s.client->reader(*status_topic, node::reader_qos(node::TopicQos::kStatus), &s.waiter).value();
  for (int i = 0; i < 1000; ++i) {
    node::dds::SubscriptionMatchedStatus matched;
    s.status->get_subscription_matched_status(matched);
    if (node::matched_readers(s.request) > 0 && matched.current_count > 0) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

// `planner`: the node's configured planner for this run (planner.name), or default.yaml's (auto)
// when not given. `security` enabled:
// node and clients secured with its keystore's enclaves, whose permissions name the default
// topics, so the topics keep their names (the domain alone keeps the run apart).
void run_map(const char* label, int size, int queries,
             std::optional<core::PlannerKind> planner = std::nullopt,
             const node::SecurityConfig* security = nullptr) {
  Setup s;
  if (security != nullptr) {
    s.cfg.domain_id = 1 + static_cast<int>(getpid() % 200);
    s.cfg.security = *security;
  } else {
    isolate(s.cfg, "bench" + std::to_string(getpid()) + "_" + std::to_string(size) + "_" +
                       (planner ? std::string(core::to_string(*planner)) : "default") + "_");
  }
  s.cfg.debug = node::DebugPublishing::kNever;
  if (planner) {
    s.cfg.planner.kind = *planner;
    s.cfg.planner.auto_kind = false;
  }
  // What the node runs for a request that names no planner, as it applies it (no costs for jps).
  core::PlannerOptions options = s.cfg.planner.options();
  core::drop_unsupported_costs(options);
  s.cfg.map.max_cells = std::max<int64_t>(s.cfg.map.max_cells, int64_t{size} * size);
  node::PlannerNode planner_node(s.cfg);
  if (!planner_node.start().is_ok() || !connect(s)) {
    std::printf("%-10s could not start the node or connect\n", label);
    return;
  }
  const core::OccupancyGrid grid = indoor_map(size, 0.05);
  auto slice = node::to_slice_msg(grid, "map", node::now_msg());
  if (!s.slice->write(&slice)) {
    std::printf("%-10s could not write the slice\n", label);
    return;
  }
  if (!planner_node.wait_for_map(std::chrono::seconds(30))) return;
  // The reference plans on the grid the node received (float32 resolution on the wire).
  const core::OccupancyGrid received =
      node::from_slice_msg(std::move(slice), "map", s.cfg.map.max_cells).grid;
  auto map = std::make_shared<const core::GridMap>(
      core::GridMap::build(received, node::planning_grid_options(s.cfg)).value());
  core::Planner reference(map);

  std::vector<double> e2e_us, core_us;
  int failures = 0;
  int q = 0;
  for (const auto& [a, b] : free_queries(*map, queries, 7, reference, options)) {
    node::PlanRequestMsg request = request_between(*map, a, b, "q" + std::to_string(++q));
    const auto sent = Clock::now();
    if (!node::write_sample(s.request, &request)) {  // counted, never silently dropped
      ++failures;
      continue;
    }
    bool ok = false;
    const auto received_at = s.waiter.wait(request.id(), &ok);
    if (!received_at || !ok) {
      ++failures;
      continue;
    }
    e2e_us.push_back(std::chrono::duration<double, std::micro>(*received_at - sent).count());
    const auto t0 = Clock::now();
    const core::PlanResult r = reference.plan({a, b}, options);
    core_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
    if (!r.status.is_ok()) ++failures;
  }
  if (e2e_us.empty()) return;
  const double e2e50 = percentile(e2e_us, 0.5), core50 = percentile(core_us, 0.5);
  std::printf("%-10s %-20s %8zu %10.0f %10.0f %10.0f %10.0f %12.0f %9d\n", label,
              std::string(core::to_string(options.planner)).c_str(), e2e_us.size(), e2e50,
              percentile(e2e_us, 0.99), core50, percentile(core_us, 0.99), e2e50 - core50,
              failures);
}

// The ComputePathToPose action against plan_request on the same queries, interleaved (request,
// then the same plan as a goal), in one reply mapping: rmw_fastrtps's (the node decides it from
// this client's vendor) or rmw_cyclonedds's (the node told so by actions.reply_mapping). The
// action's round trip is send_goal -> accepted -> get_result -> result, as a ROS 2 client does it.
void run_actions(const char* label, int size, int queries, node::WireMapping mapping) {
  Setup s;
  isolate(s.cfg, "bench" + std::to_string(getpid()) + "_act" + std::to_string(size) + "_" +
                     (mapping == node::WireMapping::kRequestHeader ? "h" : "i") + "_");
  s.cfg.debug = node::DebugPublishing::kNever;
  s.cfg.map.max_cells = std::max<int64_t>(s.cfg.map.max_cells, int64_t{size} * size);
  s.cfg.actions.reply_mapping = mapping == node::WireMapping::kRequestHeader
                                    ? node::ReplyMapping::kCycloneDds
                                    : node::ReplyMapping::kAuto;
  node::PlannerNode planner_node(s.cfg);
  if (!planner_node.start().is_ok() || !connect(s)) {
    std::printf("%-10s could not start the node or connect\n", label);
    return;
  }
  auto action = node::ActionClient::create(
      *s.client, node::ros_topic_name(s.cfg, s.cfg.topics.compute_path_to_pose),
      node::ActionKind::kComputePathToPose, mapping);
  if (!action || !(*action)->wait_for_server(std::chrono::seconds(10))) {
    std::printf("%-10s the action server did not match\n", label);
    return;
  }
  const core::OccupancyGrid grid = indoor_map(size, 0.05);
  auto slice = node::to_slice_msg(grid, "map", node::now_msg());
  if (!s.slice->write(&slice) || !planner_node.wait_for_map(std::chrono::seconds(30))) return;
  const core::OccupancyGrid received =
      node::from_slice_msg(std::move(slice), "map", s.cfg.map.max_cells).grid;
  auto map = std::make_shared<const core::GridMap>(
      core::GridMap::build(received, node::planning_grid_options(s.cfg)).value());
  std::vector<double> request_us, action_us, difference_us;
  int failures = 0;
  int q = 0;
  core::Planner query_planner(map);
  core::PlannerOptions options = s.cfg.planner.options();
  core::drop_unsupported_costs(options);
  for (const auto& [a, b] : free_queries(*map, queries, 11, query_planner, options)) {
    node::PlanRequestMsg request = request_between(*map, a, b, "a" + std::to_string(++q));
    const auto sent = Clock::now();
    bool ok = false;
    std::optional<Clock::time_point> answered;
    if (node::write_sample(s.request, &request)) answered = s.waiter.wait(request.id(), &ok);
    if (!answered || !ok) {
      ++failures;
      continue;
    }
    node::ActionGoalSpec goal;
    goal.start = request.start();
    goal.goals = {request.goal()};
    const auto goal_sent = Clock::now();
    const auto result =
        (*action)->plan(node::ActionClient::random_id(), goal, std::chrono::seconds(30));
    const auto goal_done = Clock::now();
    if (!result || result->status != node::GoalState::kSucceeded) {
      ++failures;
      continue;
    }
    request_us.push_back(std::chrono::duration<double, std::micro>(*answered - sent).count());
    action_us.push_back(std::chrono::duration<double, std::micro>(goal_done - goal_sent).count());
    difference_us.push_back(action_us.back() - request_us.back());
  }
  if (action_us.empty()) return;
  std::printf("%-10s %-16s %8zu %14.0f %14.0f %14.0f %14.0f %9d\n", label,
              mapping == node::WireMapping::kRequestHeader ? "rmw_cyclonedds" : "rmw_fastrtps",
              action_us.size(), percentile(request_us, 0.5), percentile(action_us, 0.5),
              percentile(difference_us, 0.5), percentile(action_us, 0.99), failures);
}

void run_large_slice() {
  Setup s;
  isolate(s.cfg, "bench" + std::to_string(getpid()) + "_large_");
  s.cfg.map.max_cells = int64_t{4000} * 4000;
  node::PlannerNode planner_node(s.cfg);
  if (!planner_node.start().is_ok() || !connect(s)) return;
  const core::OccupancyGrid grid = indoor_map(4000, 0.05);
  auto slice = node::to_slice_msg(grid, "map", node::now_msg());
  const auto t0 = Clock::now();
  if (!s.slice->write(&slice)) {
    std::printf("4000 x 4000 slice: could not write it\n");
    return;
  }
  const bool ready = planner_node.wait_for_map(std::chrono::seconds(60));
  const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  std::printf("4000 x 4000 slice (16 MB): %s %.0f ms after publishing\n",
              ready ? "ready to plan" : "NOT ready", ms);
}

}  // namespace

int main(int argc, char** argv) {
  // The output is the table: the node's per-plan log lines (info) would bury it.
  spdlog::set_level(spdlog::level::warn);
  std::printf("vnsba_node end-to-end latency over loopback DDS (indoor maps, 5 cm cells)\n");
  std::printf("%-10s %-20s %8s %10s %10s %10s %10s %12s %9s\n", "map", "planner", "queries",
              "e2e_p50_us", "e2e_p99_us", "core_p50_us", "core_p99_us", "overhead_us", "failures");
  // --security KEYSTORE (made by tools/make_keystore.sh): the 100 x 100 map without and with DDS
  // Security, on the same topics and domain, three times alternating; nothing else.
  if (argc == 3 && std::string(argv[1]) == "--security") {
    node::SecurityConfig open, secured;
    secured.enable = true;
    secured.keystore = argv[2];
    for (int round = 0; round < 3; ++round) {
      run_map("100x100", 100, 300, std::nullopt, &open);
      run_map("100x100sec", 100, 300, std::nullopt, &secured);
    }
    return 0;
  }
  // --actions: only the action section below.
  const bool actions_only = argc == 2 && std::string(argv[1]) == "--actions";
  if (argc != 1 && !actions_only) {
    std::fprintf(stderr, "usage: vnsba_node_latency_bench [--security KEYSTORE | --actions]\n");
    return 2;
  }
  if (!actions_only) {
    run_map("100x100", 100, 300);
    run_map("1000x1000", 1000, 60);
    // An exact plan across a 200 m office floor: what jps is for.
    run_map("4000x4000", 4000, 40, core::PlannerKind::kJps);
    run_large_slice();
  }
  // Nav2's action against plan_request, same plans; target: the action within 0.5 ms (p50) of
  // the request. action - request is the median of per-query differences.
  std::printf(
      "\nComputePathToPose action vs plan_request round trip (same queries, interleaved)\n");
  std::printf("%-10s %-16s %8s %14s %14s %14s %14s %9s\n", "map", "mapping", "queries",
              "request_p50_us", "action_p50_us", "action-request", "action_p99_us", "failures");
  for (node::WireMapping mapping :
       {node::WireMapping::kSampleIdentity, node::WireMapping::kRequestHeader}) {
    run_actions("100x100", 100, 300, mapping);
    run_actions("1000x1000", 1000, 60, mapping);
  }
  return 0;
}
