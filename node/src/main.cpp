// vnsba_node --config FILE [--domain N]: the DDS planner node.
//
// SIGINT and SIGTERM are blocked in every thread and taken by sigwait() in main: no signal
// handler runs, so nothing unsafe happens in one; the node then drains and exits 0.
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdio>

#include "vnsba/node/config.hpp"
#include "vnsba/node/planner_node.hpp"

int main(int argc, char** argv) {
  CLI::App app{"vnsba_node: VNS-BA* global path planner on DDS"};
  std::string config_path = "config/default.yaml";
  int domain = -1;
  app.add_option("--config", config_path, "YAML configuration file")->capture_default_str();
  app.add_option("--domain", domain, "DDS domain id 0..232 (overrides domain_id)");
  CLI11_PARSE(app, argc, argv);

  vnsba::node::ConfigResult loaded = vnsba::node::load_config(config_path);
  if (!loaded.config) {
    std::fprintf(stderr, "vnsba_node: %zu error(s) in %s:\n", loaded.errors.size(),
                 config_path.c_str());
    for (const std::string& e : loaded.errors) std::fprintf(stderr, "  %s\n", e.c_str());
    return 2;
  }
  vnsba::node::NodeConfig config = *loaded.config;
  if (domain >= 0) config.domain_id = domain;
  spdlog::set_default_logger(spdlog::stderr_color_mt("vnsba_node"));  // logs go to stderr
  spdlog::set_level(spdlog::level::from_str(config.log_level));
  spdlog::set_pattern("[%H:%M:%S.%e] [%^%l%$] %v");

  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);  // before any thread exists

  vnsba::node::PlannerNode node(config);
  if (vnsba::core::Status status = node.start(); !status.is_ok()) {
    spdlog::critical("could not start: {}", status.message);
    return 1;
  }
  int received = 0;
  sigwait(&signals, &received);
  spdlog::info("{} received: draining and shutting down",
               received == SIGINT ? "SIGINT" : "SIGTERM");
  node.stop();
  const auto stats = node.stats();
  spdlog::info("stopped: {} requests, {} statuses, {} maps accepted, {} rejected",
               stats.requests_received, stats.statuses_published, stats.maps_accepted,
               stats.maps_rejected);
  return 0;
}
