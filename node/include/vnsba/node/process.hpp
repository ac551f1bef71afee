// Start-up shared by every executable on the bus (node, slicer, recorder, send_goal): logging
// to stderr, loading the config with --domain applied, and taking SIGINT/SIGTERM without a
// signal handler (no work and no I/O ever runs in signal context).
#pragma once

#include <chrono>
#include <csignal>
#include <optional>
#include <string>

#include "vnsba/node/config.hpp"

namespace vnsba::node {

// Sends spdlog's default logger to stderr as `program`, with a time-stamped pattern.
void init_logging(const std::string& program);

// Loads and validates the config; on errors logs every one of them (naming the file) and
// returns nullopt. An empty `path` (no --config) means find_default_config(). The first log line
// names the file read. A non-negative `domain_override` replaces domain_id (the --domain flag).
// Sets the log level from the config.
// A set `namespace_override` (the --namespace flag) replaces the config's namespace; a bad one
// is reported as an error naming --namespace.
// A set `profile_override` (the --participant-profile flag) replaces dds.participant_profile.
// A set `name_override` (vnsba_node's --name flag) replaces node_name; a bad one is reported as
// an error naming --name.
// A participant profile named either way is looked up in the Fast DDS XML profiles here (dds.hpp,
// profile_participant_qos): a name no profile has, or a missing or malformed profiles file, is
// an error naming the key or the flag (or the file).
std::optional<NodeConfig> load_config_or_report(
    const std::string& path, int domain_override,
    const std::optional<std::string>& namespace_override = std::nullopt,
    const std::optional<std::string>& profile_override = std::nullopt,
    const std::optional<std::string>& name_override = std::nullopt);

// Every bus tool's --namespace help text.
inline constexpr const char* kNamespaceOptionHelp =
    "ROS 2 namespace of the relative topic names (overrides namespace), e.g. robot7";

// Every bus tool's --participant-profile help text.
inline constexpr const char* kParticipantProfileOptionHelp =
    "Fast DDS XML <participant> profile to start from (overrides dds.participant_profile); the "
    "files are FASTRTPS_DEFAULT_PROFILES_FILE and ./DEFAULT_FASTRTPS_PROFILES.xml";

// Blocks SIGINT and SIGTERM in the calling thread, and so in every thread it starts later (DDS
// starts its own): create it first thing in main, before any participant.
class StopSignals {
 public:
  StopSignals();
  // The signal received within `timeout` (0 = just poll), or nullopt.
  std::optional<int> wait_for(std::chrono::milliseconds timeout) const;
  // Waits until one comes; returns it.
  int wait() const;
  static const char* name(int signal) { return signal == SIGINT ? "SIGINT" : "SIGTERM"; }
  // Unblocks the signals with their default action, in the calling thread: one that came and was
  // not taken ends the process now, killed by it, and so does one that comes later. Call it last
  // in a tool that does its work and exits once DDS is torn down: a shell that ran the tool when
  // the user pressed Ctrl-C must see a command the signal killed, or (bash's "wait and cooperative
  // exit") it takes the interrupt as handled and runs the script's next command.
  void release() const;

 private:
  sigset_t signals_;
};

}  // namespace vnsba::node
