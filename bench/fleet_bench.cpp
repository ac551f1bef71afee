// Fleet benchmark (issue 18): N simulated robots, each a client participant of its own in this
// process sending a plan_request at `rate` Hz on its own namespace (robotI), against
//   processes: N vnsba_node processes, one per robot (namespace: robotI), or
//   fleet:     one vnsba_node process with robots: [robot1, ..., robotN],
// every node reading one shared map (1000 x 1000 indoor floor, 5 cm cells, on /map). Each run
// uses simple discovery (multicast) or a Discovery Server (fast-discovery-server on loopback).
// Prints, per run: discovery time (all robots' request writers and status readers matched) and
// the loopback packets sent until then and per second while idle, request -> status latency
// p50/p99 (ms), statuses lost, and the nodes' total resident memory and CPU (% of one core) over
// the measured window. Nothing passes or fails: the targets are judged from the table.
//
//   vnsba_fleet_bench [--robots 50] [--seconds 60] [--rate 1] [--map-size 1000]
//                     [--mode processes|fleet|both] [--discovery simple|server|both]
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bench/indoor_map.hpp"
#include "nav_msgs/msg/OccupancyGridPubSubTypes.h"
#include "vnsba/node/config.hpp"
#include "vnsba/node/convert.hpp"
#include "vnsba/node/dds.hpp"
#include "vnsba_msgs/msg/PlanRequestPubSubTypes.h"
#include "vnsba_msgs/msg/PlanStatusPubSubTypes.h"

extern char** environ;

namespace {

using namespace vnsba;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

struct Options {
  int robots = 50;
  int seconds = 60;
  double rate_hz = 1.0;
  int map_size = 1000;
  std::vector<std::string> modes = {"processes", "fleet"};
  std::vector<std::string> discoveries = {"simple", "server"};
};

// A child process (a node or the discovery server), its output in `log`.
class Child {
 public:
  Child(const std::string& binary, const std::vector<std::string>& args, const std::string& log) {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    std::vector<char*> argv{const_cast<char*>(binary.c_str())};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    if (posix_spawn(&pid_, binary.c_str(), &actions, nullptr, argv.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
  }
  ~Child() { stop(); }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  pid_t pid() const { return pid_; }
  void stop() {
    if (pid_ <= 0) return;
    kill(pid_, SIGTERM);
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
  }

 private:
  pid_t pid_ = -1;
};

// /proc/<pid>/status VmRSS in MB; utime + stime of /proc/<pid>/stat in seconds.
double rss_mb(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("VmRSS:", 0) == 0) return std::atof(line.c_str() + 6) / 1024.0;
  return 0.0;
}
double cpu_seconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string stat((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t close = stat.rfind(')');  // the command name may hold spaces
  if (close == std::string::npos) return 0.0;
  std::istringstream fields(stat.substr(close + 2));
  std::string field;
  double utime = 0, stime = 0;
  for (int i = 3; i <= 15 && fields >> field; ++i) {
    if (i == 14) utime = std::atof(field.c_str());
    if (i == 15) stime = std::atof(field.c_str());
  }
  return (utime + stime) / static_cast<double>(sysconf(_SC_CLK_TCK));
}
// Packets sent on the loopback interface, by every process of the machine.
uint64_t loopback_packets() {
  std::ifstream in("/sys/class/net/lo/statistics/tx_packets");
  uint64_t n = 0;
  in >> n;
  return n;
}

// One robot's client: a request writer and a status reader on its namespace; statuses are
// matched to the send time of their request id.
class RobotClient : public node::dds::DataReaderListener {
 public:
  RobotClient(const node::NodeConfig& robot_cfg, const std::string& name) {
    auto participant = node::Participant::create(robot_cfg.domain_id, name, nullptr, false, {},
                                                 robot_cfg.discovery_servers);
    if (!participant) {
      std::fprintf(stderr, "%s: %s\n", name.c_str(), participant.error().message.c_str());
      return;
    }
    participant_ = std::move(participant).value();
    auto request_topic = participant_->topic<vnsba_msgs::msg::dds_::PlanRequest_PubSubType>(
        node::dds_topic_name(robot_cfg, robot_cfg.topics.plan_request));
    auto status_topic = participant_->topic<vnsba_msgs::msg::dds_::PlanStatus_PubSubType>(
        node::dds_topic_name(robot_cfg, robot_cfg.topics.plan_status));
    if (!request_topic || !status_topic) return;
    auto writer =
        participant_->writer(*request_topic, node::writer_qos(node::TopicQos::kEvents, false));
    auto reader =
        participant_->reader(*status_topic, node::reader_qos(node::TopicQos::kStatus), this);
    if (writer) request_ = *writer;
    if (reader) status_ = *reader;
  }
  ~RobotClient() override {
    if (participant_) participant_->shutdown();
  }
  bool matched() const {
    if (request_ == nullptr || status_ == nullptr) return false;
    node::dds::SubscriptionMatchedStatus sub;
    status_->get_subscription_matched_status(sub);
    return node::matched_readers(request_) > 0 && sub.current_count > 0;
  }
  // Sends a request from cell centre `a` to `b` (metres), remembering when.
  void send(const std::string& id, double ax, double ay, double bx, double by) {
    node::PlanRequestMsg request;
    request.id(id);
    request.start(node::to_pose_msg(ax, ay, 0, "map", node::now_msg()));
    request.goal(node::to_pose_msg(bx, by, 0, "map", node::now_msg()));
    std::lock_guard<std::mutex> lock(mutex_);
    sent_[id] = Clock::now();
    if (!node::write_sample(request_, &request)) ++write_failures_;
  }
  void on_data_available(node::dds::DataReader* reader) override {
    node::PlanStatusMsg msg;
    node::dds::SampleInfo info;
    while (reader->take_next_sample(&msg, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data || msg.subject() == node::wire::SUBJECT_MAP) continue;
      const auto now = Clock::now();
      std::lock_guard<std::mutex> lock(mutex_);
      const auto it = sent_.find(msg.request_id());
      if (it == sent_.end()) continue;
      answers_[msg.request_id()] = {
          std::chrono::duration<double, std::milli>(now - it->second).count(), msg.code()};
      cv_.notify_all();
    }
  }
  // The code of `id`'s status, waiting up to `timeout`; -1 if none came.
  int wait(const std::string& id, std::chrono::milliseconds timeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (!cv_.wait_for(lock, timeout, [&] { return answers_.count(id) > 0; })) return -1;
    return answers_[id].code;
  }
  struct Answer {
    double latency_ms;
    int code;
  };
  // Sent ids whose name starts with `prefix`, and their answers.
  void collect(const std::string& prefix, size_t* sent, std::vector<Answer>* answers) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [id, at] : sent_) {
      if (id.rfind(prefix, 0) != 0) continue;
      ++*sent;
      const auto it = answers_.find(id);
      if (it != answers_.end()) answers->push_back(it->second);
    }
  }
  size_t write_failures() {
    std::lock_guard<std::mutex> lock(mutex_);
    return write_failures_;
  }

