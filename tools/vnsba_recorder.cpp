// vnsba_recorder: listens to a planner node's topics and turns each planning run into a picture
// and a run record.
//
//   vnsba_recorder --out DIR [--config FILE] [--domain N] [--namespace NS] [--duration S | --runs
//   N]
//                  [--debug-wait S] [--max-open-mb M]
//   vnsba_recorder render RUN.json [--out RUN.svg]
//
// It subscribes to the slice, plan_request, goal_pose, robot_pose, plan, plan_status and
// planner_debug, pairs them by request id, and writes DIR/<id>.svg and DIR/<id>.json for every
// run once its status has come (and its debug data, or after --debug-wait without it). Slices
// runs refer to are saved once each under DIR/maps/ (map_server .pgm + .yaml). goal_pose goals
// carry no id: the node names them goal-1, goal-2, ... and the recorder pairs them with the
// goal poses it heard in order (start = the last robot_pose), so a recorder started after some
// goals pairs goal poses only by arrival order.
//
// Runs heard of but not yet written are held in memory, at most 10,000 of them and at most
// --max-open-mb (default 512 MiB) of their data: past that, the debug data of the oldest runs
// is dropped first, then the oldest runs; every drop is logged (run id, bytes) and counted in
// the summary at exit. The samples received but not yet handled count against the same limit,
// with the runs being written: while the main thread is busy, a debug sample that would take
// them past it is dropped on arrival (logged, counted). So what is held for runs stays within
// the limit, and within twice it while a run is drawn (its picture copies its cells). A run's
// record is written element by element (records::write_json, no JSON tree of its cells) in
// about 1.5 bytes per byte of its cells, at most 2.6; its picture grows with its map, not with
// its expansions. Outside the limit: the 4 slices kept, and the DDS readers' own histories (up
// to 8 debug samples).
//
// Files are written to a temporary name and renamed, so a reader never sees half a file. A run
// whose data cannot be drawn or written is logged and skipped; the others go on. SIGINT/SIGTERM
// (or --duration, or --runs) stop it: readers are deleted first, then every run heard so far is
// written (a request without a status as NO_STATUS) and it exits 0.
//
// Exit codes: 0 done, 1 DDS failure, 2 bad arguments, config or record file.
#include <malloc.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <deque>
#include <filesystem>
#include <functional>
#include <mutex>
#include <optional>
#include <variant>

#include "geometry_msgs/msg/PoseStampedPubSubTypes.h"
#include "nav_msgs/msg/OccupancyGridPubSubTypes.h"
#include "nav_msgs/msg/PathPubSubTypes.h"
#include "vnsba/maps/map_io.hpp"
#include "vnsba/node/command_line.hpp"
#include "vnsba/node/config.hpp"
#include "vnsba/node/convert.hpp"
#include "vnsba/node/dds.hpp"
#include "vnsba/node/process.hpp"
#include "vnsba/node/security.hpp"
#include "vnsba/records/open_runs.hpp"
#include "vnsba/records/run_record.hpp"
#include "vnsba/render/svg.hpp"
#include "vnsba_msgs/msg/PlanRequestPubSubTypes.h"
#include "vnsba_msgs/msg/PlanStatusPubSubTypes.h"
#include "vnsba_msgs/msg/PlannerDebugPubSubTypes.h"

