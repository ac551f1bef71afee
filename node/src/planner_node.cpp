#include "vnsba/node/planner_node.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <set>
#include <thread>
#include <utility>

#include "action_server.hpp"
#include "geometry_msgs/msg/PointStampedPubSubTypes.h"
#include "geometry_msgs/msg/PoseStampedPubSubTypes.h"
#include "geometry_msgs/msg/PoseWithCovarianceStampedPubSubTypes.h"
#include "nav_msgs/msg/OccupancyGridPubSubTypes.h"
#include "nav_msgs/msg/PathPubSubTypes.h"
#include "rosgraph_msgs/msg/ClockPubSubTypes.h"
#include "take_listener.hpp"
#include "tf2_msgs/msg/TFMessagePubSubTypes.h"
#include "vnsba/node/convert.hpp"
#include "vnsba/node/dds.hpp"
#include "vnsba/node/reply_gate.hpp"
#include "vnsba/node/requests.hpp"
#include "vnsba/node/security.hpp"
#include "vnsba/node/slice_slot.hpp"
#include "vnsba/node/time_source.hpp"
#include "vnsba/node/transforms.hpp"
#include "vnsba_msgs/msg/PlanRequestPubSubTypes.h"
#include "vnsba_msgs/msg/PlanStatusPubSubTypes.h"
#include "vnsba_msgs/msg/PlannerDebugPubSubTypes.h"

namespace vnsba::node {

namespace {

using Clock = std::chrono::steady_clock;

// Answers a robot may owe at once beyond its queue: statuses planned but not yet handed to DDS
// (held for a requester's reader, or waiting for room in the status writer's history). Past
// queue_capacity + this, the node stops taking that robot's requests until answers go out.
constexpr size_t kAnswerBacklog = 1024;
// How long stop() waits, in all, for the statuses it still owes to be written and acknowledged.
constexpr std::chrono::seconds kDrainTimeout{10};

// Names a PubSubType in a generic lambda's argument.
template <class T>
struct TypeTag {
  using type = T;
};

// A map as the worker plans on it. The map thread builds the planner with the grid, so that its
// search arrays (both directions, tens of bytes per cell) are allocated before the map goes live,
// not in the first plan on it (about 230 ms at 4096 x 4096, which would also delay that plan's
// cancel). A plan holds its ActiveMap until it is answered: a plan in flight finishes on the
// map, and the planner, it started with.
struct ActiveMap {
  std::shared_ptr<const core::GridMap> grid;
  TimeMsg stamp;
  // One per planning worker, each used by its worker only (a Planner is not thread-safe). Null
  // only after an internal error dropped it (see worker_loop); the worker then builds a fresh one.
  mutable std::vector<std::unique_ptr<core::Planner>> planners;
};

}  // namespace

class PlannerNode::Impl {
 public:
  explicit Impl(NodeConfig config) : cfg_(std::move(config)) {}

  core::Status start();
  void stop();

  NodeConfig cfg_;
  const int workers_ = planning_workers(cfg_);
  // Declared before the participant, which calls it, so that it is destroyed after it.
  std::unique_ptr<ParticipantWatch> participant_watch_;
  std::unique_ptr<Participant> participant_;
  std::vector<std::unique_ptr<TakingListener>> listeners_;

  // The node's clock (use_sim_time) and, with robot_pose_source tf, the transforms received.
  TimeSource time_{cfg_.use_sim_time};
  std::mutex tf_mutex_;
  TransformTree transforms_;         // under tf_mutex_
  std::set<std::string> tf_warned_;  // refused transforms already logged, under tf_mutex_
  void on_transforms(const TFMessageMsg& msg, bool is_static);

  // A status held until the requester's status reader is matched (reply_gate.hpp), written by
  // the replier thread.
  struct HeldStatus {
    PlanStatusMsg msg;
    std::string what;     // for the error log
    bool answer = false;  // a request's answer (counted in Robot::unanswered), not a map report
  };

  // One robot the node serves: its topics (robot_view), writers, request queue, pose and held
  // statuses. Without `robots` there is one, under the node's own namespace.
  struct Robot {
    Robot(const NodeConfig& node, std::string robot_name)
        : name(std::move(robot_name)),
          cfg(robot_view(node, name)),
          // With several robots on one tf tree each has its own frames: "<robot>/base_link".
          base_frame(name.empty() ? node.base_frame : name + "/" + node.base_frame),
          replies(node.reply_wait, kReaderSettle),
          queue(static_cast<size_t>(node.queue_capacity), node.preempt) {}
    const std::string name;  // "" without `robots`
    const NodeConfig cfg;    // the node's, with the robot's namespace
    const std::string base_frame;
    dds::DataWriter* plan_writer = nullptr;
    dds::DataWriter* status_writer = nullptr;
    dds::DataWriter* debug_writer = nullptr;  // null with debug.publish: never (as every layer)
    // The debug layers in stock ROS 2 types, for rviz2.
    dds::DataWriter* raw_path_writer = nullptr;
    dds::DataWriter* pruned_path_writer = nullptr;
    dds::DataWriter* expansions_forward_writer = nullptr;
    dds::DataWriter* expansions_backward_writer = nullptr;
    dds::DataWriter* meeting_point_writer = nullptr;
    std::unique_ptr<dds::DataWriterListener> status_readers;  // feeds `replies` its matches
    ReplyGate<HeldStatus> replies;                            // under reply_mutex_
    RequestQueue queue;                                       // under queue_mutex_
    uint64_t goal_counter = 0;                                // under queue_mutex_
    std::mutex pose_mutex;
    std::optional<PoseStampedMsg> robot_pose;  // under pose_mutex
    // Requests taken from the bus whose status has not been handed to DDS yet (queued, planned,
    // waiting for a map, held for the requester's reader, or waiting for room in the status
    // writer's history). Past queue_capacity + kAnswerBacklog the request and goal readers
    // stop taking (input_paused) until answers go out: the bus holds the rest, not the node.
    std::atomic<size_t> unanswered{0};
    std::atomic<bool> input_paused{false};
    // This robot's request and goal readers, to take from again once there is room.
    std::vector<std::pair<TakingListener*, dds::DataReader*>> inputs;
    // Statuses released by `replies` and not yet accepted by the status writer, in order. The
    // replier thread's alone.
    std::deque<HeldStatus> unwritten;
    // Nav2's compute_path_to_pose and compute_path_through_poses (actions.enabled).
    std::vector<std::unique_ptr<ActionServer>> actions;
    std::string topic(const std::string& configured) const {
      return dds_topic_name(cfg, configured);
    }
    // In log lines: "" or " (robot robot7)".
    std::string label() const { return name.empty() ? "" : " (robot " + name + ")"; }
  };
  std::vector<std::unique_ptr<Robot>> robots_;
  core::Status add_robot_endpoints(Robot& robot);
  // replier_loop()'s steps.
  struct DueReplies;
  DueReplies take_due_replies(bool stopping);
  void forget_results_beyond_budget();
  size_t write_statuses(bool stopping, Clock::time_point drain_deadline);
  std::optional<ReplyGate<HeldStatus>::Clock::time_point> next_reply_deadline() const;
  // start()'s steps, in order.
  core::Status create_participant();
  template <class Tag>
  core::Status add_reader(Tag, const std::string& topic, const dds::DataReaderQos& qos,
                          std::unique_ptr<TakingListener> listener, Robot* input = nullptr);
  core::Status add_node_readers();
  core::Status add_robot_readers(Robot& robot);
  core::Status add_action_servers(Robot& robot);
  void log_started() const;

  std::mutex reply_mutex_;
  std::condition_variable reply_cv_;
  bool replier_stopping_ = false;  // under reply_mutex_
  // Set by stop() with replier_stopping_: statuses still unwritten then are given up (and
  // counted in the log), and the acknowledgement wait ends.
  Clock::time_point drain_deadline_ = Clock::time_point::max();
  std::thread replier_;
  std::atomic<uint64_t> replies_timed_out_{0};
  // Every robot's action servers, for the one budget of kept results (replier thread, under
  // reply_mutex_), and the results that budget made the node forget, with the last warning.
  std::vector<ActionServer*> all_action_servers_;
  uint64_t results_forgotten_for_budget_ = 0;
  Clock::time_point budget_warned_{};
  class StatusReaders;  // a status writer's listener
  void replier_loop();

  // Maps: the newest unconverted slice and the one being converted, and the active map.
  mutable std::mutex map_mutex_;
  mutable std::condition_variable map_cv_;
  SliceSlot slices_;
  std::shared_ptr<const ActiveMap> active_map_;

  // Requests: each robot's queue under one lock; workers take the robots in turn.
  std::mutex queue_mutex_;
  std::condition_variable queue_cv_;
  size_t next_robot_ = 0;  // where the next search for work starts, under queue_mutex_
  // A robot with a waiting request and none being planned (round robin), or null.
  Robot* robot_with_work();

  std::atomic<bool> stopping_{false};
  // From the start of stop(): every request taken is answered CANCELED at once, none queued, and
  // the readers are drained whatever the backlog.
  std::atomic<bool> refusing_requests_{false};
  // Whether robot may take another request now (see Robot::unanswered); marks it paused if not.
  bool may_take_request(Robot& robot);
  // Wakes the intake for a robot that is paused and has room again (replier thread).
  void resume_input(Robot& robot);
  // The intake thread: the one taker of every robot's requests and goals (TakeListener says
  // why not the DDS threads), woken by their arrival and by resume_input.
  std::mutex intake_mutex_;
  std::condition_variable intake_cv_;
  bool intake_pending_ = false;   // under intake_mutex_
  bool intake_stopping_ = false;  // under intake_mutex_
  std::thread intake_;
  void wake_intake();
  void intake_loop();
  // Takes what every robot's request and goal readers hold (as far as may_take_request allows).
  void take_inputs();
  // Requests that came before the first map, waiting for one at most requests.map_wait; under
  // map_mutex_. Answered NO_MAP by the map thread when their deadline passes.
  struct WaitingForMap {
    Robot* robot;
    Job job;
    Clock::time_point deadline;
  };
  std::deque<WaitingForMap> waiting_for_map_;
  bool started_ = false;
  std::vector<std::thread> worker_threads_;
  std::thread map_thread_;

