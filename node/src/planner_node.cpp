#include "vnsba/node/planner_node.hpp"

#include <spdlog/spdlog.h>

#include <atomic>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

#include "geometry_msgs/msg/PoseStampedPubSubTypes.h"
#include "nav_msgs/msg/OccupancyGridPubSubTypes.h"
#include "nav_msgs/msg/PathPubSubTypes.h"
#include "vnsba/node/convert.hpp"
#include "vnsba/node/dds.hpp"
#include "vnsba_msgs/msg/PlanRequestPubSubTypes.h"
#include "vnsba_msgs/msg/PlanStatusPubSubTypes.h"
#include "vnsba_msgs/msg/PlannerDebugPubSubTypes.h"

namespace vnsba::node {

namespace {

using Clock = std::chrono::steady_clock;

// Takes every valid sample of a reader and hands it to `on_sample`; runs on a DDS thread.
template <class Msg, class OnSample>
class TakeListener : public dds::DataReaderListener {
 public:
  explicit TakeListener(OnSample on_sample) : on_sample_(std::move(on_sample)) {}
  void on_data_available(dds::DataReader* reader) override {
    Msg msg;
    dds::SampleInfo info;
    while (reader->take_next_sample(&msg, &info) == ReturnCode_t::RETCODE_OK) {
      if (info.valid_data) on_sample_(std::move(msg));
      msg = Msg();
    }
  }

 private:
  OnSample on_sample_;
};

template <class Msg, class OnSample>
std::unique_ptr<dds::DataReaderListener> make_listener(OnSample on_sample) {
  return std::make_unique<TakeListener<Msg, OnSample>>(std::move(on_sample));
}

// Why a request must not be planned (or stop being planned); set under the queue lock.
struct Interruption {
  std::atomic<bool> flag{false};  // polled by the search
  std::string reason;             // the CANCELED message
};

struct Job {
  std::string id;
  PoseStampedMsg start;
  PoseStampedMsg goal;
  std::string planner;        // empty: the configured planner
  std::string missing_start;  // set when a goal_pose came before any robot_pose
  std::shared_ptr<Interruption> interruption = std::make_shared<Interruption>();
};

// A map as the worker plans on it. The map thread builds the planner with the grid, so that its
// search arrays (both directions, tens of bytes per cell) are allocated before the map goes live,
// not in the first plan on it (about 230 ms at 4096 x 4096, which would also delay that plan's
// cancel). A plan holds its ActiveMap until it is answered: a plan in flight finishes on the
// map, and the planner, it started with.
struct ActiveMap {
  std::shared_ptr<const core::GridMap> grid;
  TimeMsg stamp;
  // Used by the worker thread only (a Planner is not thread-safe). Null only after an internal
  // error dropped it (see worker_loop); the worker then builds a fresh one.
  mutable std::unique_ptr<core::Planner> planner;
};

std::string describe_world_bounds(const core::GridMap& map) {
  const Eigen::Vector2d lo = map.grid_to_world({0, 0});
  const Eigen::Vector2d hi = map.grid_to_world({double(map.width()), double(map.height())});
  char text[160];
  std::snprintf(text, sizeof(text), "[%.3f, %.3f] x [%.3f, %.3f] m", lo.x(), hi.x(), lo.y(),
                hi.y());
  return text;
}

}  // namespace

class PlannerNode::Impl {
 public:
  explicit Impl(NodeConfig config) : cfg_(std::move(config)) {}

  core::Status start();
  void stop();

  NodeConfig cfg_;
  std::unique_ptr<Participant> participant_;
  dds::DataWriter* plan_writer_ = nullptr;
  dds::DataWriter* status_writer_ = nullptr;
  dds::DataWriter* debug_writer_ = nullptr;
  std::vector<std::unique_ptr<dds::DataReaderListener>> listeners_;

  // Maps: the newest unconverted slice, and the active one.
  mutable std::mutex map_mutex_;
  mutable std::condition_variable map_cv_;
  std::optional<OccupancyGridMsg> pending_slice_;
  std::shared_ptr<const ActiveMap> active_map_;

  // Requests.
  std::mutex queue_mutex_;
  std::condition_variable queue_cv_;
  std::deque<Job> queue_;
  std::shared_ptr<Interruption> current_;  // of the request being planned
  uint64_t goal_counter_ = 0;

  std::mutex pose_mutex_;
  std::optional<PoseStampedMsg> robot_pose_;

