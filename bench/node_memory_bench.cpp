// The memory of the real vnsba_node on a big map (issue 47): starts the node with default.yaml
// (or --config) on a private domain, publishes a synthetic indoor slice (bench/indoor_map.hpp,
// 10,000 x 10,000 cells at 0.05 m by default), plans one long query across it (the centre of the
// first room to the centre of the last, corner to corner) and reports the node's resident memory
// from /proc/<pid>/status: VmRSS once idle, once the map is live, after the query, and VmHWM, the
// peak over the node's whole life. Prints a table and the node's "map accepted" line; no
// pass/fail. Not a test: run it by hand (docs/benchmarks.md).
//
// With --kept-results K it then sends K ComputePathToPose goals one after the other along the
// first row of rooms (each result kept by the node for a late get_result, actions.*) and reports
// the node's VmRSS growth per kept result beside the result's path size (its poses and encoded
// bytes), on a map of --size cells (use a small one, e.g. 2000).
//
//   vnsba_node_memory_bench [--size 10000] [--resolution 0.05] [--config FILE]
//                           [--kept-results K]
//
// Every process it starts is stopped on every way out: the node is sent SIGTERM (SIGKILL after
// 30 s) when the bench ends or fails, and the kernel kills it if the bench itself dies
// (PR_SET_PDEATHSIG).
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "bench/indoor_map.hpp"
#include "nav_msgs/msg/OccupancyGridPubSubTypes.h"
#include "nav_msgs/msg/PathPubSubTypes.h"
#include "node/src/take_listener.hpp"
#include "vnsba/node/action_client.hpp"
#include "vnsba/node/config.hpp"
#include "vnsba/node/convert.hpp"
#include "vnsba/node/dds.hpp"
#include "vnsba_msgs/msg/PlanRequestPubSubTypes.h"
#include "vnsba_msgs/msg/PlanStatusPubSubTypes.h"

namespace {

using namespace vnsba;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

struct Options {
  int size = 10000;          // cells a side
  double resolution = 0.05;  // metres per cell
  std::string config;        // empty: find_default_config()
  int kept_results = 0;      // ComputePathToPose goals to keep after the long query
};

// The node as a child process, its stdout and stderr in `log`. Stopped by the destructor.
class NodeProcess {
 public:
  NodeProcess(const std::vector<std::string>& argv, const fs::path& log) {
    const pid_t parent = getpid();
    std::fflush(nullptr);  // the child must not write the parent's buffered output again
    pid_ = fork();
    if (pid_ == 0) {
      // The node dies with the bench, whatever ends it (SIGKILL included).
      prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (getppid() != parent) _exit(127);
      std::FILE* out = std::freopen(log.c_str(), "w", stdout);
      if (out == nullptr || dup2(fileno(stdout), STDERR_FILENO) < 0) _exit(127);
      std::vector<char*> args;
      for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
      args.push_back(nullptr);
      execv(args[0], args.data());
      _exit(127);
    }
  }
  ~NodeProcess() { stop(); }
  NodeProcess(const NodeProcess&) = delete;
  NodeProcess& operator=(const NodeProcess&) = delete;

  pid_t pid() const { return pid_; }
  // Whether the node is still running (reaps it when it has exited).
  bool running() {
    if (pid_ <= 0) return false;
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == 0) return true;
    exit_status_ = status;
    pid_ = -1;
    return false;
  }
  std::optional<int> exit_status() const { return exit_status_; }
  // SIGTERM, then SIGKILL when it has not exited within 30 s.
  void stop() {
    if (!running()) return;
    kill(pid_, SIGTERM);
    const auto deadline = Clock::now() + std::chrono::seconds(30);
    while (running() && Clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (!running()) return;
    kill(pid_, SIGKILL);
    int status = 0;
    waitpid(pid_, &status, 0);
    exit_status_ = status;
    pid_ = -1;
  }

 private:
  pid_t pid_ = -1;
  std::optional<int> exit_status_;
};

// A field of /proc/<pid>/status in MiB (the kernel gives kB), or -1 when it cannot be read.
double proc_status_mib(pid_t pid, const std::string& field) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind(field + ":", 0) == 0) return std::atof(line.c_str() + field.size() + 1) / 1024.0;
  return -1.0;
}