  std::atomic<uint64_t> requests_received_{0}, statuses_published_{0}, maps_accepted_{0},
      maps_rejected_{0}, maps_superseded_{0}, plans_ok_{0};
  std::atomic<size_t> queue_peak_{0};

  // The DDS topic of the slices: one map for every robot, under the node's namespace.
  std::string map_topic() const { return dds_topic_name(cfg_, cfg_.topics.projected_map); }
  std::shared_ptr<const ActiveMap> current_map() const {
    std::lock_guard<std::mutex> lock(map_mutex_);
    return active_map_;
  }
  void on_request(Robot& robot, Job job);
  // A goal an action server accepted: checked like a request, then planned or answered.
  void on_action_goal(Robot& robot, ActionServer& server, ActionGoal&& goal);
  // Goals a client asked to cancel: waiting ones are answered CANCELED, a running one stops.
  void on_action_cancel(Robot& robot, ActionServer& server, const std::vector<GoalUuid>& ids);
  // An action goal's one result, instead of a plan_status (answer() calls it).
  void finish_action(Robot& robot, const Job& job, const WireStatus& status,
                     const core::Metrics* metrics, PathMsg path);
  // One plan (a request, or one leg of a ComputePathThroughPoses goal) on `map`.
  struct Leg {
    WireStatus status;
    std::string planner_name;
    core::PlanResult result;
    PathMsg path;          // set when status is OK
    bool planned = false;  // false: refused by resolve_request (result is empty)
  };
  Leg plan_leg(Robot& robot, Job& job, const ActiveMap& map, size_t worker);
  // on_request after counting: checks, then queues or answers.
  void submit(Robot& robot, Job job);
  // Answers NO_MAP the requests whose map_wait has passed (all with `all`); map thread and stop.
  void expire_waiting_for_map(bool all);
  void on_slice(OccupancyGridMsg&& msg);
  void on_goal(Robot& robot, PoseStampedMsg&& goal, const dds::SampleInfo& info);
  // The start of a goal_pose goal from robot_pose_source, or what is missing.
  void robot_start(Robot& robot, Job& job);
  void map_loop();
  // Converts one slice; returns what to report (OK when it went live).
  WireStatus convert_slice(SliceSlot::Taken taken);
  void worker_loop(size_t worker);
  // Plans one job with the worker's planner; `map` is set to the map it plans on (the worker
  // drops its planner when the plan throws).
  void handle(Robot& robot, Job& job, std::shared_ptr<const ActiveMap>& map, size_t worker);
  // A request's one status, on its robot's topic.
  // `endpoints` and `map`, when given, are the start and goal the plan used (see to_status_msg).
  void answer(Robot& robot, const Job& job, const WireStatus& status,
              const std::string& planner = "", const core::Metrics* metrics = nullptr,
              const TimeMsg& map_stamp = TimeMsg(), PathMsg path = PathMsg(),
              const core::Endpoints* endpoints = nullptr, const core::GridMap* map = nullptr);
  // A report about a slice (SUBJECT_MAP), on every robot's status topic.
  void report_map(const WireStatus& status, const TimeMsg& map_stamp);
  // Hands a status to the replier; `requester` (a plan_request's client) gates it.
  // `is_answer`: a request's status (counted in Robot::unanswered until written).
  void write_status(Robot& robot, PlanStatusMsg&& msg, const std::string& what, bool is_answer,
                    std::optional<GuidPrefix> requester = std::nullopt);
  // Whether to publish on a debug writer now (debug.publish: auto = while a reader is matched).
  bool publishing(dds::DataWriter* writer) const;
  void publish_debug(Robot& robot, const std::string& id, const core::PlanResult& result,
                     const core::GridMap& map, const TimeMsg& stamp);
  // What makes a remote endpoint on `topic` match the node's, for the incompatible-QoS warning.
  std::string qos_fix(const std::string& topic, const std::string& policy) const;
};

std::string PlannerNode::Impl::qos_fix(const std::string& topic, const std::string& policy) const {
  if (topic == dds_topic_name(cfg_, cfg_.topics.projected_map)) {
    if (policy == "DURABILITY" && cfg_.map_durability == MapDurability::kTransientLocal)
      return "the map publisher is volatile: set map.durability: volatile in the node's config";
    return "the node reads maps reliable, " +
           std::string(cfg_.map_durability == MapDurability::kVolatile ? "volatile"
                                                                       : "transient local") +
           " (map.durability)";
  }
  const std::pair<const std::string*, TopicQos> fixed[] = {
      {&cfg_.topics.goal_pose, TopicQos::kEvents},
      {&cfg_.topics.robot_pose, TopicQos::kLatest},
      {&cfg_.topics.plan_request, TopicQos::kEvents},
      {&cfg_.topics.plan, TopicQos::kLatest},
      {&cfg_.topics.plan_status, TopicQos::kStatus},
      {&cfg_.topics.planner_debug, TopicQos::kDebug},
      {&cfg_.topics.plan_raw, TopicQos::kLatched},
      {&cfg_.topics.plan_pruned, TopicQos::kLatched},
      {&cfg_.topics.expansions_forward, TopicQos::kLatched},
      {&cfg_.topics.expansions_backward, TopicQos::kLatched},
      {&cfg_.topics.meeting_point, TopicQos::kLatched},
      {&cfg_.topics.tf, TopicQos::kStream},
      {&cfg_.topics.tf_static, TopicQos::kStatic},
      {&cfg_.topics.clock, TopicQos::kStream}};
  for (const auto& robot : robots_)
    for (const auto& [configured, profile] : fixed)
      if (topic == robot->topic(*configured)) return "the node's endpoint is " + describe(profile);
  return "";
}

class PlannerNode::Impl::StatusReaders : public dds::DataWriterListener {
 public:
  StatusReaders(Impl& impl, Robot& robot) : impl_(impl), robot_(robot) {}
  void on_publication_matched(dds::DataWriter*,
                              const dds::PublicationMatchedStatus& status) override {
    if (status.current_count_change == 0) return;
    // An instance handle of an endpoint is its GUID: the first 12 bytes are the participant's.
    GuidPrefix prefix;
    for (size_t i = 0; i < prefix.size(); ++i) prefix[i] = status.last_subscription_handle.value[i];
    {
      std::lock_guard<std::mutex> lock(impl_.reply_mutex_);
      robot_.replies.reader_matched(prefix, status.current_count_change);
    }
    impl_.reply_cv_.notify_all();
  }