 private:
  std::unique_ptr<node::Participant> participant_;
  node::dds::DataWriter* request_ = nullptr;
  node::dds::DataReader* status_ = nullptr;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::map<std::string, Clock::time_point> sent_;
  std::map<std::string, Answer> answers_;
  size_t write_failures_ = 0;
};

std::string robot_name(int r) {
  return "robot" + std::to_string(r + 1);
}

void run(const Options& o, const std::string& mode, const std::string& discovery, int run_index) {
  const std::string label = mode + "/" + discovery;
  const fs::path dir =
      fs::temp_directory_path() /
      ("vnsba_fleet_bench_" + std::to_string(getpid()) + "_" + std::to_string(run_index));
  fs::create_directories(dir);
  // default.yaml's configuration, which the fleet's nodes load under the YAML written below.
  node::NodeConfig base = node::default_config().config.value();
  base.domain_id = 1 + static_cast<int>((getpid() + run_index) % 200);
  base.topics.projected_map = "/map";  // absolute: one map for every namespace
  std::unique_ptr<Child> server;
  std::string common = "domain_id: " + std::to_string(base.domain_id) +
                       "\nlog_level: warn\ndebug: {publish: never}\ntopics: {projected_map: /map}\n"
                       "map: {max_cells: " +
                       std::to_string(int64_t{o.map_size} * o.map_size) + "}\n";
  if (discovery == "server") {
    if (std::string(VNSBA_DISCOVERY_SERVER).empty()) {
      std::printf("%-18s skipped: fast-discovery-server not found (fastdds-tools)\n",
                  label.c_str());
      return;
    }
    const std::string port = std::to_string(21000 + (getpid() + run_index) % 20000);
    server = std::make_unique<Child>(
        VNSBA_DISCOVERY_SERVER, std::vector<std::string>{"-i", "0", "-l", "127.0.0.1", "-p", port},
        (dir / "server.log").string());
    base.discovery_servers = {"127.0.0.1:" + port};
    common += "discovery: {servers: [\"127.0.0.1:" + port + "\"]}\n";
  }
  const uint64_t packets_before = loopback_packets();
  const auto t_start = Clock::now();
  std::vector<std::unique_ptr<Child>> nodes;
  if (mode == "processes") {
    for (int r = 0; r < o.robots; ++r) {
      const fs::path config = dir / (robot_name(r) + ".yaml");
      std::ofstream(config) << common << "namespace: " << robot_name(r) << "\n";
      nodes.push_back(std::make_unique<Child>(VNSBA_NODE_BINARY,
                                              std::vector<std::string>{"--config", config.string()},
                                              (dir / (robot_name(r) + ".log")).string()));
    }
  } else {
    const fs::path config = dir / "fleet.yaml";
    std::ofstream out(config);
    out << common << "robots: [";
    for (int r = 0; r < o.robots; ++r) out << (r ? ", " : "") << robot_name(r);
    out << "]\n";
    out.close();
    nodes.push_back(std::make_unique<Child>(VNSBA_NODE_BINARY,
                                            std::vector<std::string>{"--config", config.string()},
                                            (dir / "fleet.log").string()));
  }
  std::vector<std::unique_ptr<RobotClient>> robots;
  for (int r = 0; r < o.robots; ++r)
    robots.push_back(std::make_unique<RobotClient>(node::robot_view(base, robot_name(r)),
                                                   "fleet_bench_" + robot_name(r)));
  // Discovery: every robot's writer and reader matched with its node.
  bool all_matched = false;
  while (!all_matched && Clock::now() - t_start < std::chrono::seconds(120)) {
    all_matched = true;
    for (const auto& robot : robots) all_matched = all_matched && robot->matched();
    if (!all_matched) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const double discovery_s = std::chrono::duration<double>(Clock::now() - t_start).count();
  const uint64_t discovery_packets = loopback_packets() - packets_before;
  if (!all_matched) {
    std::printf("%-18s discovery did not complete in 120 s (logs in %s)\n", label.c_str(),
                dir.c_str());
    return;
  }
  // Idle traffic: participants' announcements and heartbeats with nothing to do.
  const uint64_t idle_before = loopback_packets();
  std::this_thread::sleep_for(std::chrono::seconds(3));
  const double idle_packets_per_s = (loopback_packets() - idle_before) / 3.0;

  // The shared map, latched, from a participant of its own.
  auto map_participant = node::Participant::create(base.domain_id, "fleet_bench_map", nullptr,
                                                   false, {}, base.discovery_servers)
                             .value();
  auto map_topic = map_participant
                       ->topic<nav_msgs::msg::dds_::OccupancyGrid_PubSubType>(
                           node::dds_topic_name(base, base.topics.projected_map))
                       .value();
  auto* map_writer =
      map_participant->writer(map_topic, node::writer_qos(node::TopicQos::kLatched, true)).value();
  const core::OccupancyGrid grid = bench::indoor_map(o.map_size, 0.05);
  auto slice = node::to_slice_msg(grid, "map", node::now_msg());
  map_writer->write(&slice);
  // Start and goal cells free on the grid the nodes plan on (the robot's radius inflated).
  auto map = core::GridMap::build(grid, node::planning_grid_options(base)).value();
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> coord(0, o.map_size - 1);
  auto free_cell = [&] {
    for (;;) {
      const core::Cell c{coord(rng), coord(rng)};
      if (!map.blocked(c)) return map.cell_centre_world(c);
    }
  };
  // Every node has the map once a probe from each robot plans (NO_MAP until then).
  const auto map_deadline = Clock::now() + std::chrono::seconds(120);
  for (int r = 0; r < o.robots; ++r) {
    for (int attempt = 0;; ++attempt) {
      const auto a = free_cell(), b = free_cell();
      const std::string id = "probe-" + std::to_string(attempt);
      robots[r]->send(id, a.x(), a.y(), b.x(), b.y());
      const int code = robots[r]->wait(id, std::chrono::seconds(5));
      if (code == node::wire::OK) break;
      if (Clock::now() > map_deadline) {
        std::printf("%-18s %s never planned (last code %d; logs in %s)\n", label.c_str(),
                    robot_name(r).c_str(), code, dir.c_str());
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
  }

  // The measured window: robot r sends at phase r / robots of each period.
  std::vector<double> cpu_before;
  for (const auto& n : nodes) cpu_before.push_back(cpu_seconds(n->pid()));
  const auto period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / o.rate_hz));
  const auto window_start = Clock::now();
  const int rounds = static_cast<int>(o.seconds * o.rate_hz);
  for (int k = 0; k < rounds; ++k) {
    for (int r = 0; r < o.robots; ++r) {
      std::this_thread::sleep_until(window_start + k * period + period * r / o.robots);
      const auto a = free_cell(), b = free_cell();
      robots[r]->send("goal-" + std::to_string(k), a.x(), a.y(), b.x(), b.y());
    }
  }
  std::this_thread::sleep_until(window_start + rounds * period);
  const double window_s = std::chrono::duration<double>(Clock::now() - window_start).count();
  double cpu = 0.0, rss = 0.0;
  for (size_t i = 0; i < nodes.size(); ++i) {
    cpu += cpu_seconds(nodes[i]->pid()) - cpu_before[i];
    rss += rss_mb(nodes[i]->pid());
  }
  // Late answers count; after 10 s a request is lost.
  for (int r = 0; r < o.robots; ++r)
    robots[r]->wait("goal-" + std::to_string(rounds - 1), std::chrono::seconds(10));
  std::vector<double> latencies;
  size_t sent = 0, answered = 0, not_ok = 0, write_failures = 0;
  for (const auto& robot : robots) {
    std::vector<RobotClient::Answer> answers;
    robot->collect("goal-", &sent, &answers);
    answered += answers.size();
    write_failures += robot->write_failures();
    for (const auto& a : answers) {
      latencies.push_back(a.latency_ms);
      not_ok += a.code != node::wire::OK;
    }
  }
  std::printf("%-18s %7.2f %9llu %8.0f %8zu %8.1f %8.1f %6zu %6zu %9.0f %7.0f\n", label.c_str(),
              discovery_s, static_cast<unsigned long long>(discovery_packets), idle_packets_per_s,
              sent, bench::percentile(latencies, 0.5), bench::percentile(latencies, 0.99),
              sent - answered + write_failures, not_ok, rss, 100.0 * cpu / window_s);
  std::fflush(stdout);
  robots.clear();
  nodes.clear();
  map_participant->shutdown();
  server.reset();
  std::error_code ignored;
  fs::remove_all(dir, ignored);
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // each line as it comes, also into a file
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const char* value = i + 1 < argc ? argv[i + 1] : nullptr;
    auto number = [&](double low, double high) {
      const double v = value ? std::atof(value) : 0.0;
      if (!value || !(v >= low && v <= high)) {
        std::fprintf(stderr, "%s: expected a number in [%g, %g]\n", arg.c_str(), low, high);
        std::exit(2);
      }
      ++i;
      return v;
    };
    if (arg == "--robots") {
      o.robots = static_cast<int>(number(1, 1000));
    } else if (arg == "--seconds") {
      o.seconds = static_cast<int>(number(1, 3600));
    } else if (arg == "--rate") {
      o.rate_hz = number(0.01, 100);
    } else if (arg == "--map-size") {
      o.map_size = static_cast<int>(number(40, 4096));
    } else if (arg == "--mode" && value &&
               (std::string(value) == "processes" || std::string(value) == "fleet" ||
                std::string(value) == "both")) {
      if (std::string(value) != "both") o.modes = {value};
      ++i;
    } else if (arg == "--discovery" && value &&
               (std::string(value) == "simple" || std::string(value) == "server" ||
                std::string(value) == "both")) {
      if (std::string(value) != "both") o.discoveries = {value};
      ++i;
    } else {
      std::fprintf(stderr,
                   "usage: vnsba_fleet_bench [--robots 50] [--seconds 60] [--rate 1] [--map-size "
                   "1000] [--mode processes|fleet|both] [--discovery simple|server|both]\n");
      return 2;
    }
  }
  std::printf(
      "vnsba fleet: %d robots, a request each at %g Hz for %d s, one %d x %d indoor map (5 cm), "
      "%u cores\n",
      o.robots, o.rate_hz, o.seconds, o.map_size, o.map_size, std::thread::hardware_concurrency());
  std::printf("%-18s %7s %9s %8s %8s %8s %8s %6s %6s %9s %7s\n", "mode/discovery", "disc_s",
              "disc_pkts", "idle_pps", "requests", "p50_ms", "p99_ms", "lost", "not_ok", "rss_MB",
              "cpu_%");
  int run_index = 0;
  for (const std::string& discovery : o.discoveries)
    for (const std::string& mode : o.modes) run(o, mode, discovery, run_index++);
  return 0;
}
