// vnsba_node [--config FILE] [--domain N] [--namespace NS] [--name NAME]
// [--participant-profile NAME]: the DDS planner node, a ROS 2 managed node (managed_node.hpp).
//
// SIGINT and SIGTERM are blocked in every thread and taken by sigwait() in main: no signal
// handler runs, so nothing unsafe happens in one; the node then drains and exits 0.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cstdio>

#include "vnsba/node/command_line.hpp"
#include "vnsba/node/managed_node.hpp"
#include "vnsba/node/planner_node.hpp"
#include "vnsba/node/process.hpp"

int main(int argc, char** argv) {
  CLI::App app{"vnsba_node: VNS-BA* global path planner on DDS"};
  std::string config_path = "";
  int domain = -1;
  app.add_option("--config", config_path, vnsba::node::kConfigOptionHelp);
  app.add_option("--domain", domain,
                 "DDS domain id 0..232 (overrides ROS_DOMAIN_ID and domain_id)");
  std::optional<std::string> ros_namespace;
  app.add_option("--namespace", ros_namespace, vnsba::node::kNamespaceOptionHelp);
  std::optional<std::string> node_name;
  app.add_option("--name", node_name,
                 "the node's ROS 2 name (overrides node_name): its lifecycle services are "
                 "/<namespace>/<name>/change_state, ...; e.g. planner_server");
  std::optional<std::string> participant_profile;
  app.add_option("--participant-profile", participant_profile,
                 vnsba::node::kParticipantProfileOptionHelp);
  bool print_config = false;
  app.add_flag("--print-config", print_config,
               "print the whole configuration the config file and flags give (every key, "
               "default.yaml's value where the file leaves one out) as YAML, and exit");
  if (const auto exit_code = vnsba::node::parse_command_line(app, argc, argv)) return *exit_code;

  vnsba::node::init_logging("vnsba_node");  // logs go to stderr
  const vnsba::node::StopSignals stop;      // before any thread exists
  auto load = [=] {
    return vnsba::node::load_config_or_report(config_path, domain, ros_namespace,
                                              participant_profile, node_name);
  };
  const auto config = load();
  if (!config) return vnsba::node::kExitUsage;
  if (print_config) {
    std::fputs(vnsba::node::config_as_yaml(*config).c_str(), stdout);
    return 0;
  }

  // Configure reads the config again (lifecycle: managed), with the same flags.
  vnsba::node::ManagedNode node(*config, load);
  if (vnsba::core::Status status = node.start(); !status.is_ok()) {
    spdlog::critical("could not start: {}", status.message);
    return 1;
  }
  const int received = stop.wait();
  spdlog::info("{} received: draining and shutting down", vnsba::node::StopSignals::name(received));
  node.stop();
  // The work's figures, when it ran (a managed node may be unconfigured or finalized).
  if (const auto stats = node.final_stats())
    spdlog::info("stopped: {} requests, {} statuses, {} maps accepted, {} rejected",
                 stats->requests_received, stats->statuses_published, stats->maps_accepted,
                 stats->maps_rejected);
  return 0;
}