 private:
  Impl& impl_;
  Robot& robot_;
};

// ---------------------------------------------------------------------------------------------
// Start and stop.

core::Status PlannerNode::Impl::add_robot_endpoints(Robot& robot) {
  // Writers first, so that every request read can be answered.
  using PathType = nav_msgs::msg::dds_::Path_PubSubType;
  using GridType = nav_msgs::msg::dds_::OccupancyGrid_PubSubType;
  using PoseType = geometry_msgs::msg::dds_::PoseStamped_PubSubType;
  auto plan_writer = participant_->writer_on<PathType>(robot.topic(cfg_.topics.plan),
                                                       writer_qos(TopicQos::kLatest, false));
  if (!plan_writer) return plan_writer.error();
  robot.plan_writer = *plan_writer;
  robot.status_readers = std::make_unique<StatusReaders>(*this, robot);
  auto status_writer = participant_->writer_on<vnsba_msgs::msg::dds_::PlanStatus_PubSubType>(
      robot.topic(cfg_.topics.plan_status), writer_qos(TopicQos::kStatus, false),
      robot.status_readers.get());
  if (!status_writer) return status_writer.error();
  robot.status_writer = *status_writer;
  // debug.publish: never creates no debug endpoint at all (a fleet's discovery traffic).
  if (cfg_.debug != DebugPublishing::kNever) {
    auto debug_writer = participant_->writer_on<vnsba_msgs::msg::dds_::PlannerDebug_PubSubType>(
        robot.topic(cfg_.topics.planner_debug), writer_qos(TopicQos::kDebug, true));
    if (!debug_writer) return debug_writer.error();
    robot.debug_writer = *debug_writer;
    // The debug layers keep their last sample (transient local, keep last 1): an rviz2 display
    // opened after a run still shows it, whatever durability it asks for.
    const dds::DataWriterQos layer_qos = writer_qos(TopicQos::kLatched, true);
    auto add_layer = [&](auto type, const std::string& topic, dds::DataWriter*& out) {
      auto writer =
          participant_->writer_on<typename decltype(type)::type>(robot.topic(topic), layer_qos);
      if (writer) out = *writer;
      return writer ? core::Status::ok() : writer.error();
    };
    // In order, stopping at the first failure.
    core::Status layers =
        add_layer(TypeTag<PathType>(), cfg_.topics.plan_raw, robot.raw_path_writer);
    if (layers.is_ok())
      layers = add_layer(TypeTag<PathType>(), cfg_.topics.plan_pruned, robot.pruned_path_writer);
    if (layers.is_ok())
      layers = add_layer(TypeTag<GridType>(), cfg_.topics.expansions_forward,
                         robot.expansions_forward_writer);
    if (layers.is_ok())
      layers = add_layer(TypeTag<GridType>(), cfg_.topics.expansions_backward,
                         robot.expansions_backward_writer);
    if (layers.is_ok())
      layers = add_layer(TypeTag<geometry_msgs::msg::dds_::PointStamped_PubSubType>(),
                         cfg_.topics.meeting_point, robot.meeting_point_writer);
    if (!layers.is_ok()) return layers;
  }
  (void)sizeof(PoseType);
  return core::Status::ok();
}

core::Status PlannerNode::Impl::start() {
  if (core::Status s = create_participant(); !s.is_ok()) return s;
  // Writers first, so that every request read can be answered.
  for (const auto& robot : robots_)
    if (core::Status s = add_robot_endpoints(*robot); !s.is_ok()) return s;
  // Then the readers: the node's own, then each robot's and its action servers.
  if (core::Status s = add_node_readers(); !s.is_ok()) return s;
  for (const auto& robot : robots_) {
    if (core::Status s = add_robot_readers(*robot); !s.is_ok()) return s;
    if (cfg_.actions.enabled)
      if (core::Status s = add_action_servers(*robot); !s.is_ok()) return s;
  }
  if (cfg_.map_cost_source == MapCostSource::kCostmap)
    spdlog::info(
        "map.cost_source costmap: slices are Nav2 costmaps, planned on as they are (99 and 100 "
        "blocked, 1..98 costs); occupied_threshold, robot_radius and inflation_radius not applied");
  // The threads start once every entity exists: the replier walks each robot's action servers and
  // the intake each robot's inputs, and neither list changes from here until stop(). What arrived
  // while the readers were made waits in them (the intake listeners only set intake_pending_, and
  // the slice for the map thread is kept under map_mutex_); the intake starts last, once whatever
  // it hands on can be planned and answered.
  replier_ = std::thread([this] { replier_loop(); });
  map_thread_ = std::thread([this] { map_loop(); });
  for (int w = 0; w < workers_; ++w)
    worker_threads_.emplace_back([this, w] { worker_loop(static_cast<size_t>(w)); });
  intake_ = std::thread([this] { intake_loop(); });
  started_ = true;
  log_started();
  return core::Status::ok();
}

// The robots, the watch on other writers of our status topics, and the participant.
core::Status PlannerNode::Impl::create_participant() {
  if (cfg_.robots.empty()) {
    robots_.push_back(std::make_unique<Robot>(cfg_, ""));
  } else {
    for (const std::string& robot : cfg_.robots)
      robots_.push_back(std::make_unique<Robot>(cfg_, robot));
  }
  std::set<std::string> status_topics;
  for (const auto& robot : robots_) status_topics.insert(robot->topic(cfg_.topics.plan_status));
  // Two nodes on one domain and topics answer every request twice: say so (issue 13).
  participant_watch_ = std::make_unique<ParticipantWatch>(
      status_topics,
      [this](const std::string& who, const std::string& guid) {
        spdlog::warn(
            "another participant ('{}', GUID prefix {}) also writes a plan_status topic of this "
            "node ('{}'{}): every request there gets one answer from each; give each node its own "
            "domain_id, topics or robots",
            printable(who), guid, robots_.front()->topic(cfg_.topics.plan_status),
            robots_.size() > 1 ? " or another robot's" : "");
      },
      [this](const std::string& topic, const std::string& policy) {
        return qos_fix(topic, policy);
      });
  auto participant =
      Participant::create(cfg_.domain_id, "vnsba_node", participant_watch_.get(),
                          cfg_.localhost_only, with_default_enclave(cfg_.security, kNodeEnclave),
                          cfg_.discovery_servers, cfg_.participant_profile);
  if (!participant) return participant.error();
  participant_ = std::move(participant).value();
  return core::Status::ok();
}

// A reader whose listener lives in listeners_ until stop(). `topic` is the DDS name. `input`, when
// given, is the robot whose requests the reader carries (Robot::inputs).
template <class Tag>
core::Status PlannerNode::Impl::add_reader(Tag, const std::string& topic,
                                           const dds::DataReaderQos& qos,
                                           std::unique_ptr<TakingListener> listener, Robot* input) {
  listeners_.push_back(std::move(listener));
  auto reader = participant_->reader_on<typename Tag::type>(topic, qos, listeners_.back().get());
  if (!reader) return reader.error();
  if (input != nullptr) input->inputs.emplace_back(listeners_.back().get(), *reader);
  return core::Status::ok();
}

// The readers of the node as a whole: the clock, the map, the transforms.
core::Status PlannerNode::Impl::add_node_readers() {
  auto name = [&](const std::string& topic) { return dds_topic_name(cfg_, topic); };
  // The clock first, so that the first goal already has the simulation's time.
  if (cfg_.use_sim_time) {
    if (core::Status s =
            add_reader(TypeTag<rosgraph_msgs::msg::dds_::Clock_PubSubType>(),
                       name(cfg_.topics.clock), reader_qos(TopicQos::kStream),
                       make_listener<ClockMsg>([this](ClockMsg&& m, const dds::SampleInfo&) {
                         // A clock gone back (a simulation reset): transforms stamped in the
                         // old timeline would all be "from the future", so they go, as in ROS.
                         if (time_.set_sim_time(m.clock()) == ClockUpdate::kJumpedBack) {
                           std::lock_guard<std::mutex> lock(tf_mutex_);
                           transforms_.clear_dynamic();
                         }
                       }));
        !s.is_ok())
      return s;
  }
  // One map for every robot, under the node's namespace.
  dds::DataReaderQos slice_qos = reader_qos(TopicQos::kLatched);
  if (cfg_.map_durability == MapDurability::kVolatile)
    slice_qos.durability().kind = dds::VOLATILE_DURABILITY_QOS;
  if (core::Status s = add_reader(
          TypeTag<nav_msgs::msg::dds_::OccupancyGrid_PubSubType>(), name(cfg_.topics.projected_map),
          slice_qos,
          make_listener<OccupancyGridMsg>(
              [this](OccupancyGridMsg&& m, const dds::SampleInfo&) { on_slice(std::move(m)); }));
      !s.is_ok())
    return s;
  // The robots' poses before the goals, so that a goal never waits for a reader created after it.
  if (cfg_.robot_pose_source == RobotPoseSource::kTf) {
    for (const bool is_static : {true, false}) {
      if (core::Status s =
              add_reader(TypeTag<tf2_msgs::msg::dds_::TFMessage_PubSubType>(),
                         name(is_static ? cfg_.topics.tf_static : cfg_.topics.tf),
                         reader_qos(is_static ? TopicQos::kStatic : TopicQos::kStream),
                         make_listener<TFMessageMsg>(
                             [this, is_static](TFMessageMsg&& m, const dds::SampleInfo&) {
                               on_transforms(m, is_static);
                             }));
          !s.is_ok())
        return s;
    }
  }
  return core::Status::ok();
}

// A robot's readers: its pose (unless the transforms give it), its goals and its requests.
core::Status PlannerNode::Impl::add_robot_readers(Robot& robot) {
  using PoseType = geometry_msgs::msg::dds_::PoseStamped_PubSubType;
  core::Status pose_status = core::Status::ok();
  if (cfg_.robot_pose_source == RobotPoseSource::kTf) {
    // Read by add_node_readers, once for every robot.
  } else if (cfg_.robot_pose_type == RobotPoseType::kPoseWithCovarianceStamped) {
    pose_status =
        add_reader(TypeTag<geometry_msgs::msg::dds_::PoseWithCovarianceStamped_PubSubType>(),
                   robot.topic(cfg_.topics.robot_pose), reader_qos(TopicQos::kLatest),
                   make_listener<PoseWithCovarianceStampedMsg>(
                       [&robot](PoseWithCovarianceStampedMsg&& m, const dds::SampleInfo&) {
                         std::lock_guard<std::mutex> lock(robot.pose_mutex);
                         robot.robot_pose = to_pose_stamped(m);
                       }));
  } else {
    pose_status = add_reader(
        TypeTag<PoseType>(), robot.topic(cfg_.topics.robot_pose), reader_qos(TopicQos::kLatest),
        make_listener<PoseStampedMsg>([&robot](PoseStampedMsg&& m, const dds::SampleInfo&) {
          std::lock_guard<std::mutex> lock(robot.pose_mutex);
          robot.robot_pose = std::move(m);
        }));
  }
  if (!pose_status.is_ok()) return pose_status;
  // Goals and requests: taken only while the robot has room for their answers.
  auto has_room = [this, &robot] { return may_take_request(robot); };
  auto wake = [this] { wake_intake(); };
  if (core::Status s = add_reader(
          TypeTag<PoseType>(), robot.topic(cfg_.topics.goal_pose), reader_qos(TopicQos::kEvents),
          make_intake_listener<PoseStampedMsg>(
              [this, &robot](PoseStampedMsg&& m, const dds::SampleInfo& info) {
                on_goal(robot, std::move(m), info);
              },
              has_room, wake),
          &robot);
      !s.is_ok())
    return s;
  if (core::Status s =
          add_reader(TypeTag<vnsba_msgs::msg::dds_::PlanRequest_PubSubType>(),
                     robot.topic(cfg_.topics.plan_request), reader_qos(TopicQos::kEvents),
                     make_intake_listener<PlanRequestMsg>(
                         [this, &robot](PlanRequestMsg&& m, const dds::SampleInfo& info) {
                           Job job;
                           job.id = std::move(m.id());
                           job.identity = identity_of(info, wire::SUBJECT_REQUEST);
                           job.start = std::move(m.start());
                           job.goal = std::move(m.goal());
                           job.planner = std::move(m.planner());
                           on_request(robot, std::move(job));
                         },
                         has_room, wake),
                     &robot);
      !s.is_ok())
    return s;
  return core::Status::ok();
}

// A robot's Nav2 action servers, one per action (nav2_actions()).
core::Status PlannerNode::Impl::add_action_servers(Robot& robot) {
  auto has_room = [this, &robot] { return may_take_request(robot); };
  auto wake = [this] { wake_intake(); };
  for (const Nav2ActionInfo& action : nav2_actions()) {
    const ActionKind kind = action.kind;
    const std::string& action_name = cfg_.topics.*action.topic;
    ActionServer::Hooks hooks;
    hooks.on_goal = [this, &robot](ActionServer& server, ActionGoal&& goal) {
      on_action_goal(robot, server, std::move(goal));
    };
    hooks.on_cancel = [this, &robot](ActionServer& server, const std::vector<GoalUuid>& ids) {
      on_action_cancel(robot, server, ids);
    };
    hooks.may_take = has_room;
    hooks.wake_intake = wake;
    hooks.now = [this] { return time_.now(); };
    auto server = std::make_unique<ActionServer>(kind, ros_topic_name(robot.cfg, action_name),
                                                 robot.cfg, participant_watch_.get(), reply_mutex_,
                                                 reply_cv_, std::move(hooks));
    const core::Status created = server->create(*participant_, listeners_, robot.inputs);
    // Kept even when create() failed: the listeners it made may call it until stop().
    if (created.is_ok()) all_action_servers_.push_back(server.get());
    robot.actions.push_back(std::move(server));
    if (!created.is_ok()) return created;
  }
  return core::Status::ok();
}

void PlannerNode::Impl::log_started() const {
  auto name = [&](const std::string& topic) { return dds_topic_name(cfg_, topic); };
  const Robot& first = *robots_.front();
  if (robots_.size() == 1) {
    spdlog::info("vnsba_node up on domain {}: slices on '{}', requests on '{}', goals on '{}'",
                 cfg_.domain_id, name(cfg_.topics.projected_map),
                 first.topic(cfg_.topics.plan_request), first.topic(cfg_.topics.goal_pose));
  } else {
    spdlog::info(
        "vnsba_node up on domain {}: slices on '{}', {} robots ('{}' ... '{}'), {} planning "
        "workers",
        cfg_.domain_id, name(cfg_.topics.projected_map), robots_.size(),
        first.topic(cfg_.topics.plan_request), robots_.back()->topic(cfg_.topics.plan_request),
        workers_);
  }
}

void PlannerNode::Impl::stop() {
  // Every request taken from here on is answered CANCELED at once; what the readers still hold
  // (taken by the DDS threads as it comes, or left by a paused robot) is taken and answered so,
  // then the readers go: nothing the bus delivered goes unanswered.
  refusing_requests_ = true;
  {
    std::lock_guard<std::mutex> lock(intake_mutex_);
    intake_stopping_ = true;
    intake_pending_ = true;  // one last pass, whatever the backlog
  }
  intake_cv_.notify_one();
  if (intake_.joinable()) intake_.join();
  take_inputs();  // what came during that pass (DDS threads only wake the intake: no deadlock)
  if (participant_) participant_->delete_readers();  // no new input from here on
  stopping_ = true;
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    for (const auto& robot : robots_) robot->queue.interrupt_current("node is shutting down");
  }
  queue_cv_.notify_all();
  {
    // Under the map lock, so that the map thread cannot miss it between its check and its wait.
    std::lock_guard<std::mutex> lock(map_mutex_);
  }
  map_cv_.notify_all();
  // The map thread first: a map it installs now hands the requests that waited for it on
  // (submit answers them CANCELED from here on), so none can reach a queue no worker reads.
  if (map_thread_.joinable()) map_thread_.join();
  for (std::thread& worker : worker_threads_)
    if (worker.joinable()) worker.join();  // answers every queued request first
  worker_threads_.clear();
  expire_waiting_for_map(/*all=*/true);
  const Clock::time_point drain_deadline = Clock::now() + kDrainTimeout;
  {
    std::lock_guard<std::mutex> lock(reply_mutex_);
    replier_stopping_ = true;
    drain_deadline_ = drain_deadline;
  }
  reply_cv_.notify_all();
  if (replier_.joinable()) replier_.join();  // writes every status still held
  // Written is not delivered: a reader that lost a packet needs it again, and deleting the
  // writer would take the status with it (a SIGTERM mid-burst lost 226 of one client's 1,764).
  // Wait for every reader's acknowledgement of every status and action reply, within the
  // drain's bound.
  auto acknowledged = [&](dds::DataWriter* writer) {
    const auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(
        std::max(Clock::duration::zero(), drain_deadline - Clock::now()));
    const auto seconds = std::chrono::duration_cast<std::chrono::seconds>(left);
    const eprosima::fastrtps::Duration_t wait(static_cast<int32_t>(seconds.count()),
                                              static_cast<uint32_t>((left - seconds).count()));
    return writer->wait_for_acknowledgments(wait) == ReturnCode_t::RETCODE_OK;
  };
  for (const auto& robot : robots_) {
    if (robot->status_writer == nullptr || !started_) continue;
    bool all = acknowledged(robot->status_writer);
    for (const auto& action : robot->actions)
      for (dds::DataWriter* writer : action->reply_writers())
        if (writer != nullptr) all = acknowledged(writer) && all;
    if (!all)
      spdlog::warn(
          "shutdown{}: statuses or action replies written but not acknowledged by every reader "
          "within the drain's {} s",
          robot->label(), kDrainTimeout.count());
  }
  if (participant_) participant_->shutdown();
  participant_.reset();
  // The writers were deleted with the participant; the listeners go after it.
  robots_.clear();
  listeners_.clear();
}