// Requests to the node and their statuses.
class Client {
 public:
  explicit Client(const node::NodeConfig& cfg)
      : cfg_(cfg),
        status_listener_(node::make_listener<node::PlanStatusMsg>(
            [this](node::PlanStatusMsg&& msg, const node::dds::SampleInfo&) { on_status(msg); })) {
    auto participant = node::Participant::create(cfg.domain_id, "node_memory_bench", nullptr, false,
                                                 {}, cfg.discovery_servers);
    if (!participant) {
      std::fprintf(stderr, "%s\n", participant.error().message.c_str());
      return;
    }
    participant_ = std::move(participant).value();
    auto request_topic = participant_->topic<vnsba_msgs::msg::dds_::PlanRequest_PubSubType>(
        node::dds_topic_name(cfg, cfg.topics.plan_request));
    auto status_topic = participant_->topic<vnsba_msgs::msg::dds_::PlanStatus_PubSubType>(
        node::dds_topic_name(cfg, cfg.topics.plan_status));
    auto map_topic = participant_->topic<nav_msgs::msg::dds_::OccupancyGrid_PubSubType>(
        node::dds_topic_name(cfg, cfg.topics.projected_map));
    if (!request_topic || !status_topic || !map_topic) return;
    auto request =
        participant_->writer(*request_topic, node::writer_qos(node::TopicQos::kEvents, false));
    auto status = participant_->reader(*status_topic, node::reader_qos(node::TopicQos::kStatus),
                                       status_listener_.get());
    auto map = participant_->writer(*map_topic, node::writer_qos(node::TopicQos::kLatched, true));
    if (request) request_ = *request;
    if (status) status_ = *status;
    if (map) map_ = *map;
  }
  ~Client() {
    if (participant_) participant_->shutdown();
  }
  bool matched() const {
    if (request_ == nullptr || status_ == nullptr || map_ == nullptr) return false;
    node::dds::SubscriptionMatchedStatus sub;
    status_->get_subscription_matched_status(sub);
    return node::matched_readers(request_) > 0 && node::matched_readers(map_) > 0 &&
           sub.current_count > 0;
  }
  bool publish_slice(const core::OccupancyGrid& grid) {
    auto slice = node::to_slice_msg(grid, cfg_.frame_id, node::now_msg());
    return node::write_sample(map_, &slice);
  }
  void send(const std::string& id, double ax, double ay, double bx, double by) {
    node::PlanRequestMsg request;
    request.id(id);
    request.start(node::to_pose_msg(ax, ay, 0, cfg_.frame_id, node::now_msg()));
    request.goal(node::to_pose_msg(bx, by, 0, cfg_.frame_id, node::now_msg()));
    node::write_sample(request_, &request);
  }
  struct Answer {
    int code = -1;
    std::string message;
    size_t poses = 0;
    double time_ms = 0.0;  // the planner's own time
    std::string planner;
    int64_t expanded = 0;
  };
  // A status taken by the node's one listener template (take_listener.hpp).
  void on_status(const node::PlanStatusMsg& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (msg.subject() == node::wire::SUBJECT_MAP) {
      map_reports_.push_back(msg.message());
    } else {
      answers_[msg.request_id()] = {msg.code(),
                                    msg.message(),
                                    msg.path().poses().size(),
                                    static_cast<double>(msg.planning_time_us()) / 1000.0,
                                    msg.planner(),
                                    msg.expanded()};
    }
    cv_.notify_all();
  }
  std::optional<Answer> wait(const std::string& id, std::chrono::milliseconds timeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (!cv_.wait_for(lock, timeout, [&] { return answers_.count(id) > 0; })) return std::nullopt;
    return answers_[id];
  }
  node::Participant& participant() { return *participant_; }
  std::vector<std::string> map_reports() {
    std::lock_guard<std::mutex> lock(mutex_);
    return map_reports_;
  }

 private:
  node::NodeConfig cfg_;
  // Before the participant, which the destructor shuts down while the listener still lives.
  std::unique_ptr<node::TakingListener> status_listener_;
  std::unique_ptr<node::Participant> participant_;
  node::dds::DataWriter* request_ = nullptr;
  node::dds::DataWriter* map_ = nullptr;
  node::dds::DataReader* status_ = nullptr;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::map<std::string, Answer> answers_;
  std::vector<std::string> map_reports_;
};

