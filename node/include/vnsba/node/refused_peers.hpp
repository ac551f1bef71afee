// Remote participants that DDS Security keeps out, logged by a secured participant: one warning
// per remote participant, naming its GUID prefix, the name and certificate it announced, and
// why (issue 31: a peer from another CA was rejected with no line on the node).
//
// Fast DDS 2.9 tells a participant little. Discovery comes first (on_participant_discovery,
// before any authentication), then PKI-DH's handshake: the participant of the smaller GUID
// sends the request and the other checks its certificate first.
// - When this participant refuses the remote, its listener hears onParticipantAuthentication
//   with UNAUTHORIZED_PARTICIPANT and the remote's GUID. Fast DDS logs the exact reason just
//   before, on the same thread, but as a warning (category SECURITY_AUTHENTICATION,
//   "Invalidation error of certificate  (unable to get local issuer certificate)"), which its
//   default verbosity (errors) drops: the line says what this participant checked, and adds
//   the newest security line of Fast DDS's log when its verbosity lets one through.
// - When the remote refuses this participant, nothing at all arrives here: this participant's
//   request stays unanswered (Fast DDS resends it every 0.5 s, forever). So does a remote whose
//   governance differs. Such a remote is reported once it has stayed unauthenticated
//   `handshake_timeout` after its discovery; the log's security lines that name its GUID (a
//   refusal of its permissions does) are the reason when there are any.
// - A remote without DDS Security is refused at once (UNAUTHORIZED), and said to be one.
// A remote that authenticates (AUTHORIZED_PARTICIPANT) or leaves first is never reported; one
// that authenticates after it was reported gets an info line saying so.
//
// A DomainParticipantListener forwards its two callbacks here. Thread-safe; the timeout is
// watched by a thread of its own, stopped with the object.
#pragma once

#include <fastdds/rtps/participant/ParticipantDiscoveryInfo.h>  // and ParticipantAuthenticationInfo

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>

namespace vnsba::node {

class RefusedPeers {
 public:
  // A handshake on one host takes milliseconds; across a network with lost messages, a few
  // resends of 0.5 s.
  static constexpr std::chrono::milliseconds kHandshakeTimeout{10000};
  // Remote participants followed at once, and reported in all: past these a spoofed discovery
  // flood is one warning, not unbounded memory.
  static constexpr size_t kMaxPending = 1000;
  static constexpr size_t kMaxReported = 10000;

  explicit RefusedPeers(std::chrono::milliseconds handshake_timeout = kHandshakeTimeout);
  ~RefusedPeers();
  RefusedPeers(const RefusedPeers&) = delete;
  RefusedPeers& operator=(const RefusedPeers&) = delete;

  // From DomainParticipantListener::on_participant_discovery (every status: a participant that
  // leaves is forgotten). `local` is the listener's participant: when it has no authentication
  // plugin (security off, or Permissive running open) nothing is followed, since no remote
  // would ever authenticate with it.
  void on_participant_discovery(const eprosima::fastdds::dds::DomainParticipant* local,
                                const eprosima::fastrtps::rtps::ParticipantDiscoveryInfo& info);
  // From DomainParticipantListener::onParticipantAuthentication.
  void on_participant_authentication(
      const eprosima::fastrtps::rtps::ParticipantAuthenticationInfo& info);

 private:
  struct Pending {
    std::string announced;      // "'name', certificate /CN=... of CA /CN=..." as it announced it
    bool has_identity = false;  // it announced a DDS Security identity
    // A Cyclone DDS participant whose GUID sorts above ours: this participant (Fast DDS 2.9)
    // starts the handshake with a key agreement Cyclone DDS 0.10 cannot read.
    bool cyclone_waits_for_us = false;
    std::chrono::steady_clock::time_point deadline;
  };
  void report(const std::string& prefix, const std::string& announced, const std::string& why);
  void watch();

  const std::chrono::milliseconds timeout_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::map<std::string, Pending> pending_;  // by GUID prefix, under mutex_
  std::set<std::string> reported_;          // GUID prefixes, under mutex_
  bool flooded_ = false;                    // kMaxPending or kMaxReported reached, said once
  std::optional<bool> secured_;             // whether `local` authenticates, once known
  bool stopping_ = false;
  std::thread watcher_;
};

// Makes Fast DDS's security warnings and errors available as reasons (a Fast DDS log consumer,
// registered once per process). Call it after anything that replaces Fast DDS's consumers
// (Log::ClearConsumers drops it: dds.cpp does that when it creates the first secured
// participant); RefusedPeers calls it too, so without that only the first refusal of a process
// may lack its reason.
void install_security_reason_log();

}  // namespace vnsba::node