// ---------------------------------------------------------------------------------------------
// Input (DDS listener threads): cheap, never plans.

void PlannerNode::Impl::on_slice(OccupancyGridMsg&& msg) {
  SliceSlot::PutResult put;
  {
    std::lock_guard<std::mutex> lock(map_mutex_);
    put = slices_.put(std::move(msg));  // only the newest slice matters
  }
  if (put.superseded_converting)
    spdlog::info("a newer slice arrived: the conversion in progress stops");
  map_cv_.notify_all();
}

void PlannerNode::Impl::on_goal(Robot& robot, PoseStampedMsg&& goal, const dds::SampleInfo& info) {
  Job job;
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    job.id = "goal-" + std::to_string(++robot.goal_counter);
  }
  job.identity = identity_of(info, wire::SUBJECT_GOAL_POSE);
  job.goal = std::move(goal);
  robot_start(robot, job);
  on_request(robot, std::move(job));
}

void PlannerNode::Impl::robot_start(Robot& robot, Job& job) {
  if (cfg_.robot_pose_source == RobotPoseSource::kTopic) {
    std::lock_guard<std::mutex> lock(robot.pose_mutex);
    if (robot.robot_pose) {
      job.start = *robot.robot_pose;
    } else {
      job.missing_start =
          "start: no robot_pose received yet on '" + robot.topic(cfg_.topics.robot_pose) + "'";
    }
    return;
  }
  TransformTree::Lookup found;
  {
    std::lock_guard<std::mutex> lock(tf_mutex_);
    found = transforms_.lookup(cfg_.frame_id, robot.base_frame, time_.now_seconds(),
                               cfg_.transform_tolerance_s);
  }
  if (!found.ok) {
    job.missing_start = "start (robot_pose_source tf, '" + dds_topic_name(cfg_, cfg_.topics.tf) +
                        "' and '" + dds_topic_name(cfg_, cfg_.topics.tf_static) +
                        "'): " + found.problem;
    return;
  }
  const Eigen::Vector3d t = found.source_in_target.translation();
  const Eigen::Quaterniond q(found.source_in_target.rotation());
  job.start.header().frame_id(cfg_.frame_id);
  job.start.header().stamp(time_.now());
  job.start.pose().position().x(t.x());
  job.start.pose().position().y(t.y());
  job.start.pose().position().z(t.z());
  job.start.pose().orientation().x(q.x());
  job.start.pose().orientation().y(q.y());
  job.start.pose().orientation().z(q.z());
  job.start.pose().orientation().w(q.w());
}

void PlannerNode::Impl::on_transforms(const TFMessageMsg& msg, bool is_static) {
  std::vector<std::string> refused;
  {
    std::lock_guard<std::mutex> lock(tf_mutex_);
    refused = add_transforms(msg, is_static, transforms_);
    // Each distinct problem once (a broadcaster repeats a bad transform at its rate), and a
    // bounded number of them.
    refused.erase(std::remove_if(refused.begin(), refused.end(),
                                 [&](const std::string& problem) {
                                   return tf_warned_.size() >= 100 ||
                                          !tf_warned_.insert(problem).second;
                                 }),
                  refused.end());
  }
  for (const std::string& problem : refused)
    spdlog::warn("'{}': refused {}",
                 dds_topic_name(cfg_, is_static ? cfg_.topics.tf_static : cfg_.topics.tf), problem);
}

bool PlannerNode::Impl::may_take_request(Robot& robot) {
  if (refusing_requests_) return true;  // answered at once, and everything must be taken
  const size_t room = static_cast<size_t>(cfg_.queue_capacity) + kAnswerBacklog;
  if (robot.unanswered < room) return true;
  robot.input_paused = true;
  // Answers that went out between the check and the flag found it unset: look again.
  if (robot.unanswered < room) {
    robot.input_paused = false;
    return true;
  }
  return false;
}

void PlannerNode::Impl::resume_input(Robot& robot) {
  if (!robot.input_paused) return;
  if (robot.unanswered >= static_cast<size_t>(cfg_.queue_capacity) + kAnswerBacklog) return;
  robot.input_paused = false;
  wake_intake();
}