namespace {

using namespace vnsba;
using Clock = std::chrono::steady_clock;

constexpr int kDdsFailure = 1;
constexpr int kBadInput = node::kExitUsage;

// Memory guards: the recorder may run for days next to a busy node.
constexpr size_t kMaxOpenRuns = 10000;     // runs heard of but not yet written
constexpr double kDefaultMaxOpenMb = 512;  // and their data, MiB (--max-open-mb)
constexpr size_t kMaxPendingGoals = 1024;  // goal poses waiting for their status
constexpr size_t kMaxKeptMaps = 4;         // recent slices kept to pair runs with

std::string megabytes(uint64_t bytes) {
  return fmt::format("{:.3g} MiB", static_cast<double>(bytes) / (1024.0 * 1024.0));
}

struct GoalEvent {
  node::PoseStampedMsg goal;
};
struct RobotPoseEvent {
  node::PoseStampedMsg pose;
};
// Debug data converted as it arrives (in the DDS thread): what is queued is what a run will hold,
// and the message is freed at once.
struct DebugEvent {
  explicit DebugEvent(const node::PlannerDebugMsg& msg) : data(node::from_debug_msg(msg)) {}
  node::DebugData data;
};
using Event = std::variant<node::OccupancyGridMsg, node::PlanRequestMsg, GoalEvent, RobotPoseEvent,
                           node::PathMsg, node::PlanStatusMsg, DebugEvent>;

// The bytes a received sample holds, about: the message and the capacity of its lists and
// strings (what grows with a run; the fixed fields are in sizeof).
using records::list_bytes;
size_t extra_bytes(const node::OccupancyGridMsg& m) {
  return list_bytes(m.data());
}
size_t extra_bytes(const node::PlanRequestMsg& m) {
  return m.id().capacity() + m.planner().capacity();
}
size_t extra_bytes(const GoalEvent&) {
  return 0;
}
size_t extra_bytes(const RobotPoseEvent&) {
  return 0;
}
size_t extra_bytes(const node::PathMsg& m) {
  return list_bytes(m.poses());
}
size_t extra_bytes(const node::PlanStatusMsg& m) {
  return m.request_id().capacity() + m.message().capacity() + list_bytes(m.path().poses());
}
size_t extra_bytes(const DebugEvent& e) {
  return e.data.request_id.capacity() + records::debug_bytes(e.data.trace);
}
size_t event_bytes(const Event& event) {
  return sizeof(Event) + std::visit([](const auto& m) { return extra_bytes(m); }, event);
}

// Every listener hands its samples to one inbox; the main thread does all the work, so the
// run state needs no locking and a slow disk never blocks DDS threads for long.
//
// The samples queued count against --max-open-mb together with what the main thread holds (the
// open runs and the runs being written, settle()): while the main thread is busy (writing a
// large run), a debug sample that would take the total past the limit is dropped on arrival
// instead of queuing without bound. Other samples are small (statuses, requests, poses) or rare
// (slices) and always queued: a run is never lost for want of its status.
class Inbox {
 public:
  struct Queued {
    Event event;
    size_t bytes = 0;  // counted until handled()
  };

  explicit Inbox(size_t max_bytes) : max_bytes_(max_bytes) {}

  // Queues `event` of `bytes` (event_bytes); a `droppable` one only when it fits: false when it
  // was dropped.
  bool push(Event event, size_t bytes, bool droppable) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (droppable && queued_bytes_ + settled_bytes_ + bytes > max_bytes_) {
      ++dropped_;
      dropped_bytes_ += bytes;
      return false;
    }
    events_.push_back({std::move(event), bytes});
    queued_bytes_ += bytes;
    peak_bytes_ = std::max(peak_bytes_, queued_bytes_ + settled_bytes_);
    return true;
  }
  size_t size() {
    std::lock_guard<std::mutex> lock(mutex_);
    return events_.size();
  }
  // The oldest sample, still counted: call handled() once it is handled and freed.
  std::optional<Queued> pop() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (events_.empty()) return std::nullopt;
    Queued front = std::move(events_.front());
    events_.pop_front();
    return front;
  }
  // The sample popped is handled: what it held has moved into a run (settle()) or been freed.
  void handled(size_t bytes) {
    std::lock_guard<std::mutex> lock(mutex_);
    queued_bytes_ -= bytes;
    peak_bytes_ = std::max(peak_bytes_, queued_bytes_ + settled_bytes_);
  }
  // What the main thread holds now (open runs, runs being written), bytes. While a sample is
  // handled its bytes count twice, in the inbox and in its run, until handled(): an admission
  // then is only more cautious.
  void settle(size_t bytes) {
    std::lock_guard<std::mutex> lock(mutex_);
    settled_bytes_ = bytes;
  }
  // Debug samples dropped on arrival, their bytes, and the most ever held (queued + settled).
  std::string summary() {
    std::lock_guard<std::mutex> lock(mutex_);
    return fmt::format("{} debug sample(s) ({}) dropped on arrival; at most {} held", dropped_,
                       megabytes(dropped_bytes_), megabytes(peak_bytes_));
  }

 private:
  std::mutex mutex_;
  std::deque<Queued> events_;
  const size_t max_bytes_;
  size_t queued_bytes_ = 0;
  size_t settled_bytes_ = 0;
  size_t peak_bytes_ = 0;
  size_t dropped_ = 0;
  uint64_t dropped_bytes_ = 0;
};

