// vnsba_lifecycle: Nav2's lifecycle manager for one managed node, without ROS 2.
//
//   vnsba_lifecycle [--node NAME] [--mapping fastrtps | cyclonedds] [--bond-timeout S] [--wait S]
//                   [--config FILE] [--domain N] [--namespace NS] [--participant-profile NAME]
//                   get | set TRANSITION | startup [--watch] | shutdown
//
// It makes the calls nav2_lifecycle_manager makes (node::LifecycleManagerClient): the node's
// <namespace>/<NAME>/change_state and get_state services (lifecycle_msgs), in rmw_fastrtps's
// mapping (the default) or rmw_cyclonedds's, and the manager's side of the bond on `bond` under
// the namespace. NAME is the config's node_name unless --node gives one.
//
//   get        prints the node's state: "<label> <id>" ("active 3")
//   set T      one change_state: T a transition's label (configure, activate, deactivate,
//              cleanup, shutdown) or its id; prints "<T> succeeded|failed: <label> <id>" with the
//              state get_state gives afterwards
//   startup    configure, then activate, each checked with get_state as the manager does; after
//              activate the bond (heartbeat timeout --bond-timeout, default 4 s, Nav2's
//              bond_timeout; 0: no bond) must form within half of it. One line per step:
//              "configure: done". --watch then watches the bond every 200 ms, as the manager's
//              bond timer does, until SIGINT or SIGTERM (exit 0; the bond is broken on the way
//              out, as the manager's Bond objects break when destroyed), or until the node falls
//              silent for --bond-timeout: it prints "bond broken: <why>", resets the node
//              (deactivate, cleanup, each tried: the manager's hard reset) and exits 5
//   shutdown   deactivate, cleanup, shutdown, each tried even when one before failed (the
//              manager's shutdownAllNodes); one line per step
//
// --wait S (default 10) bounds each wait for the services and for each reply.
// Exit codes (kExitCodesHelp): 0 done; 1 the node refused a transition, ended in another state,
// or did not bond; 2 usage error; 3 no answer (no such node, or no reply within --wait); 4 DDS
// failure; 5 (--watch) the bond broke; 130 or 143 SIGINT or SIGTERM.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>

#include "vnsba/node/command_line.hpp"
#include "vnsba/node/config.hpp"
#include "vnsba/node/dds.hpp"
#include "vnsba/node/lifecycle_manager.hpp"
#include "vnsba/node/process.hpp"
#include "vnsba/node/security.hpp"