  std::atomic<bool> stopping_{false};
  bool started_ = false;
  std::thread worker_;
  std::thread map_thread_;

  std::atomic<uint64_t> requests_received_{0}, statuses_published_{0}, maps_accepted_{0},
      maps_rejected_{0}, plans_ok_{0};
  std::atomic<size_t> queue_peak_{0};

  void enqueue(Job job);
  void on_slice(OccupancyGridMsg&& msg);
  void on_goal(PoseStampedMsg&& goal);
  void map_loop();
  void worker_loop();
  // Plans one job; `map` is set to the map it plans on (the worker drops its planner when the
  // plan throws).
  void handle(Job& job, std::shared_ptr<const ActiveMap>& map);
  void publish_status(const std::string& id, const WireStatus& status, const std::string& planner,
                      const core::Metrics* metrics, const TimeMsg& map_stamp, PathMsg path,
                      bool answers_request = true);
  bool debug_wanted() const;
};

// ---------------------------------------------------------------------------------------------
// Start and stop.

core::Status PlannerNode::Impl::start() {
  auto participant = Participant::create(cfg_.domain_id, "vnsba_node");
  if (!participant) return participant.error();
  participant_ = std::move(participant).value();
  auto name = [&](const std::string& topic) { return dds_topic_name(cfg_, topic); };

  // Writers first, so that every request read can be answered.
  auto plan_topic =
      participant_->topic<nav_msgs::msg::dds_::Path_PubSubType>(name(cfg_.topics.plan));
  if (!plan_topic) return plan_topic.error();
  auto status_topic = participant_->topic<vnsba_msgs::msg::dds_::PlanStatus_PubSubType>(
      name(cfg_.topics.plan_status));
  if (!status_topic) return status_topic.error();
  auto debug_topic = participant_->topic<vnsba_msgs::msg::dds_::PlannerDebug_PubSubType>(
      name(cfg_.topics.planner_debug));
  if (!debug_topic) return debug_topic.error();
  auto plan_writer = participant_->writer(*plan_topic, writer_qos(TopicQos::kLatest, false));
  if (!plan_writer) return plan_writer.error();
  auto status_writer = participant_->writer(*status_topic, writer_qos(TopicQos::kStatus, false));
  if (!status_writer) return status_writer.error();
  auto debug_writer = participant_->writer(*debug_topic, writer_qos(TopicQos::kDebug, true));
  if (!debug_writer) return debug_writer.error();
  plan_writer_ = *plan_writer;
  status_writer_ = *status_writer;
  debug_writer_ = *debug_writer;

  map_thread_ = std::thread([this] { map_loop(); });
  worker_ = std::thread([this] { worker_loop(); });
  started_ = true;

  // Then the readers.
  auto slice_topic = participant_->topic<nav_msgs::msg::dds_::OccupancyGrid_PubSubType>(
      name(cfg_.topics.projected_map));
  if (!slice_topic) return slice_topic.error();
  auto goal_topic = participant_->topic<geometry_msgs::msg::dds_::PoseStamped_PubSubType>(
      name(cfg_.topics.goal_pose));
  if (!goal_topic) return goal_topic.error();
  auto pose_topic = participant_->topic<geometry_msgs::msg::dds_::PoseStamped_PubSubType>(
      name(cfg_.topics.robot_pose));
  if (!pose_topic) return pose_topic.error();
  auto request_topic = participant_->topic<vnsba_msgs::msg::dds_::PlanRequest_PubSubType>(
      name(cfg_.topics.plan_request));
  if (!request_topic) return request_topic.error();

  listeners_.push_back(
      make_listener<OccupancyGridMsg>([this](OccupancyGridMsg&& m) { on_slice(std::move(m)); }));
  listeners_.push_back(
      make_listener<PoseStampedMsg>([this](PoseStampedMsg&& m) { on_goal(std::move(m)); }));
  listeners_.push_back(make_listener<PoseStampedMsg>([this](PoseStampedMsg&& m) {
    std::lock_guard<std::mutex> lock(pose_mutex_);
    robot_pose_ = std::move(m);
  }));
  listeners_.push_back(make_listener<PlanRequestMsg>([this](PlanRequestMsg&& m) {
    Job job;
    job.id = m.id();
    job.start = std::move(m.start());
    job.goal = std::move(m.goal());
    job.planner = m.planner();
    enqueue(std::move(job));
  }));
  const std::pair<dds::Topic*, TopicQos> readers[] = {{*slice_topic, TopicQos::kLatched},
                                                      {*goal_topic, TopicQos::kEvents},
                                                      {*pose_topic, TopicQos::kLatest},
                                                      {*request_topic, TopicQos::kEvents}};
  for (size_t i = 0; i < 4; ++i) {
    auto reader =
        participant_->reader(readers[i].first, reader_qos(readers[i].second), listeners_[i].get());
    if (!reader) return reader.error();
  }
  spdlog::info("vnsba_node up on domain {}: slices on '{}', requests on '{}', goals on '{}'",
               cfg_.domain_id, name(cfg_.topics.projected_map), name(cfg_.topics.plan_request),
               name(cfg_.topics.goal_pose));
  return core::Status::ok();
}

void PlannerNode::Impl::stop() {
  if (participant_) participant_->delete_readers();  // no new input from here on
  stopping_ = true;
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    if (current_) {
      current_->reason = "node is shutting down";
      current_->flag = true;
    }
  }
  queue_cv_.notify_all();
  map_cv_.notify_all();
  if (worker_.joinable()) worker_.join();  // answers every queued request first
  if (map_thread_.joinable()) map_thread_.join();
  if (participant_) participant_->shutdown();
  participant_.reset();
  listeners_.clear();
}