template <class Msg, class Wrap = Msg>
class Forwarder : public node::dds::DataReaderListener {
 public:
  Forwarder(Inbox& inbox, std::string topic) : inbox_(inbox), topic_(std::move(topic)) {}
  // Logged so that scripts and tests can wait until the node's writers are matched.
  void on_subscription_matched(node::dds::DataReader*,
                               const node::dds::SubscriptionMatchedStatus& status) override {
    if (status.current_count_change > 0)
      spdlog::info("recorder: {} matched {} writer(s)", topic_, status.current_count);
  }
  void on_data_available(node::dds::DataReader* reader) override {
    Msg msg;
    node::dds::SampleInfo info;
    // Nothing escapes a DDS thread: a sample that cannot be queued (memory) is logged and lost.
    try {
      while (reader->take_next_sample(&msg, &info) == ReturnCode_t::RETCODE_OK) {
        if (!info.valid_data) continue;
        constexpr bool kDebug = std::is_same_v<Wrap, DebugEvent>;
        Event event(Wrap{std::move(msg)});
        std::string id;
        if constexpr (kDebug) id = std::get<DebugEvent>(event).data.request_id;
        const size_t bytes = event_bytes(event);
        if (!inbox_.push(std::move(event), bytes, kDebug))
          spdlog::warn(
              "dropped the debug data of run '{}' on arrival ({} bytes): with what is held it "
              "would exceed --max-open-mb; its picture and record will have no expansions",
              node::printable(id, 256), bytes);
        msg = Msg();
      }
    } catch (const std::exception& e) {
      spdlog::error("recorder: a sample on {} was lost: {}", topic_, e.what());
    }
  }

 private:
  Inbox& inbox_;
  std::string topic_;
};

struct StoredMap {
  int64_t stamp_sec = 0;
  uint32_t stamp_nanosec = 0;
  core::OccupancyGrid grid;
  std::string file;  // relative to the output folder once saved
};

using records::OpenRun;

class Recorder {
 public:
  // `inbox` is told what the recorder holds after every change (Inbox::settle).
  Recorder(node::NodeConfig config, std::filesystem::path out_dir,
           std::chrono::milliseconds debug_wait, size_t max_open_bytes, Inbox& inbox)
      : config_(std::move(config)),
        out_dir_(std::move(out_dir)),
        debug_wait_(debug_wait),
        runs_(kMaxOpenRuns, max_open_bytes),
        inbox_(inbox) {}

  // Handles the samples queued now, one at a time: each stays counted in the inbox until it is
  // handled and freed.
  void handle_queued() {
    for (size_t n = inbox_.size(); n > 0; --n) {
      std::optional<Inbox::Queued> queued = inbox_.pop();
      if (!queued) return;
      std::visit([this](auto&& e) { on(std::move(e)); }, std::move(queued->event));
      inbox_.handled(queued->bytes);
    }
  }

