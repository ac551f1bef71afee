// The DDS plumbing every executable shares: one participant, the QoS of the topic table in
// docs/node.md, entity creation in order with every step checked, and teardown through
// delete_contained_entities().
//
// Rules learned the hard way (docs/architecture.md, "Rules the code keeps"): UDP only (shared
// memory fails silently across users and containers), data sharing off, payloads allocated per
// sample and freed with it (DYNAMIC_RESERVE: maps are megabytes and debug samples vary; see
// apply_common), no type information on the wire (Cyclone DDS drops such matches), and a short
// heartbeat on latched writers so late joiners get the map quickly.
#pragma once

#include <array>
#include <atomic>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>

#include "vnsba/core/status.hpp"
#include "vnsba/node/config.hpp"
#include "vnsba/node/convert.hpp"
#include "vnsba/node/refused_peers.hpp"

namespace vnsba::node {

namespace dds = eprosima::fastdds::dds;

// The QoS profiles of the topic table.
enum class TopicQos {
  kLatched,  // reliable, transient local, keep last 1: the slice (and the octomap)
  kEvents,   // reliable, volatile, keep all: requests and goals; nothing dropped
  // Statuses: reliable and volatile, as a ROS 2 client's default reader; keep all on both sides:
  // the writer holds at most kStatusHistory unacknowledged statuses, and a write into a full
  // history waits for acknowledgements (never overwrites one). A volatile writer drops a status
  // from its history once every matched reader acknowledged it, so the history holds only what
  // is in flight: a transient-local one kept its last 1,024 with their paths per robot for ever
  // (a 10-robot node grew to 340 MB). A requester's answer is held until the node has matched
  // its reader (requests.reply_wait), so no history is needed.
  kStatus,
  kLatest,  // reliable, volatile, keep last 1: robot pose, path
  kDebug,   // reliable, volatile, keep last 8: debug, so back-to-back runs are not replaced
  // Readers of tf and clock: best effort (matches reliable and best-effort writers alike),
  // volatile, keep last 100 (ROS 2's tf listener depth): only the newest value matters.
  kStream,
  // The reader of /tf_static: reliable, transient local (static broadcasters publish once,
  // latched), keep last 100, as tf2_ros's static listener.
  kStatic,
};

constexpr int32_t kStatusHistory = 1024;

dds::DataWriterQos writer_qos(TopicQos profile, bool large_samples);
dds::DataReaderQos reader_qos(TopicQos profile);
// The profile in words, for messages: "reliable, transient local, keep last 1".
std::string describe(TopicQos profile);

// The node participant's own events, on DDS threads; attach it at Participant::create so that
// endpoints discovered at once are seen too; it must outlive the participant.
// - Once per remote participant, a writer on `topic_name` in a participant other than the one it
//   listens on: on the status topic that is a second node answering every request.
//   `on_other(participant_name, guid_prefix)` is called.
// - Incompatible QoS on any of the participant's readers or writers (a remote endpoint that will
//   never match, so nothing flows and nothing else says why): logged as a warning once per remote
//   endpoint (each increment of the status's total count), naming the topic, the policy and
//   `fix(topic, policy)`, the config key or QoS that makes them match.
class ParticipantWatch : public dds::DomainParticipantListener {
 public:
  using OnOther = std::function<void(const std::string& name, const std::string& guid_prefix)>;
  using FixHint = std::function<std::string(const std::string& topic, const std::string& policy)>;
  // `topic_names`: the status topics (one per robot) another participant must not write.
  ParticipantWatch(std::set<std::string> topic_names, OnOther on_other, FixHint fix = nullptr)
      : topic_names_(std::move(topic_names)),
        on_other_(std::move(on_other)),
        fix_(std::move(fix)) {}