// ---------------------------------------------------------------------------------------------
// Input (DDS listener threads): cheap, never plans.

void PlannerNode::Impl::on_slice(OccupancyGridMsg&& msg) {
  {
    std::lock_guard<std::mutex> lock(map_mutex_);
    pending_slice_ = std::move(msg);  // only the newest unconverted slice matters
  }
  map_cv_.notify_all();
}

void PlannerNode::Impl::on_goal(PoseStampedMsg&& goal) {
  Job job;
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    job.id = "goal-" + std::to_string(++goal_counter_);
  }
  job.goal = std::move(goal);
  {
    std::lock_guard<std::mutex> lock(pose_mutex_);
    if (robot_pose_) {
      job.start = *robot_pose_;
    } else {
      job.missing_start = "start: no robot_pose received yet on '" +
                          dds_topic_name(cfg_, cfg_.topics.robot_pose) + "'";
    }
  }
  enqueue(std::move(job));
}

void PlannerNode::Impl::enqueue(Job job) {
  ++requests_received_;
  std::optional<Job> refused;
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    if (cfg_.preempt) {
      const std::string reason = "preempted by newer request '" + job.id + "'";
      for (Job& waiting : queue_) {
        if (!waiting.interruption->flag) {
          waiting.interruption->reason = reason;
          waiting.interruption->flag = true;
        }
      }
      if (current_ && !current_->flag) {
        current_->reason = reason;
        current_->flag = true;
      }
    }
    if (queue_.size() >= static_cast<size_t>(cfg_.queue_capacity)) {
      if (cfg_.preempt) {
        // The oldest waiting request is already preempted: answer it now to make room.
        refused = std::move(queue_.front());
        queue_.pop_front();
      } else {
        refused = std::move(job);
        refused->interruption->reason = "request queue is full (requests.queue_capacity = " +
                                        std::to_string(cfg_.queue_capacity) + ")";
      }
    }
    if (!refused || cfg_.preempt) queue_.push_back(std::move(job));
    queue_peak_ = std::max(queue_peak_.load(), queue_.size());
  }
  queue_cv_.notify_one();
  if (refused) {
    // Writers are thread-safe; this answer does not wait for the worker.
    publish_status(refused->id, {wire::CANCELED, refused->interruption->reason}, "", nullptr,
                   TimeMsg(), PathMsg());
  }
}

// ---------------------------------------------------------------------------------------------
// Map thread.