// The first line of the node's log that contains `text` ("map accepted"), or "".
std::string log_line(const fs::path& log, const std::string& text) {
  std::ifstream in(log);
  for (std::string line; std::getline(in, line);)
    if (line.find(text) != std::string::npos) return line;
  return "";
}

// K goals along the first row of rooms, each kept by the node once it finished; prints the
// node's VmRSS growth per kept result.
bool measure_kept_results(const Options& o, const node::NodeConfig& cfg, Client& client,
                          NodeProcess& node_process, double near, double far) {
  auto action = node::ActionClient::create(
      client.participant(), node::ros_topic_name(cfg, cfg.topics.compute_path_to_pose),
      node::ActionKind::kComputePathToPose, node::WireMapping::kSampleIdentity);
  if (!action || !(*action)->wait_for_server(std::chrono::seconds(30))) return false;
  node::ActionGoalSpec goal;
  goal.start = node::to_pose_msg(near, near, 0, cfg.frame_id, node::now_msg());
  goal.goals = {node::to_pose_msg(far, near, 0, cfg.frame_id, node::now_msg())};
  // One goal first, so that what every goal allocates once (DDS endpoints' first samples, the
  // worker's buffers) is not counted.
  const auto first =
      (*action)->plan(node::ActionClient::random_id(), goal, std::chrono::seconds(60));
  if (!first || first->status != node::GoalState::kSucceeded) return false;
  const size_t poses = first->path.poses().size();
  nav_msgs::msg::dds_::Path_PubSubType path_type;
  node::PathMsg path = first->path;
  const size_t path_bytes = path_type.getSerializedSizeProvider(&path)();
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const double before = proc_status_mib(node_process.pid(), "VmRSS");
  int succeeded = 0;
  for (int k = 0; k < o.kept_results; ++k) {
    if (!node_process.running()) return false;
    const auto result =
        (*action)->plan(node::ActionClient::random_id(), goal, std::chrono::seconds(60));
    if (result && result->status == node::GoalState::kSucceeded) ++succeeded;
  }
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const double after = proc_status_mib(node_process.pid(), "VmRSS");
  const double per_result = (after - before) * double(1 << 20) / std::max(succeeded, 1);
  std::printf(
      "kept results: %d goals succeeded of %d, %zu poses each (path encoded %zu bytes, %.1f a "
      "pose); node VmRSS %.1f -> %.1f MiB: %.0f bytes per kept result, %.1f per pose\n",
      succeeded, o.kept_results, poses, path_bytes, double(path_bytes) / double(poses), before,
      after, per_result, per_result / double(poses));
  return succeeded == o.kept_results;
}

