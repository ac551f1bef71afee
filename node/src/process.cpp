#include "vnsba/node/process.hpp"

#include <signal.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <csignal>
#include <ctime>
#include <filesystem>

#include "vnsba/node/dds.hpp"
#include "vnsba/node/security.hpp"

namespace vnsba::node {

void init_logging(const std::string& program) {
  if (auto existing = spdlog::get(program)) {
    spdlog::set_default_logger(existing);
  } else {
    spdlog::set_default_logger(spdlog::stderr_color_mt(program));
  }
  spdlog::set_pattern("[%H:%M:%S.%e] [%^%l%$] %v");
}

namespace {

// load_config_or_report's steps: each applies one override to `config` and logs why, or reports
// the problem and returns false.

// The domain: --domain, else ROS_DOMAIN_ID (as every ROS 2 node takes it), else domain_id.
bool apply_domain(NodeConfig& config, int domain_override) {
  const core::Expected<std::optional<int>> ros_domain = ros_domain_id_from_environment();
  if (!ros_domain) {
    spdlog::error("{}", ros_domain.error().message);
    return false;
  }
  if (domain_override >= 0) {
    if (*ros_domain && **ros_domain != domain_override)
      spdlog::info("DDS domain {} (--domain; ROS_DOMAIN_ID={} in the environment is not used)",
                   domain_override, **ros_domain);
    config.domain_id = domain_override;
  } else if (*ros_domain) {
    spdlog::info("DDS domain {} (ROS_DOMAIN_ID; domain_id {} of the config is not used)",
                 **ros_domain, config.domain_id);
    config.domain_id = **ros_domain;
  }
  return true;
}

bool apply_namespace(NodeConfig& config, const std::optional<std::string>& namespace_override) {
  if (!namespace_override) return true;
  auto ns = normalized_namespace(*namespace_override);
  if (!ns) {
    spdlog::error("--namespace: found \"{}\", expected {}", *namespace_override,
                  ns.error().message);
    return false;
  }
  config.ros_namespace = *ns;
  if (std::string problem = overlong_topic_name(config); !problem.empty()) {
    spdlog::error("--namespace: {}", problem);
    return false;
  }
  return true;
}

bool apply_node_name(NodeConfig& config, const std::optional<std::string>& name_override) {
  if (!name_override) return true;
  if (std::string problem = node_name_problem(*name_override); !problem.empty()) {
    spdlog::error("--name: found \"{}\", expected {}", *name_override, problem);
    return false;
  }
  config.node_name = *name_override;
  return true;
}

bool apply_participant_profile(NodeConfig& config,
                               const std::optional<std::string>& profile_override) {
  if (profile_override) config.participant_profile = *profile_override;
  if (config.participant_profile.empty()) return true;
  // Checked now, as a config error; the participant made later reads the same files. Fast DDS
  // may start its log thread while loading them: SIGINT and SIGTERM stay blocked in it (the
  // executables take them with sigwait, StopSignals), whether or not this thread blocks them.
  sigset_t stop_signals, previous;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop_signals, &previous);
  const auto profiled = profile_participant_qos(
      config.participant_profile,
      profile_override ? "--participant-profile" : "dds.participant_profile");
  pthread_sigmask(SIG_SETMASK, &previous, nullptr);
  if (!profiled) {
    spdlog::error("{}", profiled.error().message);
    return false;
  }
  return true;
}

// ROS_LOCALHOST_ONLY, and SROS2's ROS_SECURITY_* variables over the security section
// (node/security.hpp).
bool apply_environment(NodeConfig& config) {
  if (!config.localhost_only && ros_localhost_only_from_environment()) {
    spdlog::info("ROS_LOCALHOST_ONLY=1: DDS on the loopback interface only");
    config.localhost_only = true;
  }
  const auto security_environment = apply_security_environment(config.security);
  if (!security_environment) {
    spdlog::error("{}", security_environment.error().message);
    return false;
  }
  for (const std::string& line : *security_environment) spdlog::info("{}", line);
  return true;
}

}  // namespace

std::optional<NodeConfig> load_config_or_report(
    const std::string& given_path, int domain_override,
    const std::optional<std::string>& namespace_override,
    const std::optional<std::string>& profile_override,
    const std::optional<std::string>& name_override) {
  std::string path = given_path;
  if (path.empty()) {
    const core::Expected<std::string> found = find_default_config();
    if (!found) {
      spdlog::error("{}", found.error().message);
      return std::nullopt;
    }
    path = *found;
  }
  spdlog::info("config: {}", std::filesystem::absolute(path).lexically_normal().string());
  ConfigResult loaded = load_config(path);
  if (!loaded.config) {
    spdlog::error("{} error(s) in {}:", loaded.errors.size(), path);
    for (const std::string& e : loaded.errors) spdlog::error("  {}", e);
    return std::nullopt;
  }
  NodeConfig config = std::move(*loaded.config);
  if (!apply_domain(config, domain_override) || !apply_namespace(config, namespace_override) ||
      !apply_node_name(config, name_override) ||
      !apply_participant_profile(config, profile_override) || !apply_environment(config))
    return std::nullopt;
  spdlog::set_level(spdlog::level::from_str(config.log_level));
  return config;
}

StopSignals::StopSignals() {
  sigemptyset(&signals_);
  sigaddset(&signals_, SIGINT);
  sigaddset(&signals_, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals_, nullptr);
}

std::optional<int> StopSignals::wait_for(std::chrono::milliseconds timeout) const {
  const auto ms = timeout.count() > 0 ? timeout.count() : 0;
  const timespec interval{static_cast<time_t>(ms / 1000), static_cast<long>(ms % 1000) * 1'000'000};
  const int received = sigtimedwait(&signals_, nullptr, &interval);
  if (received == SIGINT || received == SIGTERM) return received;
  return std::nullopt;
}

void StopSignals::release() const {
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  pthread_sigmask(SIG_UNBLOCK, &signals_, nullptr);
}

int StopSignals::wait() const {
  int received = 0;
  while (sigwait(&signals_, &received) != 0 || (received != SIGINT && received != SIGTERM)) {
  }
  return received;
}

}  // namespace vnsba::node