namespace {

namespace node = vnsba::node;
using node::LifecycleState;
using node::LifecycleTransition;
using node::ManagerStep;

constexpr int kOk = 0;
constexpr int kStepFailed = 1;
constexpr int kNoAnswer = 3;
constexpr int kDdsFailure = 4;
constexpr int kBondBroken = 5;
constexpr const char* kExitCodesHelp =
    "Exit codes: 0 done; 1 the node refused a transition, ended in another state or did not "
    "bond; 2 usage error; 3 no answer (no such node, or no reply within --wait); 4 DDS failure; "
    "5 (startup --watch) the bond broke; 130 or 143 SIGINT or SIGTERM.";

struct CommandLine {
  std::string config_path;
  std::optional<int> domain;
  std::optional<std::string> ros_namespace;
  std::optional<std::string> participant_profile;
  std::optional<std::string> node_name;
  std::string mapping = "fastrtps";
  double bond_timeout_s = 4.0;
  double wait_s = 10.0;
  std::string transition;
  bool watch = false;
};

std::string state_text(LifecycleState state) {
  return std::string(node::state_label(state)) + " " + std::to_string(static_cast<int>(state));
}

int exit_code_of(ManagerStep step) {
  switch (step) {
    case ManagerStep::kDone:
      return kOk;
    case ManagerStep::kNoService:
    case ManagerStep::kNoReply:
      return kNoAnswer;
    default:
      return kStepFailed;
  }
}

const char* step_label(LifecycleTransition t) {
  for (const node::LifecycleEdge& edge : node::lifecycle_edges())
    if (edge.id == t) return edge.label;
  return "?";
}

// Prints one line per step of startup / shutdown / reset.
void print_step(LifecycleTransition t, ManagerStep step) {
  std::printf("%s: %s\n", step_label(t), node::to_string(step));
  std::fflush(stdout);
}

int watch_bond(node::LifecycleManagerClient& manager, const node::StopSignals& signals) {
  const std::string& name = manager.options().bond_id;
  for (;;) {
    if (const std::optional<int> signal = signals.wait_for(std::chrono::milliseconds(200))) {
      spdlog::info("{}: stopping the watch", node::StopSignals::name(*signal));
      return 128 + *signal;
    }
    if (manager.bond_state() == node::BondState::kDead) {
      // checkBondConnections: "CRITICAL FAILURE: SERVER %s IS DOWN after not receiving a
      // heartbeat for %i ms. Shutting down related nodes.", then reset(true).
      std::printf("bond broken: server %s is down (no heartbeat for %lld ms)\n", name.c_str(),
                  static_cast<long long>(manager.options().bond_timeout.count()));
      std::fflush(stdout);
      manager.reset(print_step);
      return kBondBroken;
    }
  }
}

int run(int argc, char** argv, const node::StopSignals& signals) {
  node::init_logging("vnsba_lifecycle");
  CLI::App app{"vnsba_lifecycle: Nav2's lifecycle manager's calls to one managed node"};
  app.footer(kExitCodesHelp);
  app.require_subcommand(1);
  CommandLine line;
  app.add_option("--config", line.config_path, node::kConfigOptionHelp);
  app.add_option("--domain", line.domain,
                 "DDS domain id 0..232 (overrides ROS_DOMAIN_ID and domain_id)")
      ->check(CLI::Range(0, 232));
  app.add_option("--namespace", line.ros_namespace, node::kNamespaceOptionHelp);
  app.add_option("--participant-profile", line.participant_profile,
                 node::kParticipantProfileOptionHelp);
  app.add_option("--node", line.node_name,
                 "the managed node's name (default: the config's node_name), e.g. planner_server");
  app.add_option("--mapping", line.mapping,
                 "the services' wire mapping: fastrtps (rmw_fastrtps) or cyclonedds "
                 "(rmw_cyclonedds)")
      ->check(CLI::IsMember({"fastrtps", "cyclonedds"}));
  app.add_option("--bond-timeout", line.bond_timeout_s,
                 "seconds of the node's silence that break the bond (Nav2's bond_timeout; 0: "
                 "no bond), 0..3600")
      ->check(CLI::Range(0.0, 3600.0));
  app.add_option("--wait", line.wait_s,
                 "seconds to wait for the services and for each reply, 0.1..3600")
      ->check(CLI::Range(0.1, 3600.0));
  app.add_subcommand("get", "print the node's state");
  CLI::App* set = app.add_subcommand("set", "one change_state");
  set->add_option("transition", line.transition,
                  "a transition's label (configure, activate, deactivate, cleanup, shutdown) or "
                  "id")
      ->required();
  CLI::App* startup = app.add_subcommand("startup", "configure, activate, bond");
  startup->add_flag("--watch", line.watch,
                    "then watch the bond until SIGINT / SIGTERM or until it breaks");
  app.add_subcommand("shutdown", "deactivate, cleanup, shutdown");
  if (const auto exit_code = node::parse_command_line(app, argc, argv)) return *exit_code;

  const std::optional<node::NodeConfig> loaded =
      node::load_config_or_report(line.config_path, line.domain.value_or(-1), line.ros_namespace,
                                  line.participant_profile, line.node_name);
  if (!loaded) return node::kExitUsage;
  const node::NodeConfig& config = *loaded;

  auto participant =
      node::Participant::create_configured(config, "vnsba_lifecycle", node::kSendGoalEnclave);
  if (!participant) {
    spdlog::error("{}", participant.error().message);
    return kDdsFailure;
  }
  node::LifecycleManagerOptions options;
  options.node_full_name = node::node_full_name(config);
  options.bond_id = config.node_name;
  options.bond_topic = node::dds_topic_name(config, "bond");
  options.mapping = line.mapping == "cyclonedds" ? node::WireMapping::kRequestHeader
                                                 : node::WireMapping::kSampleIdentity;
  options.bond_timeout = std::chrono::milliseconds(std::llround(line.bond_timeout_s * 1000.0));
  options.service_wait = std::chrono::milliseconds(std::llround(line.wait_s * 1000.0));
  options.reply_wait = options.service_wait;
  int code = kOk;
  {
    auto manager = node::LifecycleManagerClient::create(**participant, options);
    if (!manager) {
      spdlog::error("{}", manager.error().message);
      return kDdsFailure;
    }
    node::LifecycleManagerClient& m = **manager;
    const std::string command = app.get_subcommands().front()->get_name();
    if (!m.wait_for_services(options.service_wait)) {
      spdlog::error("no lifecycle services of {} within {} s (change_state, get_state)",
                    options.node_full_name, line.wait_s);
      code = kNoAnswer;
    } else if (command == "get") {
      const std::optional<LifecycleState> state = m.get_state();
      if (state)
        std::printf("%s\n", state_text(*state).c_str());
      else
        code = kNoAnswer;
    } else if (command == "set") {
      // A label is sent as the label (rclcpp_lifecycle takes a non-empty label over the id);
      // a number as the id.
      char* end = nullptr;
      const long id = std::strtol(line.transition.c_str(), &end, 10);
      const bool numeric = end != line.transition.c_str() && *end == '\0';
      if (numeric && (id < 0 || id > 255)) {
        spdlog::error("set: transition id {} is not in 0..255", id);
        code = node::kExitUsage;
      } else {
        const std::optional<bool> ok =
            numeric ? m.change_state_only(static_cast<LifecycleTransition>(id))
                    : m.change_state_only(LifecycleTransition::kCreate, line.transition);
        const std::optional<LifecycleState> state = ok ? m.get_state() : std::nullopt;
        if (!ok || !state) {
          code = kNoAnswer;
        } else {
          std::printf("%s %s: %s\n", line.transition.c_str(), *ok ? "succeeded" : "failed",
                      state_text(*state).c_str());
          code = *ok ? kOk : kStepFailed;
        }
      }
    } else if (command == "startup") {
      code = exit_code_of(m.startup(print_step));
      if (code == kOk && options.bond_timeout.count() > 0) {
        std::printf("bond formed with %s\n", options.bond_id.c_str());
        std::fflush(stdout);
      }
      if (code == kOk && line.watch) code = watch_bond(m, signals);
    } else {  // shutdown
      code = exit_code_of(m.shutdown(print_step));
    }
  }
  (*participant)->shutdown();
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  const vnsba::node::StopSignals stop_signals;
  const int code = run(argc, argv, stop_signals);
  std::fflush(stdout);
  stop_signals.release();
  if (code == 128 + SIGINT || code == 128 + SIGTERM) std::raise(code - 128);
  return code;
}