void PlannerNode::Impl::wake_intake() {
  {
    std::lock_guard<std::mutex> lock(intake_mutex_);
    intake_pending_ = true;
  }
  intake_cv_.notify_one();
}

void PlannerNode::Impl::take_inputs() {
  for (const auto& robot : robots_)
    for (const auto& [listener, reader] : robot->inputs) listener->take_available(reader);
}

void PlannerNode::Impl::intake_loop() {
  std::unique_lock<std::mutex> lock(intake_mutex_);
  for (;;) {
    intake_cv_.wait(lock, [&] { return intake_pending_ || intake_stopping_; });
    if (!intake_pending_) return;  // stopping, and nothing arrived since the last pass
    intake_pending_ = false;
    lock.unlock();
    take_inputs();
    lock.lock();
  }
}

void PlannerNode::Impl::on_request(Robot& robot, Job job) {
  ++requests_received_;
  ++robot.unanswered;  // until its status is handed to DDS (replier_loop)
  submit(robot, std::move(job));
}

// The queue's id of an action goal: the action and the goal's id, whatever the namespace (a
// long namespace once made it longer than a request id may be, and every goal failed).
std::string action_job_id(const ActionServer& server, const GoalUuid& id) {
  return std::string(nav2_action(server.kind()).id_name) + ":" + uuid_text(id);
}

// The fewest poses a path through `goals` from `start` can have at `spacing` metres: the straight
// lines between them (a path is never shorter), one pose per spacing and one at each end.
double fewest_poses(const std::vector<PoseStampedMsg>& goals, const PoseStampedMsg* start,
                    double spacing) {
  double length = 0.0;
  const PoseStampedMsg* from = start;
  for (const PoseStampedMsg& to : goals) {
    if (from != nullptr) {
      const double dx = to.pose().position().x() - from->pose().position().x();
      const double dy = to.pose().position().y() - from->pose().position().y();
      if (std::isfinite(dx) && std::isfinite(dy)) length += std::hypot(dx, dy);
    }
    from = &to;
  }
  return std::floor(length / spacing) + 1.0;
}

void PlannerNode::Impl::on_action_goal(Robot& robot, ActionServer& server, ActionGoal&& goal) {
  Job job;
  job.id = action_job_id(server, goal.id);
  job.identity = goal.identity;
  job.planner = std::move(goal.planner_id);
  job.action = std::make_shared<ActionJob>();
  job.action->server = &server;
  job.action->goal_id = goal.id;
  ++requests_received_;
  ++robot.unanswered;  // until its result is stored (finish_action)
  // Checked before the request rules: Nav2's own codes for these.
  const size_t poses = goal.goals.size();
  const size_t max_poses = static_cast<size_t>(cfg_.actions.max_goal_poses);
  std::string refused;
  if (poses == 0) {
    refused = "goals: empty (NO_VIAPOINTS_GIVEN)";
  } else if (poses > max_poses) {
    refused = "goals: found " + std::to_string(poses) + " poses, expected at most " +
              std::to_string(max_poses) + " (actions.max_goal_poses)";
  } else if (const std::shared_ptr<const ActiveMap> map = current_map()) {
    // A result that cannot fit actions.max_result_poses is refused before any planning.
    const double spacing = std::max(cfg_.planner.path_spacing_for(map->grid->resolution()),
                                    min_path_spacing(map->grid->resolution()));
    const double fewest = fewest_poses(goal.goals, goal.use_start ? &goal.start : nullptr, spacing);
    if (fewest > cfg_.actions.max_result_poses) {
      refused = fmt::format(
          "goals: a path through them needs at least {:.0f} poses at {:g} m apart (the straight "
          "lines between them), more than actions.max_result_poses ({})",
          fewest, spacing, cfg_.actions.max_result_poses);
    }
  }
  if (!refused.empty()) {
    ActionOutcome outcome;
    outcome.state = GoalState::kAborted;
    outcome.error_code = poses == 0 ? kNoViapointsGiven
                                    : nav2_error_code(server.kind(), wire::INVALID_REQUEST, false);
    outcome.error_msg = refused;
    spdlog::warn("goal '{}'{}: ABORTED ({})", job.id, robot.label(), outcome.error_msg);
    server.execute(goal.id);  // rcl_action: ACCEPTED -> EXECUTING -> ABORTED
    server.finish(goal.id, std::move(outcome));
    --robot.unanswered;
    ++statuses_published_;
    return;
  }
  job.goal = std::move(goal.goals.front());
  job.action->more_goals.assign(std::make_move_iterator(goal.goals.begin() + 1),
                                std::make_move_iterator(goal.goals.end()));
  if (goal.use_start) {
    job.start = std::move(goal.start);
  } else {
    robot_start(robot, job);  // robot_pose_source: the topic or tf
    job.action->tf_problem =
        !job.missing_start.empty() && cfg_.robot_pose_source == RobotPoseSource::kTf;
  }
  submit(robot, std::move(job));
}

void PlannerNode::Impl::on_action_cancel(Robot& robot, ActionServer& server,
                                         const std::vector<GoalUuid>& ids) {
  std::vector<Job> removed;
  const std::string reason = "canceled by its client";
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    for (const GoalUuid& id : ids) {
      std::vector<Job> jobs = robot.queue.cancel(action_job_id(server, id), reason);
      for (Job& job : jobs) removed.push_back(std::move(job));
    }
  }
  {
    // A goal still waiting for the first map.
    std::lock_guard<std::mutex> lock(map_mutex_);
    for (auto it = waiting_for_map_.begin(); it != waiting_for_map_.end();) {
      const bool canceled = it->robot == &robot && it->job.action &&
                            it->job.action->server == &server &&
                            std::find(ids.begin(), ids.end(), it->job.action->goal_id) != ids.end();
      if (canceled) {
        removed.push_back(std::move(it->job));
        it = waiting_for_map_.erase(it);
      } else {
        ++it;
      }
    }
  }
  for (const Job& job : removed) {
    spdlog::info("goal '{}'{}: CANCELED ({})", job.id, robot.label(), reason);
    answer(robot, job, {wire::CANCELED, reason});
  }
}

void PlannerNode::Impl::finish_action(Robot& robot, const Job& job, const WireStatus& status,
                                      const core::Metrics* metrics, PathMsg path) {
  ActionServer& server = *job.action->server;
  ActionOutcome outcome;
  if (status.ok()) {
    outcome.state = GoalState::kSucceeded;
  } else if (status.code == wire::CANCELED && server.canceling(job.action->goal_id)) {
    outcome.state = GoalState::kCanceled;  // the client asked; otherwise (preempted, shutdown)
  } else {                                 // the goal is aborted, as Nav2's servers do
    outcome.state = GoalState::kAborted;
    server.execute(job.action->goal_id);  // rcl_action: from ACCEPTED only through EXECUTING
  }
  outcome.error_code = nav2_error_code(server.kind(), status.code, job.action->invalid_planner);
  if (!status.ok() && job.action->tf_problem)
    outcome.error_code = nav2_error_code(server.kind(), wire::FRAME_MISMATCH, false);
  // A success carries no error_msg, as Nav2's planner server's: what the plan's status message
  // says beside it (a goal moved by goal_tolerance, costs not applied) is in the log line of
  // the plan (handle) and on plan_status for plan_request clients.
  if (!status.ok()) outcome.error_msg = status.message;
  if (outcome.state == GoalState::kCanceled) outcome.error_code = 0;
  if (metrics != nullptr) outcome.planning_time_s = metrics->planning_time_us / 1e6;
  outcome.path = std::move(path);
  server.finish(job.action->goal_id, std::move(outcome));
  --robot.unanswered;
  resume_input(robot);
  ++statuses_published_;
}

void PlannerNode::Impl::expire_waiting_for_map(bool all) {
  std::vector<WaitingForMap> expired;
  {
    std::lock_guard<std::mutex> lock(map_mutex_);
    const Clock::time_point now = Clock::now();
    while (!waiting_for_map_.empty() && (all || waiting_for_map_.front().deadline <= now)) {
      expired.push_back(std::move(waiting_for_map_.front()));
      waiting_for_map_.pop_front();
    }
  }
  for (WaitingForMap& waiting : expired) {
    const std::string why =
        all && stopping_
            ? "node is shutting down before a map arrived"
            : fmt::format("no map received within requests.map_wait ({:g} s) on '{}'",
                          static_cast<double>(cfg_.map_wait.count()) / 1000.0, map_topic());
    const WireStatus status{all && stopping_ ? wire::CANCELED : wire::NO_MAP, why};
    spdlog::warn("request '{}'{}: {} ({})", printable(waiting.job.id), waiting.robot->label(),
                 code_name(status.code), status.message);
    answer(*waiting.robot, waiting.job, status);
  }
}