  // Writes the runs that are complete (all of them when `flush`). Returns how many were written.
  size_t write_ready(bool flush) {
    size_t written = 0;
    const auto now = Clock::now();
    std::vector<OpenRun> ready = runs_.take([&](const OpenRun& run) {
      const bool has_status = run.status_time.has_value();
      // Topics are not ordered with respect to each other: the debug data, and even the request
      // or goal pose, may arrive after the status. A run waits for them up to debug_wait.
      const bool complete = has_status && run.record.request &&
                            (run.record.debug || run.record.status->metrics.expanded == 0);
      return flush || complete || (has_status && now - *run.status_time >= debug_wait_);
    });
    // Taken runs stay counted until written, and are written and freed one at a time.
    for (const OpenRun& run : ready) writing_bytes_ += run.bytes;
    settle();
    for (OpenRun& run : ready) {
      written += write_run(run.record) ? 1 : 0;
      run.record = {};
      writing_bytes_ -= run.bytes;
      settle();
    }
    return written;
  }

  size_t runs_written() const { return runs_written_; }

  // What was dropped to stay within the memory limits, for the summary at exit.
  std::string dropped_summary() const {
    const records::DropTotals& d = runs_.dropped();
    if (d.runs == 0 && d.debug == 0) return "nothing dropped";
    return fmt::format(
        "dropped to stay within {} open runs and --max-open-mb ({}): {} whole run(s) and the "
        "debug data of {} run(s), {} in all",
        runs_.max_runs(), megabytes(runs_.max_bytes()), d.runs, d.debug, megabytes(d.bytes));
  }

 private:
  void settle() { inbox_.settle(runs_.bytes() + writing_bytes_); }

  // Changes the open run of `id` (opened if new) and logs what the memory limits dropped.
  void update_run(const std::string& id, const std::function<void(OpenRun&)>& change) {
    const std::vector<records::DroppedPart> dropped = runs_.update(id, change);
    settle();
    for (const records::DroppedPart& part : dropped) {
      spdlog::warn("{}: dropped {} of run '{}' ({} bytes){}", part.reason,
                   part.whole_run ? "everything heard" : "the debug data", part.request_id,
                   part.bytes,
                   part.whole_run ? "" : "; its picture and record will have no expansions");
    }
  }

  // The node names goal_pose goals goal-1, goal-2, ...
  static bool is_goal_id(const std::string& id) { return id.rfind("goal-", 0) == 0; }

  void on(node::OccupancyGridMsg&& msg) {
    const int64_t sec = msg.header().stamp().sec();
    const uint32_t nanosec = msg.header().stamp().nanosec();
    node::SliceCheck check =
        node::from_slice_msg(std::move(msg), config_.frame_id, config_.map.max_cells);
    if (!check.status.ok()) {
      spdlog::warn("slice ignored: {}", check.status.message);
      return;
    }
    maps_.push_back({sec, nanosec, std::move(check.grid), {}});
    while (maps_.size() > kMaxKeptMaps) maps_.pop_front();
    spdlog::info("slice {} x {} cells at {} m", maps_.back().grid.width, maps_.back().grid.height,
                 maps_.back().grid.resolution);
  }

  void on(node::PlanRequestMsg&& msg) {
    if (msg.id().empty()) {
      spdlog::warn("a plan_request without an id cannot be paired with its status; not recorded");
      return;
    }
    records::RequestRecord request;
    request.source = "plan_request";
    request.planner = msg.planner();
    request.start = node::position_of(msg.start());
    request.goal = node::position_of(msg.goal());
    update_run(msg.id(), [&](OpenRun& run) { run.record.request = request; });
  }

  void on(GoalEvent&& e) {
    records::RequestRecord request;
    request.source = "goal_pose";
    request.goal = node::position_of(e.goal);
    request.start = robot_pose_;
    // Its status may have come first: then the oldest goal run still without a request is it.
    const std::optional<std::string> waiting =
        runs_.oldest([](const std::string& id, const OpenRun& run) {
          return !run.record.request && is_goal_id(id);
        });
    if (waiting) {
      update_run(*waiting, [&](OpenRun& run) { run.record.request = request; });
      return;
    }
    goals_.push_back(request);
    while (goals_.size() > kMaxPendingGoals) goals_.pop_front();
  }

  void on(RobotPoseEvent&& e) { robot_pose_ = node::position_of(e.pose); }