  void on_participant_discovery(dds::DomainParticipant* participant,
                                eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override;
  // A secured node logs each remote participant it refuses, once (RefusedPeers).
  void onParticipantAuthentication(
      dds::DomainParticipant*,
      eprosima::fastrtps::rtps::ParticipantAuthenticationInfo&& info) override {
    if (report_refused_) refused_.on_participant_authentication(info);
  }
  // Refused peers go unreported by this watch (call before the participant is created): a
  // second participant of the same identity in the process (the lifecycle's, managed_node.hpp)
  // refuses the same peers the first one reports.
  void leave_refused_peers_unreported() { report_refused_ = false; }
  void on_publisher_discovery(dds::DomainParticipant* participant,
                              eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) override;
  void on_requested_incompatible_qos(dds::DataReader* reader,
                                     const dds::RequestedIncompatibleQosStatus& status) override;
  void on_offered_incompatible_qos(dds::DataWriter* writer,
                                   const dds::OfferedIncompatibleQosStatus& status) override;
  // Incompatible remote endpoints seen so far, on every reader and writer.
  size_t incompatible_qos() const;
  // Remote participants seen writing the topic so far.
  size_t count() const;
  // The vendor id a remote participant announced (eProsima 01.0f, Eclipse Cyclone 01.10), while
  // it is known: a service's server picks each client's reply mapping by it (service_wire.hpp,
  // choose_mapping).
  std::optional<std::array<uint8_t, 2>> vendor_of(
      const eprosima::fastrtps::rtps::GuidPrefix_t& prefix) const;

 private:
  const std::set<std::string> topic_names_;
  OnOther on_other_;
  mutable std::mutex mutex_;
  std::map<std::string, std::string> names_;               // guid prefix -> participant name
  std::set<std::string> reported_;                         // guid prefixes
  std::map<std::string, std::array<uint8_t, 2>> vendors_;  // guid prefix -> vendor id
  FixHint fix_;
  std::atomic<size_t> incompatible_qos_{0};
  RefusedPeers refused_;
  bool report_refused_ = true;
  void report_incompatible(const std::string& topic, bool ours_reads, uint32_t policy_id,
                           int32_t new_endpoints);
};

// One DomainParticipant with a publisher and a subscriber. Not copyable; the destructor deletes
// every contained entity, then the participant.
class Participant {
 public:
  // `listener` (may be null) receives discovery events from the start; it must outlive this.
  // `localhost_only`: UDP on 127.0.0.1 only (network.localhost_only, ROS_LOCALHOST_ONLY=1).
  // `security` (security.hpp; give it the executable's default enclave with
  // with_default_enclave): when enabled, the enclave's files are checked first and the
  // participant is created with Fast DDS's builtin security plugins. Enforce: any failure is an
  // error naming the files at fault, never an open participant. Permissive without an enclave:
  // an open participant and a warning (as SROS2).
  // `participant_profile` (dds.participant_profile): the Fast DDS XML participant profile to
  // start from (profile_participant_qos); the node's rules go on top.
  static core::Expected<std::unique_ptr<Participant>> create(
      int domain_id, const std::string& name, dds::DomainParticipantListener* listener = nullptr,
      bool localhost_only = false, const SecurityConfig& security = {},
      const std::vector<std::string>& discovery_servers = {},
      const std::string& participant_profile = "");
  // The participant of a process run from `config`: its domain, localhost_only, security (with
  // `default_enclave` unless the config names an enclave), discovery servers and participant
  // profile. `name`: the participant's name; `listener` as create's.
  static core::Expected<std::unique_ptr<Participant>> create_configured(
      const NodeConfig& config, const std::string& name, const std::string& default_enclave,
      dds::DomainParticipantListener* listener = nullptr);
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  // Registers PubSubType (once per participant) and creates or returns the topic `topic_name`.
  template <class PubSubType>
  core::Expected<dds::Topic*> topic(const std::string& topic_name) {
    auto it = topics_.find(topic_name);
    if (it != topics_.end()) return it->second;
    dds::TypeSupport type(new PubSubType());
    type->auto_fill_type_information(false);
    type->auto_fill_type_object(false);
    return make_topic(topic_name, type);
  }

  // The topic `topic_name` of PubSubType and a writer (reader) on it, in one checked step.
  template <class PubSubType>
  core::Expected<dds::DataWriter*> writer_on(const std::string& topic_name,
                                             const dds::DataWriterQos& qos,
                                             dds::DataWriterListener* listener = nullptr) {
    auto t = topic<PubSubType>(topic_name);
    if (!t) return t.error();
    return writer(*t, qos, listener);
  }
  template <class PubSubType>
  core::Expected<dds::DataReader*> reader_on(const std::string& topic_name,
                                             const dds::DataReaderQos& qos,
                                             dds::DataReaderListener* listener) {
    auto t = topic<PubSubType>(topic_name);
    if (!t) return t.error();
    return reader(*t, qos, listener);
  }

  // `listener` (may be null) hears of its matched readers (publication_matched only). The QoS
  // starts from the XML profile named after the topic (its DDS name, else its ROS 2 name, as
  // rmw_fastrtps looks it up) or the default profile; `qos`'s topic rules go on top
  // (overlay_topic_rules). The same for readers.
  core::Expected<dds::DataWriter*> writer(dds::Topic* topic, const dds::DataWriterQos& qos,
                                          dds::DataWriterListener* listener = nullptr);
  core::Expected<dds::DataReader*> reader(dds::Topic* topic, const dds::DataReaderQos& qos,
                                          dds::DataReaderListener* listener);