int run(const Options& o) {
  std::string config_path = o.config;
  if (config_path.empty()) {
    auto found = node::find_default_config();
    if (!found) {
      std::fprintf(stderr, "%s\n", found.error().message.c_str());
      return 1;
    }
    config_path = *found;
  }
  node::ConfigResult loaded = node::load_config(config_path);
  if (!loaded.config) {
    for (const std::string& e : loaded.errors) std::fprintf(stderr, "%s\n", e.c_str());
    return 1;
  }
  node::NodeConfig cfg = *loaded.config;
  cfg.domain_id = 100 + static_cast<int>(getpid() % 100);  // private: concurrent runs never meet
  const fs::path dir =
      fs::temp_directory_path() / ("vnsba_node_memory_bench_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const fs::path log = dir / "node.log";
  std::printf("config %s, domain %d, node log %s\n", config_path.c_str(), cfg.domain_id,
              log.c_str());

  NodeProcess node_process(
      {VNSBA_NODE_BINARY, "--config", config_path, "--domain", std::to_string(cfg.domain_id)}, log);
  const pid_t pid = node_process.pid();
  auto fail = [&](const std::string& why) {
    std::fprintf(stderr, "failed: %s (node log %s)\n", why.c_str(), log.c_str());
    return 1;
  };
  if (pid <= 0) return fail("cannot start " + std::string(VNSBA_NODE_BINARY));

  Client client(cfg);
  const auto discovery_deadline = Clock::now() + std::chrono::seconds(60);
  while (!client.matched()) {
    if (!node_process.running()) return fail("the node exited");
    if (Clock::now() > discovery_deadline) return fail("the node was not discovered in 60 s");
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const double idle_rss = proc_status_mib(pid, "VmRSS");

  // The slice, built and published; the bench keeps only the latched sample in its writer.
  const auto t_publish = Clock::now();
  {
    const core::OccupancyGrid grid = bench::indoor_map(o.size, o.resolution);
    if (!client.publish_slice(grid)) return fail("the slice could not be written");
  }
  // The centre of the first room and of the last (rooms of kIndoorRoomMetres, walls on their
  // upper and right sides): free for any robot smaller than a room.
  const double room = bench::kIndoorRoomMetres;
  const int rooms = static_cast<int>(o.size * o.resolution / room);
  const double near = 0.5 * room, far = (rooms - 0.5) * room;
  // The map is live once a short request in the first room plans (NO_MAP until then).
  const auto map_deadline = Clock::now() + std::chrono::seconds(600);
  double map_ready_s = 0.0;
  for (int attempt = 0;; ++attempt) {
    if (!node_process.running()) return fail("the node exited while converting the map");
    const std::string id = "probe-" + std::to_string(attempt);
    client.send(id, near, near, near + 0.5, near);
    const auto answer = client.wait(id, std::chrono::seconds(30));
    if (answer && answer->code == node::wire::OK) {
      map_ready_s = std::chrono::duration<double>(Clock::now() - t_publish).count();
      break;
    }
    if (!client.map_reports().empty())
      return fail("the map was refused: " + client.map_reports().back());
    if (Clock::now() > map_deadline) return fail("the map was not live within 600 s");
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
  }
  const double map_rss = proc_status_mib(pid, "VmRSS");

  client.send("long", near, near, far, far);
  const auto long_answer = client.wait("long", std::chrono::seconds(600));
  if (!node_process.running()) return fail("the node exited while planning");
  const double query_rss = proc_status_mib(pid, "VmRSS");
  const double peak_rss = proc_status_mib(pid, "VmHWM");
  if (!long_answer) return fail("no answer to the long query within 600 s");

  std::printf("\n%d x %d cells at %g m (%.0f m x %.0f m), %s\n", o.size, o.size, o.resolution,
              o.size * o.resolution, o.size * o.resolution, config_path.c_str());
  std::printf("%-34s %10s\n", "node resident memory", "MiB");
  std::printf("%-34s %10.0f\n", "idle (VmRSS)", idle_rss);
  std::printf("%-34s %10.0f\n", "map live (VmRSS)", map_rss);
  std::printf("%-34s %10.0f\n", "after the long query (VmRSS)", query_rss);
  std::printf("%-34s %10.0f\n", "peak (VmHWM)", peak_rss);
  std::printf("map live %.1f s after publishing\n", map_ready_s);
  std::printf(
      "long query (%.1f, %.1f) -> (%.1f, %.1f) m: %s, %s, %.0f ms, %lld expansions, %zu "
      "poses%s%s\n",
      near, near, far, far, long_answer->planner.c_str(),
      node::code_name(static_cast<uint8_t>(long_answer->code)).c_str(), long_answer->time_ms,
      static_cast<long long>(long_answer->expanded), long_answer->poses,
      long_answer->message.empty() ? "" : ": ", long_answer->message.c_str());
  std::printf("node: %s\n", log_line(log, "map accepted").c_str());
  if (o.kept_results > 0 && !measure_kept_results(o, cfg, client, node_process, near, far))
    return fail("the kept results could not be measured");
  node_process.stop();
  fs::remove_all(dir);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--size" && has_value) {
      o.size = std::atoi(argv[++i]);
    } else if (arg == "--resolution" && has_value) {
      o.resolution = std::atof(argv[++i]);
    } else if (arg == "--config" && has_value) {
      o.config = argv[++i];
    } else if (arg == "--kept-results" && has_value) {
      o.kept_results = std::atoi(argv[++i]);
    } else {
      std::fprintf(
          stderr,
          "usage: %s [--size CELLS] [--resolution METRES] [--config FILE] [--kept-results K]\n"
          "Starts vnsba_node, publishes an indoor slice of CELLS x CELLS (10000) and "
          "plans one long query; prints the node's resident memory.\n",
          argv[0]);
      return 2;
    }
  }
  if (o.size < 2 || !(o.resolution > 0.0) || o.size * o.resolution < bench::kIndoorRoomMetres) {
    std::fprintf(stderr, "--size and --resolution must give at least one %g m room\n",
                 bench::kIndoorRoomMetres);
    return 2;
  }
  return run(o);
}