  void on(node::PathMsg&& msg) {
    // The path also arrives inside PlanStatus (with the id); this copy only fills a status that
    // came without one.
    last_plan_ = node::from_path_msg(msg);
  }

  void on(node::PlanStatusMsg&& msg) {
    // Map reports have their own subject; an empty request_id can also be a rejected request
    // (issue 13: the recorder used to take that for a map).
    if (msg.subject() == node::wire::SUBJECT_MAP) {
      spdlog::warn("the node did not take a slice ({}): {}", msg.code_name(),
                   node::printable(msg.message(), 1024));
      return;
    }
    update_run(msg.request_id(), [&](OpenRun& run) { set_status(run, msg); });
  }

  void set_status(OpenRun& run, const node::PlanStatusMsg& msg) {
    records::StatusRecord status;
    status.code = msg.code();
    status.code_name = msg.code_name();
    status.message = msg.message();
    status.planner = msg.planner();
    status.metrics = node::metrics_from_status_msg(msg);
    status.map_stamp_sec = msg.map_stamp().sec();
    status.map_stamp_nanosec = msg.map_stamp().nanosec();
    run.record.status = status;
    run.record.path = node::from_path_msg(msg.path());
    if (run.record.path.empty() && status.code == 0) run.record.path = last_plan_;
    if (!run.record.request && is_goal_id(msg.request_id()) && !goals_.empty()) {
      run.record.request = goals_.front();
      goals_.pop_front();
    }
    run.status_time = Clock::now();
  }

  void on(DebugEvent&& e) {
    if (e.data.request_id.empty()) return;
    update_run(e.data.request_id,
               [&](OpenRun& run) { run.record.debug = std::move(e.data.trace); });
  }

  // The slice a run was planned on: the one whose stamp the status names, else the newest one
  // with the debug data's geometry, else the newest one.
  StoredMap* map_of(const records::RunRecord& r) {
    if (maps_.empty()) return nullptr;
    if (r.status)
      for (auto it = maps_.rbegin(); it != maps_.rend(); ++it)
        if (it->stamp_sec == r.status->map_stamp_sec &&
            it->stamp_nanosec == r.status->map_stamp_nanosec)
          return &*it;
    if (r.debug)
      for (auto it = maps_.rbegin(); it != maps_.rend(); ++it)
        if (it->grid.width == r.debug->width && it->grid.height == r.debug->height) return &*it;
    return r.status && r.status->map_stamp_sec == 0 && r.status->map_stamp_nanosec == 0
               ? &maps_.back()
               : nullptr;
  }