  // Deletes the readers only: no listener is called after this returns. Idempotent.
  void delete_readers();
  // Removes every entity (readers first, so no listener runs afterwards). Idempotent.
  void shutdown();

  dds::DomainParticipant* get() { return participant_; }
  int domain_id() const { return domain_id_; }

 private:
  Participant() = default;
  core::Expected<dds::Topic*> make_topic(const std::string& topic_name, dds::TypeSupport type);

  dds::DomainParticipant* participant_ = nullptr;
  dds::Publisher* publisher_ = nullptr;
  dds::Subscriber* subscriber_ = nullptr;
  std::map<std::string, dds::Topic*> topics_;
  int domain_id_ = 0;
};

// Fast DDS XML profiles, as rmw_fastrtps honours them. The participant QoS of `profile` (empty:
// the default participant profile, or Fast DDS's defaults without one), after loading the
// profiles files Fast DDS reads (FASTRTPS_DEFAULT_PROFILES_FILE, and DEFAULT_FASTRTPS_PROFILES.xml
// in the working directory unless SKIP_DEFAULT_XML_FILE=1). A missing or malformed file (one
// Fast DDS cannot parse, or a profile in it Fast DDS could not take: no profile_name, a name
// already used) is an error naming the file; a profile no file has is an error naming `key`.
core::Expected<dds::DomainParticipantQos> profile_participant_qos(
    const std::string& profile, const std::string& key = "dds.participant_profile");
// The profile names an endpoint on `dds_topic` is looked up by: the DDS name, then the ROS 2 one.
std::vector<std::string> topic_profile_names(const std::string& dds_topic);
// The node's topic rules (writer_qos, reader_qos: reliability, durability, history, resource
// limits, memory policy, data sharing; for writers also liveliness, publish mode and heartbeat
// period) copied from `rules` onto `out`; every other policy stays as the profile set it.
void overlay_topic_rules(const dds::DataWriterQos& rules, dds::DataWriterQos& out);
void overlay_topic_rules(const dds::DataReaderQos& rules, dds::DataReaderQos& out);
// The QoS an endpoint on `topic` is created with: the <data_writer>/<data_reader> profile named
// after the topic (topic_profile_names), else the publisher's/subscriber's default (the default
// profile, or Fast DDS's defaults), with `rules` overlaid. Participant::writer/reader use them;
// so does any code making endpoints on a publisher or subscriber of its own.
dds::DataWriterQos profiled_writer_qos(const dds::Publisher& publisher,
                                       const std::string& topic_name,
                                       const dds::DataWriterQos& rules);
dds::DataReaderQos profiled_reader_qos(const dds::Subscriber& subscriber,
                                       const std::string& topic_name,
                                       const dds::DataReaderQos& rules);

// Matched readers of a writer right now (0 when the call fails).
int matched_readers(dds::DataWriter* writer);

// DataWriter::write, tried a second time if the first is refused before the writer's
// max_blocking_time has passed. A reliable keep-all writer of
// Fast DDS 2.9 whose history is full waits up to max_blocking_time for acknowledgements; when the
// acknowledgements arrive while it waits and empty the whole history (a volatile writer drops
// what every reader has), it finds no sample left to remove and refuses at once, though there is
// room now (StatefulWriter::try_remove_change). A 3,000-request burst over the transport hit it
// at the 2,049th write. A refused write adds nothing, so the second try cannot duplicate; a write
// refused after the whole max_blocking_time (a history full of unacknowledged samples) is not
// tried again, so a real timeout takes no longer than before.
bool write_sample(dds::DataWriter* writer, void* sample);
bool write_sample(dds::DataWriter* writer, void* sample,
                  eprosima::fastrtps::rtps::WriteParams& params);

// A GUID prefix as Fast DDS prints it ("01.0f.8d.2a..."), as the logs name participants.
std::string guid_prefix_text(const eprosima::fastrtps::rtps::GuidPrefix_t& prefix);
// A GUID as the 16 bytes PlanStatus carries (prefix, then entity id).
std::array<uint8_t, 16> guid_bytes(const eprosima::fastrtps::rtps::GUID_t& guid);
// The sample identity of a received sample, as PlanStatus carries it.
RequestIdentity identity_of(const dds::SampleInfo& info, uint8_t subject);
// The identity `params` got from DataWriter::write(data, params), as PlanStatus echoes it.
RequestIdentity identity_of(const eprosima::fastrtps::rtps::WriteParams& params, uint8_t subject);

}  // namespace vnsba::node