void PlannerNode::Impl::submit(Robot& robot, Job job) {
  if (refusing_requests_) {
    spdlog::info("request '{}'{}: CANCELED (node is shutting down)", printable(job.id),
                 robot.label());
    answer(robot, job, {wire::CANCELED, "node is shutting down"});
    return;
  }
  // Checked before it may touch anything: only a request that would be planned preempts,
  // replaces or queues (see requests.hpp). The worker checks again against its map.
  std::shared_ptr<const ActiveMap> map = current_map();
  // Before the first map, a request waits for one (requests.map_wait): a client that latches its
  // map and asks at once must not lose the race to its own map.
  if (!map && cfg_.map_wait.count() > 0) {
    std::unique_lock<std::mutex> lock(map_mutex_);
    if (!active_map_) {
      if (waiting_for_map_.empty()) {
        spdlog::info("request '{}'{}: no map yet; waiting up to requests.map_wait ({:g} s)",
                     printable(job.id), robot.label(),
                     static_cast<double>(cfg_.map_wait.count()) / 1000.0);
      }
      waiting_for_map_.push_back({&robot, std::move(job), Clock::now() + cfg_.map_wait});
      lock.unlock();
      map_cv_.notify_all();  // the map thread times the wait
      return;
    }
    map = active_map_;  // arrived meanwhile
  }
  const ResolvedRequest resolved =
      resolve_request(job, robot.cfg, map ? map->grid.get() : nullptr, map_topic());
  if (!resolved.status.ok()) {
    if (job.action) job.action->invalid_planner = resolved.invalid_planner;
    spdlog::warn("request '{}'{}: {} ({})", printable(job.id), robot.label(),
                 code_name(resolved.status.code), resolved.status.message);
    answer(robot, job, resolved.status, resolved.planner_name, nullptr,
           map ? map->stamp : TimeMsg());
    return;
  }
  std::vector<Job> canceled;
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    canceled = robot.queue.admit(std::move(job));
    queue_peak_ = std::max(queue_peak_.load(), robot.queue.waiting());
  }
  queue_cv_.notify_one();
  // Writers are thread-safe; these answers do not wait for the worker.
  // Out of the queue, nobody else reads or writes these any more: no lock for their reasons.
  for (const Job& old : canceled) {
    spdlog::info("request '{}'{}: CANCELED ({})", printable(old.id), robot.label(),
                 old.interruption->reason);
    answer(robot, old, {wire::CANCELED, old.interruption->reason});
  }
}

// ---------------------------------------------------------------------------------------------
// Map thread.

void PlannerNode::Impl::map_loop() {
  for (;;) {
    std::optional<SliceSlot::Taken> taken;
    {
      std::unique_lock<std::mutex> lock(map_mutex_);
      auto has_work = [&] { return stopping_ || slices_.has_waiting(); };
      // Requests waiting for a first map are answered NO_MAP when their wait is over.
      while (!has_work() && !waiting_for_map_.empty()) {
        if (map_cv_.wait_until(lock, waiting_for_map_.front().deadline, has_work)) break;
        lock.unlock();
        expire_waiting_for_map(/*all=*/false);
        lock.lock();
      }
      map_cv_.wait(lock, [&] { return has_work() || !waiting_for_map_.empty(); });
      if (stopping_) return;
      if (!slices_.has_waiting()) continue;  // a request came to wait for a map: time it
      taken = slices_.take();
    }
    const TimeMsg stamp = taken->slice.header().stamp();
    WireStatus status;
    try {
      status = convert_slice(std::move(*taken));
    } catch (const std::exception& e) {
      // Resource exhaustion, never bad input (that is refused before any allocation): refuse
      // this map, keep planning on the last one, and keep the thread alive.
      status = {wire::INTERNAL_ERROR, std::string("cannot convert the slice: ") + e.what()};
    }
    {
      std::lock_guard<std::mutex> lock(map_mutex_);
      slices_.finish(status.code != wire::CANCELED);
    }
    if (status.ok()) continue;
    if (status.code == wire::CANCELED) {
      ++maps_superseded_;
      spdlog::info("slice superseded by a newer one before its conversion finished");
    } else {
      ++maps_rejected_;
      spdlog::error("map rejected ({}): {}; keeping the previous map", code_name(status.code),
                    status.message);
    }
    // A report on the status topic (SUBJECT_MAP), so tools on the bus see it too.
    report_map(status, stamp);
  }
}

WireStatus PlannerNode::Impl::convert_slice(SliceSlot::Taken taken) {
  const auto t0 = Clock::now();
  const std::atomic<bool>* superseded = taken.superseded.get();
  const TimeMsg stamp = taken.slice.header().stamp();
  // Every check that bounds the conversion's cost (size against map.max_cells, robot_radius
  // against the map) comes before any allocation; the conversion is then linear in the cells.
  SliceCheck check = from_slice_msg(std::move(taken.slice), cfg_.frame_id, cfg_.map.max_cells);
  if (!check.status.ok()) return check.status;
  auto built = core::GridMap::build(check.grid, planning_grid_options(cfg_), superseded);
  if (!built) {
    return {to_wire_code(built.error().code),
            built.error().code == core::StatusCode::kCanceled
                ? "superseded by a newer slice while being converted"
                : built.error().message};
  }
  check.grid = core::OccupancyGrid();  // the raw values are not needed any more
  auto active = std::make_shared<ActiveMap>();
  active->grid = std::make_shared<const core::GridMap>(std::move(built).value());
  active->stamp = stamp;
  if (superseded->load())
    return {wire::CANCELED, "superseded by a newer slice while being converted"};
  size_t search_state_bytes = 0;
  try {
    for (int w = 0; w < workers_; ++w) {  // see ActiveMap
      active->planners.push_back(std::make_unique<core::Planner>(active->grid));
      search_state_bytes += active->planners.back()->search_state_bytes();
    }
  } catch (const std::exception& e) {
    return {wire::INTERNAL_ERROR,
            "cannot allocate the search state of " + std::to_string(active->grid->width()) + " x " +
                std::to_string(active->grid->height()) + " cells for " + std::to_string(workers_) +
                " planning worker(s) (requests.workers): " + e.what()};
  }
  const auto ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  spdlog::info(
      "map accepted: {} x {} cells at {} m, {} blocked, {:.1f} MB of search state ({} "
      "worker(s)), ready in {:.1f} ms",
      active->grid->width(), active->grid->height(), active->grid->resolution(),
      active->grid->blocked_count(), search_state_bytes / 1e6, workers_, ms);
  std::shared_ptr<const ActiveMap> previous;
  std::deque<WaitingForMap> waited;
  {
    std::lock_guard<std::mutex> lock(map_mutex_);
    previous = std::exchange(active_map_, std::move(active));
    waited.swap(waiting_for_map_);
  }
  map_cv_.notify_all();
  ++maps_accepted_;
  // The requests that waited for a first map, in arrival order, as if they came now.
  for (WaitingForMap& w : waited) submit(*w.robot, std::move(w.job));
  // The previous map and its planner go here, outside the lock, unless a plan still holds
  // them (then when that plan is answered).
  previous.reset();
  return {};
}

// ---------------------------------------------------------------------------------------------
// Worker thread: the only place that plans.

bool PlannerNode::Impl::publishing(dds::DataWriter* writer) const {
  if (writer == nullptr) return false;  // not created (debug.publish: never)
  switch (cfg_.debug) {
    case DebugPublishing::kAlways:
      return true;
    case DebugPublishing::kNever:
      return false;
    case DebugPublishing::kAuto:
      return matched_readers(writer) > 0;
  }
  return false;
}

void PlannerNode::Impl::publish_debug(Robot& robot, const std::string& id,
                                      const core::PlanResult& result, const core::GridMap& map,
                                      const TimeMsg& stamp) {
  const std::string& frame = cfg_.frame_id;
  auto write = [&](dds::DataWriter* writer, auto&& msg, const char* what) {
    if (!writer->write(&msg))
      spdlog::warn("could not publish the {} of '{}'{}", what, printable(id), robot.label());
  };
  if (result.metrics.expanded > 0 && publishing(robot.debug_writer))
    write(robot.debug_writer, to_debug_msg(echoed_id(id), result, map, frame, stamp), "debug");
  if (!result.raw_path.empty() && publishing(robot.raw_path_writer))
    write(robot.raw_path_writer, to_raw_path_msg(result, map, frame, stamp), "raw path");
  if (!result.waypoints.empty() && publishing(robot.pruned_path_writer))
    write(robot.pruned_path_writer, to_pruned_path_msg(result, map, frame, stamp), "pruned path");
  if (result.metrics.expanded > 0 && publishing(robot.expansions_forward_writer))
    write(robot.expansions_forward_writer,
          to_expansions_msg(result.expanded_forward, map, frame, stamp), "forward expansions");
  if (result.metrics.expanded > 0 && publishing(robot.expansions_backward_writer))
    write(robot.expansions_backward_writer,
          to_expansions_msg(result.expanded_backward, map, frame, stamp), "backward expansions");
  if (result.meeting_cell && publishing(robot.meeting_point_writer))
    write(robot.meeting_point_writer, to_point_msg(*result.meeting_cell, map, frame, stamp),
          "meeting point");
}

void PlannerNode::Impl::write_status(Robot& robot, PlanStatusMsg&& msg, const std::string& what,
                                     bool is_answer, std::optional<GuidPrefix> requester) {
  {
    std::lock_guard<std::mutex> lock(reply_mutex_);
    robot.replies.hold(requester, HeldStatus{std::move(msg), what, is_answer},
                       ReplyGate<HeldStatus>::Clock::now());
  }
  reply_cv_.notify_all();
}

// What one pass of the replier found due, under reply_mutex_.
struct PlannerNode::Impl::DueReplies {
  size_t timed_out = 0;    // statuses released after requests.reply_wait without their reader
  bool unwritten = false;  // some robot has statuses to write
  // The action servers' replies and status lists due now.
  std::vector<std::pair<ActionServer*, ActionServer::Due>> action_dues;
  // Status writers whose gate asked for a heartbeat (reply_gate.hpp: a fresh requester).
  std::vector<dds::DataWriter*> status_heartbeats;
};