  bool write_run(records::RunRecord& record) {
    try {
      StoredMap* map = map_of(record);
      if (map != nullptr) {
        if (map->file.empty()) save_map(*map);
        records::MapReference ref;
        ref.file = map->file;
        ref.frame_id = config_.frame_id;
        ref.stamp_sec = map->stamp_sec;
        ref.stamp_nanosec = map->stamp_nanosec;
        ref.width = map->grid.width;
        ref.height = map->grid.height;
        ref.resolution = map->grid.resolution;
        ref.origin_x = map->grid.origin_x;
        ref.origin_y = map->grid.origin_y;
        // As the node built its grid (map.cost_source costmap: the costmap's own values).
        ref.set_build_options(node::planning_grid_options(config_));
        record.map = ref;
      }
      // The options the node plans with: its config's for the planner the run names (a
      // request names nothing else), as the node applies them (no costs for jps).
      // A request that named no planner (and a goal) ran the configured one, auto's options
      // included; one that named `auto` auto's; one that named a planner that planner's. A
      // request the recorder did not hear (its reader matched the client's writer after the
      // sample went out) is known by its status, which names the planner that ran: the
      // configured one's options where that is it, that planner's otherwise.
      const core::PlannerOptions configured = config_.planner.options();
      std::string requested = record.request ? record.request->planner : std::string();
      if (!record.request && record.status &&
          record.status->planner != core::to_string(configured.planner))
        requested = record.status->planner;
      const auto named = core::planner_kind_from_string(requested);
      core::PlannerOptions run_options = requested == core::kAutoPlannerName
                                             ? config_.planner.auto_options()
                                         : named ? config_.planner.options(*named)
                                                 : configured;
      core::drop_unsupported_costs(run_options);
      record.options = records::options_record(run_options);
      // What the bus brought is recorded as it came; what cannot be drawn is said.
      if (const core::Status checked = records::check_record(record, map ? &map->grid : nullptr);
          !checked.is_ok())
        spdlog::warn("run '{}': {}; its picture leaves out what does not fit", record.request_id,
                     checked.message);
      // The record streamed first (no JSON tree of its cells is built), then the picture.
      const std::string stem = records::safe_file_stem(record.request_id);
      if (!write_file(stem + ".json", [&](const std::string& path) {
            return records::write_json_file(path, record);
          }))
        return false;
      const std::string svg =
          render::render_svg(records::picture_of(record, map ? &map->grid : nullptr));
      if (!write_file(stem + ".svg",
                      [&](const std::string& path) { return render::write_text_file(path, svg); }))
        return false;
      ++runs_written_;
      spdlog::info("run '{}' {}: wrote {}", record.request_id,
                   record.status ? record.status->code_name : std::string("NO_STATUS"),
                   (out_dir_ / (stem + ".svg")).string());
      return true;
    } catch (const std::exception& e) {
      spdlog::error("run '{}' could not be recorded: {}", record.request_id, e.what());
      return false;
    }
  }

  void save_map(StoredMap& map) {
    const std::string stem =
        "map_" + std::to_string(map.stamp_sec) + "_" + std::to_string(map.stamp_nanosec);
    std::error_code ec;
    std::filesystem::create_directories(out_dir_ / "maps", ec);
    auto saved = maps::save_map_server(map.grid, (out_dir_ / "maps" / stem).string(),
                                       config_.map.occupied_threshold);
    if (!saved) {
      spdlog::error("could not save the slice: {}", saved.error().message);
      return;
    }
    map.file = "maps/" + stem + ".yaml";
  }

  // Writes out_dir/name through `write` (given the temporary path), then renames it in place.
  bool write_file(const std::string& name,
                  const std::function<core::Status(const std::string&)>& write) {
    const std::filesystem::path final_path = out_dir_ / name;
    const std::filesystem::path temp = out_dir_ / ("." + name + ".tmp");
    const core::Status written = write(temp.string());
    std::error_code ec;
    if (written.is_ok()) std::filesystem::rename(temp, final_path, ec);
    if (!written.is_ok() || ec) {
      spdlog::error("could not write {}: {}", final_path.string(),
                    written.is_ok() ? ec.message() : written.message);
      std::filesystem::remove(temp, ec);
      return false;
    }
    return true;
  }

  node::NodeConfig config_;
  std::filesystem::path out_dir_;
  std::chrono::milliseconds debug_wait_;
  records::OpenRuns runs_;
  Inbox& inbox_;
  size_t writing_bytes_ = 0;  // of the runs taken to be written, not yet written
  std::deque<StoredMap> maps_;
  std::deque<records::RequestRecord> goals_;
  std::optional<Eigen::Vector2d> robot_pose_;
  std::vector<Eigen::Vector2d> last_plan_;
  size_t runs_written_ = 0;
};

int render_command(const std::string& json_path, std::string svg_path) {
  auto svg = records::render_record_file(json_path);
  if (!svg) {
    spdlog::error("{}", svg.error().message);
    return kBadInput;
  }
  if (svg_path.empty())
    svg_path = std::filesystem::path(json_path).replace_extension(".svg").string();
  const core::Status written = render::write_text_file(svg_path, *svg);
  if (!written.is_ok()) {
    spdlog::error("--out: {}", written.message);
    return kBadInput;
  }
  spdlog::info("wrote {}", svg_path);
  return 0;
}