void PlannerNode::Impl::map_loop() {
  for (;;) {
    OccupancyGridMsg msg;
    {
      std::unique_lock<std::mutex> lock(map_mutex_);
      map_cv_.wait(lock, [&] { return stopping_ || pending_slice_.has_value(); });
      if (stopping_) return;
      msg = std::move(*pending_slice_);
      pending_slice_.reset();
    }
    const auto t0 = Clock::now();
    const TimeMsg stamp = msg.header().stamp();
    SliceCheck check = from_slice_msg(std::move(msg), cfg_.frame_id, cfg_.map.max_cells);
    WireStatus status = check.status;
    if (status.ok()) {
      auto built = core::GridMap::build(check.grid, cfg_.map);
      if (built) {
        auto active = std::make_shared<ActiveMap>();
        active->grid = std::make_shared<const core::GridMap>(std::move(built).value());
        active->stamp = stamp;
        try {
          active->planner = std::make_unique<core::Planner>(active->grid);  // see ActiveMap
        } catch (const std::exception& e) {
          // Resource exhaustion, never bad input: refuse this map, keep planning on the last one.
          status = {wire::INTERNAL_ERROR,
                    "cannot allocate the search state of " + std::to_string(active->grid->width()) +
                        " x " + std::to_string(active->grid->height()) + " cells: " + e.what()};
        }
        if (status.ok()) {
          const auto ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
          spdlog::info(
              "map accepted: {} x {} cells at {} m, {} blocked, {:.1f} MB of search state, ready "
              "in {:.1f} ms",
              active->grid->width(), active->grid->height(), active->grid->resolution(),
              active->grid->blocked_count(), active->planner->search_state_bytes() / 1e6, ms);
          std::shared_ptr<const ActiveMap> previous;
          {
            std::lock_guard<std::mutex> lock(map_mutex_);
            previous = std::exchange(active_map_, std::move(active));
          }
          map_cv_.notify_all();
          ++maps_accepted_;
          // The previous map and its planner go here, outside the lock, unless a plan still
          // holds them (then when that plan is answered).
          previous.reset();
          continue;
        }
      } else {
        status = {to_wire_code(built.error().code), built.error().message};
      }
    }
    ++maps_rejected_;
    spdlog::error("map rejected ({}): {}; keeping the previous map", code_name(status.code),
                  status.message);
    // A report on the status topic, with no request id, so tools on the bus see it too.
    publish_status("", status, "", nullptr, stamp, PathMsg(), /*answers_request=*/false);
  }
}

// ---------------------------------------------------------------------------------------------
// Worker thread: the only place that plans.

bool PlannerNode::Impl::debug_wanted() const {
  switch (cfg_.debug) {
    case DebugPublishing::kAlways:
      return true;
    case DebugPublishing::kNever:
      return false;
    case DebugPublishing::kAuto:
      return matched_readers(debug_writer_) > 0;
  }
  return false;
}

void PlannerNode::Impl::publish_status(const std::string& id, const WireStatus& status,
                                       const std::string& planner, const core::Metrics* metrics,
                                       const TimeMsg& map_stamp, PathMsg path,
                                       bool answers_request) {
  PlanStatusMsg msg = to_status_msg(id, status, planner, metrics, map_stamp, std::move(path));
  if (status_writer_ == nullptr || !status_writer_->write(&msg)) {
    spdlog::error("could not publish the status of request '{}'", id);
  }
  if (answers_request) ++statuses_published_;
}

void PlannerNode::Impl::worker_loop() {
  for (;;) {
    Job job;
    {
      std::unique_lock<std::mutex> lock(queue_mutex_);
      queue_cv_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping, and everything is answered
      job = std::move(queue_.front());
      queue_.pop_front();
      if (stopping_ && !job.interruption->flag) {
        job.interruption->reason = "node is shutting down";
        job.interruption->flag = true;
      }
      current_ = job.interruption;
    }
    std::shared_ptr<const ActiveMap> map;
    try {
      handle(job, map);
    } catch (const std::exception& e) {
      // A bug or resource exhaustion, never bad input: the request still gets its one status,
      // the planner is rebuilt (at the next plan on this map), and the node keeps serving.
      spdlog::critical("request '{}': internal error: {}", job.id, e.what());
      if (map) map->planner.reset();
      publish_status(job.id, {wire::INTERNAL_ERROR, std::string("internal error: ") + e.what()}, "",
                     nullptr, TimeMsg(), PathMsg());
    }
    std::lock_guard<std::mutex> lock(queue_mutex_);
    current_.reset();
  }
}