PlannerNode::Impl::DueReplies PlannerNode::Impl::take_due_replies(bool stopping) {
  using ReplyClock = ReplyGate<HeldStatus>::Clock;
  // At shutdown everything still held goes out at once: nothing accepted is lost.
  const ReplyClock::time_point now = stopping ? ReplyClock::time_point::max() : ReplyClock::now();
  DueReplies due;
  for (const auto& robot : robots_) {
    bool heartbeat = false;
    for (HeldStatus& held : robot->replies.release(now, &due.timed_out, &heartbeat))
      robot->unwritten.push_back(std::move(held));
    if (heartbeat && robot->status_writer != nullptr)
      due.status_heartbeats.push_back(robot->status_writer);
    due.unwritten = due.unwritten || !robot->unwritten.empty();
    for (const auto& action : robot->actions) {
      ActionServer::Due action_due;
      action->take_due(ReplyClock::now(), stopping, action_due);
      if (!action_due.replies.empty() || action_due.status || action_due.check_flows ||
          !action_due.heartbeats.empty())
        due.action_dues.emplace_back(action.get(), std::move(action_due));
    }
  }
  return due;
}

// One budget for the results every action server keeps (actions.kept_results_mb); under
// reply_mutex_.
void PlannerNode::Impl::forget_results_beyond_budget() {
  const size_t forgotten = forget_beyond_budget(
      all_action_servers_, static_cast<size_t>(cfg_.actions.kept_results_mb) << 20);
  if (forgotten == 0) return;
  results_forgotten_for_budget_ += forgotten;
  if (Clock::now() - budget_warned_ < std::chrono::seconds(60)) return;
  budget_warned_ = Clock::now();
  spdlog::warn(
      "action results forgotten before actions.result_timeout to stay within "
      "actions.kept_results_mb ({} MiB): {} so far (a late get_result of one answers UNKNOWN)",
      cfg_.actions.kept_results_mb, results_forgotten_for_budget_);
}

// Writes every robot's unwritten statuses, without reply_mutex_ (a write may block up to the
// writer's max_blocking_time). Returns how many a full status history kept back.
size_t PlannerNode::Impl::write_statuses(bool stopping, Clock::time_point drain_deadline) {
  size_t waiting = 0;
  for (const auto& robot : robots_) {
    std::deque<HeldStatus>& queue = robot->unwritten;
    if (queue.empty()) continue;
    dds::DataWriter* writer = robot->status_writer;
    // A heartbeat first, one that does not count these statuses (writer_qos: manual
    // liveliness for that). To a volatile reader that has acknowledged nothing yet, Fast DDS
    // sends a status right behind a heartbeat that counts it, and Cyclone DDS's volatile
    // reader skips everything up to the last sequence number of the first heartbeat it gets
    // from a writer. A client that matched this writer after the node matched its reader
    // (discovery is not symmetric) missed the earlier heartbeats: it would lose its status.
    // Not enough alone over multicast (reply_gate.hpp): a requester's first status also
    // waited a settle after a heartbeat of its own (status_heartbeats in take_due_replies).
    if (writer != nullptr) writer->assert_liveliness();
    while (!queue.empty()) {
      HeldStatus& held = queue.front();
      // A keep-all history full of unacknowledged statuses refuses after max_blocking_time:
      // the status stays first in line and is tried again; none is ever dropped for a newer
      // one. Only a shutdown whose drain ran out of time gives the rest up, and says so.
      const bool written = writer != nullptr && write_sample(writer, &held.msg);
      if (!written && writer != nullptr && !(stopping && Clock::now() >= drain_deadline)) {
        waiting += queue.size();
        break;
      }
      if (!written)
        spdlog::error("could not publish the status of {}{}", held.what,
                      writer == nullptr ? "" : ": the shutdown's drain ran out of time");
      if (held.answer) --robot->unanswered;
      queue.pop_front();
    }
    resume_input(*robot);
  }
  return waiting;
}

// The earliest time a held status or an action server's reply falls due; under reply_mutex_.
auto PlannerNode::Impl::next_reply_deadline() const
    -> std::optional<ReplyGate<HeldStatus>::Clock::time_point> {
  std::optional<ReplyGate<HeldStatus>::Clock::time_point> deadline;
  for (const auto& robot : robots_) {
    const auto next = robot->replies.next_deadline();
    if (next && (!deadline || *next < *deadline)) deadline = next;
    for (const auto& action : robot->actions) {
      const auto next_action = action->next_deadline();
      if (next_action && (!deadline || *next_action < *deadline)) deadline = next_action;
    }
  }
  return deadline;
}

void PlannerNode::Impl::replier_loop() {
  std::unique_lock<std::mutex> lock(reply_mutex_);
  bool warned_full = false;  // one warning per episode of a full status history
  for (;;) {
    const bool stopping = replier_stopping_;
    const Clock::time_point drain_deadline = drain_deadline_;
    DueReplies due = take_due_replies(stopping);
    if (!due.status_heartbeats.empty()) {
      // Heartbeats that count no status held now: a fresh requester's settle starts with them.
      lock.unlock();
      for (dds::DataWriter* writer : due.status_heartbeats) writer->assert_liveliness();
      lock.lock();
    }
    forget_results_beyond_budget();
    if (!due.action_dues.empty()) {
      lock.unlock();
      const bool give_up = stopping && Clock::now() >= drain_deadline;
      bool all_written = true;
      for (auto& [action, action_due] : due.action_dues)
        all_written = action->write(action_due, stopping, give_up) && all_written;
      lock.lock();
      // Statuses released this pass go out below, in the same pass.
      if (!due.unwritten) {
        // Replies waiting for their readers' acknowledgements (reply_flow.hpp), which arrive
        // without a callback: looked for again shortly.
        if (!all_written) reply_cv_.wait_for(lock, std::chrono::milliseconds(2));
        continue;
      }
    }
    if (due.unwritten) {
      lock.unlock();
      replies_timed_out_ += due.timed_out;
      if (due.timed_out > 0)
        spdlog::warn(
            "{} status(es) written after requests.reply_wait ({} ms) without a matched status "
            "reader of the requesting participant: a volatile reader that matches later misses it",
            due.timed_out, cfg_.reply_wait.count());
      const size_t waiting = write_statuses(stopping, drain_deadline);
      lock.lock();
      if (waiting > 0 && !warned_full) {
        spdlog::warn(
            "status history full: {} status(es) wait for readers to acknowledge earlier ones "
            "(requests are taken again once answers go out)",
            waiting);
      }
      warned_full = waiting > 0;
      // Kept back: the write waited max_blocking_time already; look again soon, or at once
      // when something new is held.
      if (waiting > 0) reply_cv_.wait_for(lock, std::chrono::milliseconds(10));
      continue;
    }
    if (stopping) return;
    if (const auto deadline = next_reply_deadline())
      reply_cv_.wait_until(lock, *deadline);
    else
      reply_cv_.wait(lock);
  }
}

void PlannerNode::Impl::answer(Robot& robot, const Job& job, const WireStatus& status,
                               const std::string& planner, const core::Metrics* metrics,
                               const TimeMsg& map_stamp, PathMsg path,
                               const core::Endpoints* endpoints, const core::GridMap* map) {
  if (job.action) return finish_action(robot, job, status, metrics, std::move(path));
  PlanStatusMsg msg = to_status_msg(echoed_id(job.id), &job.identity, status, planner, metrics,
                                    map_stamp, std::move(path), endpoints, map);
  // A plan_request's client is waited for; goal_pose goals (rviz2) have no status reader.
  std::optional<GuidPrefix> requester;
  if (job.identity.subject == wire::SUBJECT_REQUEST) {
    requester.emplace();
    std::copy_n(job.identity.writer_guid.begin(), requester->size(), requester->begin());
  }
  write_status(robot, std::move(msg), "request '" + printable(job.id) + "'" + robot.label(),
               /*is_answer=*/true, requester);
  ++statuses_published_;
}

void PlannerNode::Impl::report_map(const WireStatus& status, const TimeMsg& map_stamp) {
  // The map is every robot's: each robot's tools see the report.
  for (const auto& robot : robots_)
    write_status(*robot, to_status_msg("", nullptr, status, "", nullptr, map_stamp, PathMsg()),
                 "a slice" + robot->label(), /*is_answer=*/false);
}

PlannerNode::Impl::Robot* PlannerNode::Impl::robot_with_work() {
  for (size_t i = 0; i < robots_.size(); ++i) {
    const size_t r = (next_robot_ + i) % robots_.size();
    Robot& robot = *robots_[r];
    if (robot.queue.waiting() > 0 && !robot.queue.planning()) {
      next_robot_ = r + 1;  // the next search starts after it: no robot starves the others
      return &robot;
    }
  }
  return nullptr;
}

void PlannerNode::Impl::worker_loop(size_t worker) {
  for (;;) {
    Job job;
    Robot* robot = nullptr;
    {
      std::unique_lock<std::mutex> lock(queue_mutex_);
      queue_cv_.wait(lock, [&] {
        robot = robot_with_work();
        return robot != nullptr || stopping_;
      });
      // Stopping, and nothing this worker can take: a robot being planned that still has
      // requests waiting is drained by its own worker, which comes back here for them.
      if (robot == nullptr) return;
      job = std::move(*robot->queue.next());
      if (stopping_) robot->queue.interrupt_current("node is shutting down");
    }
    std::shared_ptr<const ActiveMap> map;
    try {
      handle(*robot, job, map, worker);
    } catch (const std::exception& e) {
      // A bug or resource exhaustion, never bad input: the request still gets its one status,
      // the planner is rebuilt (at the next plan on this map), and the node keeps serving.
      spdlog::critical("request '{}'{}: internal error: {}", printable(job.id), robot->label(),
                       e.what());
      if (map && worker < map->planners.size()) map->planners[worker].reset();
      answer(*robot, job, {wire::INTERNAL_ERROR, std::string("internal error: ") + e.what()});
    }
    {
      std::lock_guard<std::mutex> lock(queue_mutex_);
      robot->queue.finish_current();
    }
    queue_cv_.notify_all();  // this robot's next request may wait for a worker
  }
}