template <class PubSubType, class Listener>
core::Status subscribe(node::Participant& bus, const node::NodeConfig& config,
                       const std::string& name, node::TopicQos qos, Listener& listener) {
  auto topic = bus.topic<PubSubType>(node::dds_topic_name(config, name));
  if (!topic) return topic.error();
  auto reader = bus.reader(*topic, node::reader_qos(qos), &listener);
  if (!reader) return reader.error();
  return core::Status::ok();
}

}  // namespace

int main(int argc, char** argv) {
  // Blocks of 1 MiB and more (debug cells, pictures) are mapped each for itself and unmapped when
  // freed. By default glibc raises its mmap threshold to the largest block freed (up to 32 MiB)
  // and then serves such blocks from the arena of the thread asking (the DDS threads, the main
  // one), where a freed block stays resident: the process kept several runs' worth of freed
  // debug data besides what it held.
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
  node::init_logging("vnsba_recorder");
  CLI::App app{"vnsba_recorder: planning runs on the bus to SVG pictures and run records"};
  std::string out_dir, config_path = "";
  int domain = -1;
  std::optional<double> duration;
  std::optional<int64_t> runs_wanted;
  double debug_wait_s = 0.5;
  double max_open_mb = kDefaultMaxOpenMb;
  app.add_option("--out", out_dir, "folder for <id>.svg and <id>.json (created if missing)");
  app.add_option("--config", config_path, vnsba::node::kConfigOptionHelp);
  app.add_option("--domain", domain,
                 "DDS domain id 0..232 (overrides ROS_DOMAIN_ID and domain_id)");
  std::optional<std::string> ros_namespace;
  app.add_option("--namespace", ros_namespace, node::kNamespaceOptionHelp);
  std::optional<std::string> participant_profile;
  app.add_option("--participant-profile", participant_profile, node::kParticipantProfileOptionHelp);
  auto* duration_opt = app.add_option("--duration", duration, "stop after this many seconds");
  app.add_option("--runs", runs_wanted, "stop after this many runs are written")
      ->excludes(duration_opt);
  app.add_option("--debug-wait", debug_wait_s,
                 "seconds to wait for a run's debug data after its status")
      ->capture_default_str();
  app.add_option("--max-open-mb", max_open_mb,
                 "MiB at most held for runs not yet written and samples not yet handled (debug "
                 "data is dropped first); twice that while a run is drawn")
      ->capture_default_str();
  auto* render_cmd = app.add_subcommand("render", "redraw a run record as SVG");
  std::string record_path, render_out;
  render_cmd->add_option("record", record_path, "RUN.json written by the recorder")->required();
  render_cmd->add_option("--out", render_out, "SVG to write (default: RUN.svg beside the record)");
  if (const auto exit_code = node::parse_command_line(app, argc, argv)) return *exit_code;
  if (render_cmd->parsed()) return render_command(record_path, render_out);

  if (out_dir.empty()) {
    spdlog::error("--out: give the folder to write runs to");
    return kBadInput;
  }
  if (duration && !(*duration > 0 && *duration < 1e7)) {
    spdlog::error("--duration: must be a positive number of seconds");
    return kBadInput;
  }
  if (runs_wanted && *runs_wanted < 1) {
    spdlog::error("--runs: must be at least 1");
    return kBadInput;
  }
  if (!(debug_wait_s >= 0 && debug_wait_s <= 60)) {
    spdlog::error("--debug-wait: must be in [0, 60] seconds");
    return kBadInput;
  }
  if (!(max_open_mb > 0 && max_open_mb <= 1e6)) {
    spdlog::error("--max-open-mb: must be in (0, 1e6] MiB");
    return kBadInput;
  }
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec || !std::filesystem::is_directory(out_dir)) {
    spdlog::error("--out: cannot create folder {}: {}", out_dir, ec.message());
    return kBadInput;
  }
  const auto loaded =
      node::load_config_or_report(config_path, domain, ros_namespace, participant_profile);
  if (!loaded) return kBadInput;
  const node::NodeConfig& config = *loaded;

  // Signals are blocked before DDS starts its threads and taken in the loop below.
  const node::StopSignals stop;

  auto participant =
      node::Participant::create_configured(config, "vnsba_recorder", node::kRecorderEnclave);
  if (!participant) {
    spdlog::error("{}", participant.error().message);
    return kDdsFailure;
  }
  node::Participant& bus = **participant;
  const size_t max_open_bytes = static_cast<size_t>(max_open_mb * 1024 * 1024);
  Inbox inbox(max_open_bytes);
  const node::TopicNames& t = config.topics;
  Forwarder<node::OccupancyGridMsg> slices(inbox, t.projected_map);
  Forwarder<node::PlanRequestMsg> requests(inbox, t.plan_request);
  Forwarder<node::PoseStampedMsg, GoalEvent> goals(inbox, t.goal_pose);
  Forwarder<node::PoseStampedMsg, RobotPoseEvent> robot_poses(inbox, t.robot_pose);
  Forwarder<node::PathMsg> plans(inbox, t.plan);
  Forwarder<node::PlanStatusMsg> statuses(inbox, t.plan_status);
  Forwarder<node::PlannerDebugMsg, DebugEvent> debugs(inbox, t.planner_debug);
  using namespace nav_msgs::msg::dds_;
  using geometry_msgs::msg::dds_::PoseStamped_PubSubType;
  using namespace vnsba_msgs::msg::dds_;
  for (const core::Status& s : {
           // The debug reader first: the node records expansions only while one is matched.
           subscribe<PlannerDebug_PubSubType>(bus, config, t.planner_debug, node::TopicQos::kDebug,
                                              debugs),
           subscribe<PlanStatus_PubSubType>(bus, config, t.plan_status, node::TopicQos::kStatus,
                                            statuses),
           subscribe<Path_PubSubType>(bus, config, t.plan, node::TopicQos::kLatest, plans),
           subscribe<OccupancyGrid_PubSubType>(bus, config, t.projected_map,
                                               node::TopicQos::kLatched, slices),
           subscribe<PlanRequest_PubSubType>(bus, config, t.plan_request, node::TopicQos::kEvents,
                                             requests),
           subscribe<PoseStamped_PubSubType>(bus, config, t.goal_pose, node::TopicQos::kEvents,
                                             goals),
           subscribe<PoseStamped_PubSubType>(bus, config, t.robot_pose, node::TopicQos::kLatest,
                                             robot_poses),
       }) {
    if (!s.is_ok()) {
      spdlog::error("{}", s.message);
      return kDdsFailure;
    }
  }
  spdlog::info("recorder: ready (domain {}, writing to {})", config.domain_id, out_dir);

  Recorder recorder(config, out_dir,
                    std::chrono::milliseconds(static_cast<int64_t>(debug_wait_s * 1000)),
                    max_open_bytes, inbox);
  // No deadline: the largest time point (a plain value keeps GCC's uninitialized check quiet).
  const Clock::time_point deadline =
      duration ? Clock::now() + std::chrono::microseconds(static_cast<int64_t>(*duration * 1e6))
               : Clock::time_point::max();
  for (;;) {
    if (const auto received = stop.wait_for(std::chrono::milliseconds(50))) {
      spdlog::info("{} received: writing what was heard, then stopping",
                   node::StopSignals::name(*received));
      break;
    }
    recorder.handle_queued();
    recorder.write_ready(false);
    if (runs_wanted && recorder.runs_written() >= static_cast<size_t>(*runs_wanted)) break;
    if (Clock::now() >= deadline) break;
  }
  // No listener runs after delete_readers(); then the last samples are drained and written.
  bus.delete_readers();
  recorder.handle_queued();
  if (!runs_wanted || recorder.runs_written() < static_cast<size_t>(*runs_wanted))
    recorder.write_ready(true);
  bus.shutdown();
  spdlog::info("recorder: {} run(s) written to {}; {}; {}", recorder.runs_written(), out_dir,
               recorder.dropped_summary(), inbox.summary());
  return 0;
}