void PlannerNode::Impl::handle(Job& job, std::shared_ptr<const ActiveMap>& map) {
  const auto t0 = Clock::now();
  auto reject = [&](uint8_t code, const std::string& message, const std::string& planner_name = "",
                    const TimeMsg& stamp = TimeMsg()) {
    publish_status(job.id, {code, message}, planner_name, nullptr, stamp, PathMsg());
    spdlog::warn("request '{}': {} ({})", job.id, code_name(code), message);
  };
  std::string interrupted;
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    if (job.interruption->flag) interrupted = job.interruption->reason;
  }
  if (!interrupted.empty()) return reject(wire::CANCELED, interrupted);
  {
    std::lock_guard<std::mutex> lock(map_mutex_);
    map = active_map_;
  }
  if (job.id.empty()) return reject(wire::INVALID_REQUEST, "id: must not be empty");
  if (!map) {
    return reject(wire::NO_MAP, "no map has been accepted yet (slices arrive on '" +
                                    dds_topic_name(cfg_, cfg_.topics.projected_map) + "')");
  }
  core::PlannerKind kind = cfg_.planner.kind;
  if (!job.planner.empty()) {
    const auto requested = core::planner_kind_from_string(job.planner);
    if (!requested) {
      std::string known;
      for (core::PlannerKind k : core::all_planner_kinds())
        known += (known.empty() ? "" : ", ") + std::string(core::to_string(k));
      return reject(wire::INVALID_REQUEST,
                    "planner: unknown planner '" + job.planner + "' (known: " + known + ")");
    }
    kind = *requested;
  }
  // Every configured planner key, whichever planner runs; the rest is that planner's paper
  // configuration.
  core::PlannerOptions options = cfg_.planner.options(kind);
  const std::string planner_name(core::to_string(options.planner));
  if (!job.missing_start.empty())
    return reject(wire::INVALID_REQUEST, job.missing_start, planner_name);
  const PoseCheck start = check_pose(job.start, "start", cfg_.frame_id);
  if (!start.status.ok()) return reject(start.status.code, start.status.message, planner_name);
  const PoseCheck goal = check_pose(job.goal, "goal", cfg_.frame_id);
  if (!goal.status.ok()) return reject(goal.status.code, goal.status.message, planner_name);
  const core::GridMap& grid = *map->grid;
  const auto start_cell = grid.world_to_cell(start.x, start.y);
  const auto goal_cell = grid.world_to_cell(goal.x, goal.y);
  char where[96];
  if (!start_cell) {
    std::snprintf(where, sizeof(where), "start (%.3f, %.3f) m", start.x, start.y);
    return reject(wire::START_OUTSIDE_MAP,
                  std::string(where) + " is outside the map " + describe_world_bounds(grid),
                  planner_name, map->stamp);
  }
  if (!goal_cell) {
    std::snprintf(where, sizeof(where), "goal (%.3f, %.3f) m", goal.x, goal.y);
    return reject(wire::GOAL_OUTSIDE_MAP,
                  std::string(where) + " is outside the map " + describe_world_bounds(grid),
                  planner_name, map->stamp);
  }

  if (!map->planner) map->planner = std::make_unique<core::Planner>(map->grid);  // see worker_loop
  const bool debug = debug_wanted();
  options.record_expansions = debug;
  core::PlanResult result =
      map->planner->plan({*start_cell, *goal_cell}, options, &job.interruption->flag);

  WireStatus status{to_wire_code(result.status.code), result.status.message};
  if (result.status.code == core::StatusCode::kCanceled) {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    status.message = job.interruption->reason;
  }
  const TimeMsg stamp = now_msg();
  PathMsg path;
  if (status.ok()) {
    path = to_path_msg(result, cfg_.frame_id, stamp);
    if (!plan_writer_->write(&path)) spdlog::error("could not publish the path of '{}'", job.id);
    ++plans_ok_;
  }
  publish_status(job.id, status, planner_name, &result.metrics, map->stamp, std::move(path));
  if (debug && result.metrics.expanded > 0) {
    PlannerDebugMsg msg = to_debug_msg(job.id, result, grid, cfg_.frame_id, stamp);
    if (!debug_writer_->write(&msg)) spdlog::warn("could not publish the debug of '{}'", job.id);
  }
  const auto total_us =
      std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - t0).count();
  spdlog::log(
      status.ok() ? spdlog::level::info : spdlog::level::warn,
      "plan '{}' {} {}: length {:.2f} m, {} turns, {:.1f} deg, {} expanded, {} us planning, "
      "{} us total{}{}",
      job.id, planner_name, code_name(status.code), result.metrics.length_m, result.metrics.turns,
      result.metrics.turn_angle_deg, result.metrics.expanded, result.metrics.planning_time_us,
      total_us, status.ok() ? "" : ": ", status.message);
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
  s.plans_ok = impl_->plans_ok_;
  s.queue_peak = impl_->queue_peak_;
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