PlannerNode::Impl::Leg PlannerNode::Impl::plan_leg(Robot& robot, Job& job, const ActiveMap& map,
                                                   size_t worker) {
  Leg leg;
  // Checked again: the map may have changed since the request arrived.
  ResolvedRequest resolved = resolve_request(job, robot.cfg, map.grid.get(), map_topic());
  leg.planner_name = resolved.planner_name;
  if (!resolved.status.ok()) {
    if (job.action) job.action->invalid_planner = resolved.invalid_planner;
    leg.status = resolved.status;
    return leg;
  }
  core::PlannerOptions& options = resolved.options;
  // The planners of a map are as many as the workers (convert_slice); one is null only after an
  // internal error dropped it (worker_loop).
  std::unique_ptr<core::Planner>& planner = map.planners.at(worker);
  if (!planner) planner = std::make_unique<core::Planner>(map.grid);
  // Recording the expansions costs time and memory: only when something will show them.
  options.record_expansions = publishing(robot.debug_writer) ||
                              publishing(robot.expansions_forward_writer) ||
                              publishing(robot.expansions_backward_writer);
  leg.result = planner->plan(resolved.query, options, &job.interruption->flag);
  leg.planned = true;
  leg.status = {to_wire_code(leg.result.status.code), leg.result.status.message};
  if (leg.result.status.code == core::StatusCode::kCanceled) {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    leg.status.message = job.interruption->reason;
  }
  if (!leg.status.ok()) return leg;
  // Poses at most planner.path_spacing apart (default: this map's resolution), never finer
  // than min_path_spacing (a bound on the pose count).
  const double resolution = map.grid->resolution();
  const double configured = cfg_.planner.path_spacing_for(resolution);
  const double spacing = std::max(configured, min_path_spacing(resolution));
  std::vector<std::string> remarks;
  if (std::string moved = describe_adjusted_endpoints(leg.result.endpoints, *map.grid, options);
      !moved.empty())
    remarks.push_back(std::move(moved));
  if (!resolved.warning.empty()) remarks.push_back(resolved.warning);
  if (spacing > configured) {
    remarks.push_back(fmt::format(
        "warning: planner.path_spacing {:g} m is finer than {:g} cells at this map's resolution "
        "of {:g} m; poses are {:g} m apart",
        configured, kMinPathSpacingCells, resolution, spacing));
  }
  for (const std::string& remark : remarks)
    leg.status.message += (leg.status.message.empty() ? "" : "; ") + remark;
  leg.path = to_path_msg(leg.result, cfg_.frame_id, time_.now(), spacing, resolved.goal_yaw);
  return leg;
}

void PlannerNode::Impl::handle(Robot& robot, Job& job, std::shared_ptr<const ActiveMap>& map,
                               size_t worker) {
  const auto t0 = Clock::now();
  const std::string id = printable(job.id);
  auto reject = [&](const WireStatus& status, const std::string& planner_name = "",
                    const TimeMsg& stamp = TimeMsg()) {
    answer(robot, job, status, planner_name, nullptr, stamp);
    spdlog::warn("request '{}'{}: {} ({})", id, robot.label(), code_name(status.code),
                 status.message);
  };
  std::string interrupted;
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    if (job.interruption->flag) interrupted = job.interruption->reason;
  }
  if (!interrupted.empty()) return reject({wire::CANCELED, interrupted});
  if (job.action) job.action->server->execute(job.action->goal_id);
  map = current_map();
  if (!map)
    return reject(
        {wire::NO_MAP, "no map has been accepted yet (slices arrive on '" + map_topic() + "')"});

  Leg leg = plan_leg(robot, job, *map, worker);
  if (!leg.planned) return reject(leg.status, leg.planner_name, map->stamp);
  // ComputePathThroughPoses: the next legs start where the previous one ended (the goal it
  // actually used) and their paths are joined; the first failure ends the goal with its code.
  const size_t legs = job.action ? 1 + job.action->more_goals.size() : 1;
  core::Metrics total = leg.result.metrics;
  // An action's result carries at most actions.max_result_poses poses.
  const size_t max_poses = static_cast<size_t>(cfg_.actions.max_result_poses);
  auto over_size = [&](size_t leg_number) {
    if (!job.action || !leg.status.ok() || leg.path.poses().size() <= max_poses) return false;
    leg.status = {wire::INVALID_REQUEST,
                  fmt::format("the path has {} poses{}, more than actions.max_result_poses ({})",
                              leg.path.poses().size(),
                              legs > 1 ? fmt::format(" after leg {} of {}", leg_number, legs) : "",
                              max_poses)};
    leg.path = PathMsg();
    return true;
  };
  over_size(1);
  for (size_t k = 1; k < legs && leg.status.ok(); ++k) {
    Job next = job;  // the same id, client, planner, interruption and action
    next.start = leg.path.poses().back();
    next.goal = job.action->more_goals[k - 1];
    Leg following = plan_leg(robot, next, *map, worker);
    total.length_m += following.result.metrics.length_m;
    total.planning_time_us += following.result.metrics.planning_time_us;
    total.expanded += following.result.metrics.expanded;
    total.turns += following.result.metrics.turns;
    total.turn_angle_deg += following.result.metrics.turn_angle_deg;
    total.clearance_m = std::min(total.clearance_m, following.result.metrics.clearance_m);
    if (!following.status.ok()) {
      following.status.message =
          fmt::format("leg {} of {} (to goals[{}]): {}", k + 1, legs, k, following.status.message);
      leg.status = following.status;
      leg.path = PathMsg();
      break;
    }
    auto& poses = leg.path.poses();
    poses.insert(poses.end(), following.path.poses().begin() + 1, following.path.poses().end());
    if (!following.status.message.empty())
      leg.status.message += (leg.status.message.empty() ? "" : "; ") +
                            fmt::format("leg {}: {}", k + 1, following.status.message);
    if (over_size(k + 1)) break;
  }
  if (legs > 1) leg.result.metrics = total;
  const std::string& planner_name = leg.planner_name;
  const core::PlanResult& result = leg.result;
  WireStatus& status = leg.status;
  // The debug layers carry the path's stamp: a client ties them to its plan by it.
  const TimeMsg stamp = status.ok() ? leg.path.header().stamp() : time_.now();
  if (status.ok()) {
    if (!robot.plan_writer->write(&leg.path))
      spdlog::error("could not publish the path of '{}'{}", id, robot.label());
    ++plans_ok_;
  }
  // The endpoints are the plan's once core resolved them: every outcome but a refusal of the
  // query itself (which resolve_request normally catches first).
  const bool resolved_endpoints =
      legs == 1 && (status.ok() || status.code == wire::NO_VALID_PATH ||
                    status.code == wire::TIMEOUT || status.code == wire::CANCELED);
  answer(robot, job, status, planner_name, &result.metrics, map->stamp, std::move(leg.path),
         resolved_endpoints ? &result.endpoints : nullptr, map->grid.get());
  publish_debug(robot, job.id, result, *map->grid, stamp);
  const auto total_us =
      std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - t0).count();
  spdlog::log(status.ok() ? spdlog::level::info : spdlog::level::warn,
              "plan '{}'{} {} {}: length {:.2f} m, clearance {:.3f} m, {} turns, {:.1f} deg, {} "
              "expanded, {} us planning, {} us total{}{}",
              id, robot.label(), planner_name, code_name(status.code), result.metrics.length_m,
              result.metrics.clearance_m, result.metrics.turns, result.metrics.turn_angle_deg,
              result.metrics.expanded, result.metrics.planning_time_us, total_us,
              status.message.empty() ? "" : ": ", status.message);
}

// ---------------------------------------------------------------------------------------------

PlannerNode::PlannerNode(NodeConfig config) : impl_(std::make_unique<Impl>(std::move(config))) {}
PlannerNode::~PlannerNode() {
  stop();
}

core::Status PlannerNode::start() {
  core::Status status = impl_->start();
  if (!status.is_ok()) impl_->stop();
  return status;
}

void PlannerNode::stop() {
  impl_->stop();
}

PlannerNode::Stats PlannerNode::stats() const {
  Stats s;
  s.requests_received = impl_->requests_received_;
  s.statuses_published = impl_->statuses_published_;
  s.maps_accepted = impl_->maps_accepted_;
  s.maps_rejected = impl_->maps_rejected_;
  s.maps_superseded = impl_->maps_superseded_;
  s.plans_ok = impl_->plans_ok_;
  s.queue_peak = impl_->queue_peak_;
  s.other_status_writers = impl_->participant_watch_ ? impl_->participant_watch_->count() : 0;
  s.incompatible_qos =
      impl_->participant_watch_ ? impl_->participant_watch_->incompatible_qos() : 0;
  {
    std::lock_guard<std::mutex> lock(impl_->reply_mutex_);
    for (const auto& robot : impl_->robots_)
      for (const auto& action : robot->actions) s.action_goals += action->goals();
  }
  for (const auto& robot : impl_->robots_) {
    if (robot->plan_writer != nullptr)
      s.plan_readers += static_cast<size_t>(matched_readers(robot->plan_writer));
    if (robot->status_writer != nullptr)
      s.status_readers += static_cast<size_t>(matched_readers(robot->status_writer));
  }
  return s;
}

bool PlannerNode::wait_for_map(std::chrono::milliseconds timeout) const {
  std::unique_lock<std::mutex> lock(impl_->map_mutex_);
  return impl_->map_cv_.wait_for(lock, timeout, [&] { return impl_->active_map_ != nullptr; });
}

const NodeConfig& PlannerNode::config() const {
  return impl_->cfg_;
}

}  // namespace vnsba::node
