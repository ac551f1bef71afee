#include "vnsba/node/dds.hpp"

#include <fastdds/rtps/attributes/ServerAttributes.h>
#include <fastdds/rtps/common/WriteParams.h>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastrtps/xmlparser/XMLProfileManager.h>
#include <spdlog/spdlog.h>
#include <tinyxml2.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/log/Log.hpp>
#include <fastdds/dds/log/StdoutErrConsumer.hpp>
#include <filesystem>
#include <iterator>
#include <sstream>

#include "vnsba/node/security.hpp"

namespace vnsba::node {

namespace {

core::Status dds_error(const std::string& what) {
  return core::Status::error(core::StatusCode::kInternalError, "DDS: " + what + " failed");
}

// Fast DDS reports why its security plugins refuse a participant only in its log (an
// asynchronous queue); this consumer keeps the errors and warnings logged while a secured
// participant is being created, so the failure can name the files at fault. Registered once,
// with the first secured participant, for the life of the process.
class SecurityLogCapture : public eprosima::fastdds::dds::LogConsumer {
 public:
  static SecurityLogCapture& instance() {
    static SecurityLogCapture* capture = [] {
      using eprosima::fastdds::dds::Log;
      // Fast DDS's own console output moves from stdout to stderr: a secured bus logs refused
      // peers, and stdout is where vnsba_send_goal prints its one line.
      Log::ClearConsumers();
      Log::RegisterConsumer(std::make_unique<eprosima::fastdds::dds::StdoutErrConsumer>());
      auto owned = std::make_unique<SecurityLogCapture>();
      SecurityLogCapture* raw = owned.get();
      Log::RegisterConsumer(std::move(owned));
      return raw;
    }();
    return *capture;
  }
  void Consume(const eprosima::fastdds::dds::Log::Entry& entry) override {
    if (entry.kind == eprosima::fastdds::dds::Log::Info ||
        entry.message.find_first_not_of(" \t\r\n") == std::string::npos)
      return;
    std::lock_guard<std::mutex> lock(mutex_);
    if (capturing_ && messages_.size() < 32) {
      std::string category = entry.context.category != nullptr ? entry.context.category : "";
      messages_.push_back((category.empty() ? "" : category + ": ") + entry.message);
    }
  }
  void start() {
    std::lock_guard<std::mutex> lock(mutex_);
    capturing_ = true;
    messages_.clear();
  }
  std::vector<std::string> stop() {
    eprosima::fastdds::dds::Log::Flush();  // everything logged so far has been consumed
    std::lock_guard<std::mutex> lock(mutex_);
    capturing_ = false;
    return std::move(messages_);
  }

 private:
  std::mutex mutex_;
  bool capturing_ = false;
  std::vector<std::string> messages_;
};

}  // namespace

// What writers and readers share: reliability, durability, history and memory policy.
template <class Qos>
void apply_common(Qos& qos, TopicQos profile, bool reader) {
  qos.reliability().kind = profile == TopicQos::kStream ? dds::BEST_EFFORT_RELIABILITY_QOS
                                                        : dds::RELIABLE_RELIABILITY_QOS;
  const bool durable = profile == TopicQos::kLatched || profile == TopicQos::kStatic;
  qos.durability().kind =
      durable ? dds::TRANSIENT_LOCAL_DURABILITY_QOS : dds::VOLATILE_DURABILITY_QOS;
  // Requests and statuses are kept until taken (readers) or acknowledged (writers): nothing is
  // overwritten. A status writer's full history makes write() wait for acknowledgements (the
  // node retries until its statuses are out); a keep-last one overwrote unacknowledged statuses
  // in bursts (4,467 of 15,000 lost to three fast clients).
  const bool keep_all = profile == TopicQos::kEvents || profile == TopicQos::kStatus;
  int32_t limit = 0;
  if (keep_all) {
    qos.history().kind = dds::KEEP_ALL_HISTORY_QOS;
    limit = reader ? 4096 : profile == TopicQos::kStatus ? kStatusHistory : 2048;
  } else {
    qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
    qos.history().depth = profile == TopicQos::kDebug                                    ? 8
                          : profile == TopicQos::kStream || profile == TopicQos::kStatic ? 100
                                                                                         : 1;
  }
  if (limit > 0) {
    qos.resource_limits().max_samples = limit;
    qos.resource_limits().max_instances = 1;
    qos.resource_limits().max_samples_per_instance = limit;
  }
  // Dynamic: each sample's payload is allocated at its serialized size when the sample enters
  // the history and freed when it leaves. Fast DDS's pools in any other mode keep every payload
  // they ever made, each at the largest sample it carried (at least the type's bound, tens of kB
  // for a status with its path): a node's memory then followed the largest debug sample seen so
  // far and grew for as long as it ran (issue 18's ten-robot soak: 23 MB of payloads after ten
  // minutes, still growing). A malloc per sample costs nothing beside planning or serializing
  // it. The reason first given for PREALLOCATED_WITH_REALLOC (maps are megabytes, so
  // nothing is made at the type's bound) holds for this mode too. One cache change up front
  // (allocated_samples), the rest as samples come, up to the history's limit.
  qos.resource_limits().allocated_samples = 1;
  qos.endpoint().history_memory_policy = eprosima::fastrtps::rtps::DYNAMIC_RESERVE_MEMORY_MODE;
  qos.data_sharing().off();
}

std::string describe(TopicQos profile) {
  switch (profile) {
    case TopicQos::kLatched:
      return "reliable, transient local, keep last 1";
    case TopicQos::kEvents:
      return "reliable, volatile, keep all";
    case TopicQos::kStatus:
      return "reliable, volatile, keep all";
    case TopicQos::kLatest:
      return "reliable, volatile, keep last 1";
    case TopicQos::kDebug:
      return "reliable, volatile, keep last 8";
    case TopicQos::kStream:
      return "best effort, volatile, keep last 100";
    case TopicQos::kStatic:
      return "reliable, transient local, keep last 100";
  }
  return "";
}

dds::DataWriterQos writer_qos(TopicQos profile, bool large_samples) {
  dds::DataWriterQos qos = dds::DATAWRITER_QOS_DEFAULT;
  apply_common(qos, profile, /*reader=*/false);
  // A full KEEP_ALL history blocks write() until the readers acknowledge, at most this long:
  // 10 s for requests and goals (under the sanitizers a 3,000-request burst once needed more
  // than 1 s of acknowledgements, and the write failed), 1 s for everything else.
  qos.reliability().max_blocking_time = {profile == TopicQos::kEvents ? 10 : 1, 0};
  // Late joiners of a latched map should not wait for the default 3 s heartbeat.
  qos.reliable_writer_qos().times.heartbeatPeriod = {0, 150'000'000};
  // Manual liveliness (lease infinite: never lost; it matches every requested kind) only so that
  // DataWriter::assert_liveliness() heartbeats the status writer's readers at once: the replier
  // does that before each status it writes (replier.cpp, Replier::loop).
  if (profile == TopicQos::kStatus) qos.liveliness().kind = dds::MANUAL_BY_TOPIC_LIVELINESS_QOS;
  // Large samples go out on Fast DDS's sending thread, so the writer returns at once, but only
  // from writers that keep what readers acknowledged (transient local). A volatile writer drops a
  // sample once every reader has it, and Fast DDS 2.9 does that, when a reader goes away, under
  // the lock the sending thread takes while it holds its own (StatefulWriter::
  // matched_reader_remove against FlowControllerImpl::run; eProsima/Fast-DDS#5432, fixed in
  // 2.10.x and 2.14.x): the node hung on it when a debug reader left while a debug sample was
  // being sent. Synchronous volatile writers send on the writing thread, fragments and all.
  const bool durable = qos.durability().kind != dds::VOLATILE_DURABILITY_QOS;
  if (large_samples && durable) qos.publish_mode().kind = dds::ASYNCHRONOUS_PUBLISH_MODE;
  return qos;
}

dds::DataReaderQos reader_qos(TopicQos profile) {
  dds::DataReaderQos qos = dds::DATAREADER_QOS_DEFAULT;
  apply_common(qos, profile, /*reader=*/true);
  return qos;
}

namespace {

// The Fast DDS XML profiles files of this process, as Fast DDS finds them itself (and spelled as
// it spells them, so that a file it loads is the same entry of its table of parsed files):
// FASTRTPS_DEFAULT_PROFILES_FILE, then DEFAULT_FASTRTPS_PROFILES.xml in the working directory
// unless SKIP_DEFAULT_XML_FILE=1.
std::vector<std::string> profiles_files() {
  std::vector<std::string> files;
  const char* env = std::getenv("FASTRTPS_DEFAULT_PROFILES_FILE");
  if (env != nullptr && *env) files.emplace_back(env);
  const char* skip = std::getenv("SKIP_DEFAULT_XML_FILE");
  if (skip != nullptr && skip[0] == '1') return files;
  std::error_code error;
  if (std::filesystem::exists("DEFAULT_FASTRTPS_PROFILES.xml", error))
    files.emplace_back("DEFAULT_FASTRTPS_PROFILES.xml");
  return files;
}

// Sets Fast DDS's process-wide intraprocess delivery to OFF; false if it was something else.
bool force_intraprocess_off() {
  using eprosima::fastrtps::xmlparser::XMLProfileManager;
  eprosima::fastrtps::LibrarySettingsAttributes settings = XMLProfileManager::library_settings();
  if (settings.intraprocess_delivery == eprosima::fastrtps::INTRAPROCESS_OFF) return true;
  settings.intraprocess_delivery = eprosima::fastrtps::INTRAPROCESS_OFF;
  XMLProfileManager::library_settings(settings);
  return false;
}

// The profiles files read so far, and the names they were read as (profile_participant_qos
// holds its lock while it uses them).
struct ProfilesFilesRead {
  // The files read in full so far, by canonical path: Fast DDS knows a file by the name it was
  // given, and reading one file again under another name (the variable naming
  // ./DEFAULT_FASTRTPS_PROFILES.xml) would refuse each of its profiles as already defined.
  std::set<std::string> loaded_files;
  // The file each name was read as: a relative name (./DEFAULT_FASTRTPS_PROFILES.xml) that
  // stands for another file now (the working directory changed) is read by its canonical path,
  // as Fast DDS would take the name for one it has read already.
  std::map<std::string, std::string> read_as;
};

// Why Fast DDS could not read `file` as XML profiles: Fast DDS says which element it could not
// read in its log (flushed now, before the executable stops); XML that does not parse at all
// gets tinyxml2's line here.
core::Status unreadable_profiles_error(const std::string& file) {
  eprosima::fastdds::dds::Log::Flush();
  tinyxml2::XMLDocument document;
  const std::string why =
      document.LoadFile(file.c_str()) != tinyxml2::XML_SUCCESS
          ? std::string("not well-formed XML: ") + document.ErrorStr()
          : "well-formed XML, but not Fast DDS profiles Fast DDS could read (its XMLPARSER "
            "log names the element)";
  return core::Status::error(core::StatusCode::kInvalidRequest,
                             file + ": not a valid Fast DDS XML profiles file: " + why);
}

// Checks `file` and has Fast DDS read it, unless it read it in full before: a missing or
// malformed one stops the executable naming it (Fast DDS alone would log it and go on with its
// defaults). One it read in part (XML_NOK: a profile it could not take) is parsed again, and
// refused every time.
core::Status load_profiles_file(const std::string& file, ProfilesFilesRead& read) {
  using eprosima::fastrtps::xmlparser::XMLP_ret;
  using eprosima::fastrtps::xmlparser::XMLProfileManager;
  std::error_code error;
  if (!std::filesystem::is_regular_file(file, error))
    return core::Status::error(core::StatusCode::kInvalidRequest,
                               std::filesystem::exists(file, error)
                                   ? file + ": not a regular file"
                                   : "FASTRTPS_DEFAULT_PROFILES_FILE: " + file + ": no such file");
  const std::string canonical = std::filesystem::weakly_canonical(file, error).string();
  if (read.loaded_files.count(canonical) > 0) return core::Status::ok();
  const auto known = read.read_as.find(file);
  const std::string name =
      known != read.read_as.end() && known->second != canonical ? canonical : file;
  const XMLP_ret loaded = XMLProfileManager::loadXMLFile(name);
  if (loaded == XMLP_ret::XML_NOK)
    return core::Status::error(
        core::StatusCode::kInvalidRequest,
        file +
            ": a profile in this Fast DDS XML profiles file was refused (no profile_name, or "
            "a profile_name already taken; Fast DDS's XMLPARSER log names it)");
  if (loaded != XMLP_ret::XML_OK) return unreadable_profiles_error(file);
  read.loaded_files.insert(canonical);
  read.read_as.emplace(name, canonical);
  if (!force_intraprocess_off())
    spdlog::warn(
        "{}: <library_settings><intraprocess_delivery> ignored: this process keeps it OFF "
        "(Fast DDS 2.9 can crash deleting a participant's endpoints with it on)",
        file);
  return core::Status::ok();
}

// The participant QoS of the profile named `profile` (empty: the default participant profile)
// among those Fast DDS has loaded; an error naming `key` and `files` when none has that name.
core::Expected<dds::DomainParticipantQos> loaded_participant_qos(
    dds::DomainParticipantFactory& factory, const std::string& profile, const std::string& key,
    const std::vector<std::string>& files) {
  factory.load_profiles();  // once per process: Fast DDS's own loading, which finds them loaded
  // The default participant profile as loaded now (load_profiles took it only the first time).
  factory.set_default_participant_qos(dds::PARTICIPANT_QOS_DEFAULT);
  dds::DomainParticipantQos qos = factory.get_default_participant_qos();
  if (!profile.empty() &&
      factory.get_participant_qos_from_profile(profile, qos) != ReturnCode_t::RETCODE_OK) {
    std::string where;
    for (const std::string& file : files) where += (where.empty() ? "" : ", ") + file;
    return core::Status::error(
        core::StatusCode::kInvalidRequest,
        key + ": found \"" + profile +
            "\", expected the profile_name of a "
            "<participant> in the XML profiles (" +
            (where.empty() ? "none loaded: set FASTRTPS_DEFAULT_PROFILES_FILE" : where) + ")");
  }
  return qos;
}

}  // namespace

core::Expected<dds::DomainParticipantQos> profile_participant_qos(const std::string& profile,
                                                                  const std::string& key) {
  // Fast DDS's profile tables are process-wide and unguarded: one caller at a time.
  static std::mutex loading;
  const std::lock_guard<std::mutex> lock(loading);
  static ProfilesFilesRead read;
  auto* factory = dds::DomainParticipantFactory::get_instance();
  // No intraprocess delivery: participants of one process talk through the transport, as
  // participants of different processes do. Fast DDS 2.9 (Debian 12's) delivers intraprocess
  // through raw pointers to the other participant's endpoints, and a participant deleting its
  // endpoints just after another participant of the process was deleted writes through a dangling
  // one (SIGSEGV in StatefulWriter::intraprocess_gap; eProsima/Fast-DDS#5034, fixed in 2.14.4 and
  // 3.0.2). The node and each tool have one participant and lose nothing by it; processes with
  // several (the tests, the benchmarks' in-process clients) talk over loopback.
  // Set before any file is read, so a file that sets it otherwise is noticed below, and again on
  // every way out: Fast DDS applies a file's setting while it parses it, also when it then
  // refuses the file. Fast DDS reads the setting at each match, so a file first read while other
  // participants of the process exist has it on for them during its parse; our executables read
  // their files before their one participant exists.
  force_intraprocess_off();
  struct KeepIntraprocessOff {
    ~KeepIntraprocessOff() { force_intraprocess_off(); }
  } keep_intraprocess_off;
  const std::vector<std::string> files = profiles_files();
  for (const std::string& file : files)
    if (core::Status loaded = load_profiles_file(file, read); !loaded.is_ok()) return loaded;
  return loaded_participant_qos(*factory, profile, key, files);
}

std::vector<std::string> topic_profile_names(const std::string& dds_topic) {
  std::vector<std::string> names{dds_topic};
  // rt/robot7/plan -> /robot7/plan, the ROS 2 name rmw_fastrtps looks profiles up by.
  if (dds_topic.rfind("rt/", 0) == 0) names.push_back(dds_topic.substr(2));
  return names;
}

template <class Qos>
void overlay_common(const Qos& rules, Qos& out) {
  out.reliability() = rules.reliability();
  out.durability() = rules.durability();
  out.history() = rules.history();
  out.resource_limits() = rules.resource_limits();
  out.endpoint().history_memory_policy = rules.endpoint().history_memory_policy;
  out.data_sharing() = rules.data_sharing();
}

void overlay_topic_rules(const dds::DataWriterQos& rules, dds::DataWriterQos& out) {
  overlay_common(rules, out);
  out.liveliness() = rules.liveliness();
  out.publish_mode() = rules.publish_mode();
  out.reliable_writer_qos().times.heartbeatPeriod =
      rules.reliable_writer_qos().times.heartbeatPeriod;
}

void overlay_topic_rules(const dds::DataReaderQos& rules, dds::DataReaderQos& out) {
  overlay_common(rules, out);
}

namespace {

// The security section's properties replace a profile's of the same name (Fast DDS reads the
// first of a name); the profile's others stay (a profile may enable security by itself).
void apply_security_properties(const SecurityPlan& plan, dds::DomainParticipantQos& qos) {
  for (const auto& [property, value] : plan.properties) {
    auto& properties = qos.properties().properties();
    properties.erase(std::remove_if(properties.begin(), properties.end(),
                                    [&](const auto& p) { return p.name() == property; }),
                     properties.end());
    properties.emplace_back(property, value);
  }
}

// Transports a profile gives are kept, unless localhost_only asks for loopback; otherwise UDP.
void apply_transports(bool localhost_only, dds::DomainParticipantQos& qos) {
  const bool profile_transports =
      !qos.transport().user_transports.empty() || !qos.transport().use_builtin_transports;
  if (profile_transports && !localhost_only) return;
  if (profile_transports)
    spdlog::warn(
        "network.localhost_only: the XML profile's transports are replaced by UDP on "
        "127.0.0.1");
  qos.transport().user_transports.clear();
  qos.transport().use_builtin_transports = false;
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  // Room for bursts of map fragments on loopback.
  udp->sendBufferSize = 4 * 1024 * 1024;
  udp->receiveBufferSize = 4 * 1024 * 1024;
  // As rmw_fastrtps does for ROS_LOCALHOST_ONLY: the whitelist limits both the interfaces used
  // and the locators announced, so loopback-only peers can reach this participant.
  if (localhost_only) udp->interfaceWhiteList.emplace_back("127.0.0.1");
  qos.transport().user_transports.push_back(udp);
}

// The announcement period, and discovery.servers.
core::Status apply_discovery(const std::vector<std::string>& discovery_servers,
                             dds::DomainParticipantQos& qos) {
  const dds::DomainParticipantQos fast_dds_defaults;  // what "left at the default" means below
  // A participant that starts after another (a send_goal after the node) is matched only once
  // the older one announces itself again: Fast DDS does not answer a new participant's initial
  // announcements at once. With the default 3 s period a short-lived client waits up to 3 s;
  // 0.5 s bounds that wait for a few dozen bytes per participant and second on the wire.
  auto& announcement_period =
      qos.wire_protocol().builtin.discovery_config.leaseDuration_announcementperiod;
  if (announcement_period ==
      fast_dds_defaults.wire_protocol().builtin.discovery_config.leaseDuration_announcementperiod)
    announcement_period = eprosima::fastrtps::Duration_t(0, 500'000'000);
  // discovery.servers: a Discovery Server client, the servers parsed by Fast DDS's own reader of
  // ROS_DISCOVERY_SERVER lists (position = server id), so both spell servers the same way.
  if (discovery_servers.empty()) return core::Status::ok();
  std::string list;
  for (const std::string& server : discovery_servers) list += (list.empty() ? "" : ";") + server;
  auto& discovery = qos.wire_protocol().builtin.discovery_config;
  if (!eprosima::fastdds::rtps::load_environment_server_info(list, discovery.m_DiscoveryServers))
    return core::Status::error(core::StatusCode::kInvalidRequest,
                               "discovery.servers: Fast DDS cannot read \"" + list + "\"");
  discovery.discoveryProtocol = eprosima::fastrtps::rtps::DiscoveryProtocol_t::CLIENT;
  return core::Status::ok();
}

// The participant's QoS: the XML profiles first, as rmw_fastrtps does (the named participant
// profile, else the default one; Fast DDS's defaults without a file), the node's rules on top.
core::Expected<dds::DomainParticipantQos> participant_qos(
    const std::string& name, bool localhost_only, const SecurityPlan& security_plan,
    const std::vector<std::string>& discovery_servers, const std::string& participant_profile) {
  core::Expected<dds::DomainParticipantQos> profiled = profile_participant_qos(participant_profile);
  if (!profiled) return profiled.error();
  dds::DomainParticipantQos qos = std::move(profiled).value();
  qos.name(name);
  apply_security_properties(security_plan, qos);
  apply_transports(localhost_only, qos);
  if (core::Status discovery = apply_discovery(discovery_servers, qos); !discovery.is_ok())
    return discovery;
  if (qos.transport().send_socket_buffer_size == 0)
    qos.transport().send_socket_buffer_size = 4 * 1024 * 1024;
  if (qos.transport().listen_socket_buffer_size == 0)
    qos.transport().listen_socket_buffer_size = 4 * 1024 * 1024;
  return qos;
}

// The GUID prefix starts with a 1 bit, then the first 47 bits of the SHA-256 of the
// certificate's subject. Below ff.f8 (12 one bits of that hash, what tools/make_keystore.sh
// gives its own enclaves), Cyclone DDS peers whose identity sorts higher wait for this
// participant to start the handshake, which Fast DDS 2.9 starts with a key agreement Cyclone
// DDS 0.10 cannot read.
void warn_if_identity_sorts_low(const dds::DomainParticipant& participant) {
  const auto& prefix = participant.guid().guidPrefix.value;
  if (prefix[0] != 0xff || prefix[1] < 0xf8)
    spdlog::warn(
        "security: this identity's GUID prefix ({:02x}.{:02x}...) sorts below most: Cyclone DDS "
        "peers with an identity that sorts above it cannot authenticate with it (a Fast DDS 2.9 "
        "limit); enclaves of tools/make_keystore.sh sort first (docs/security.md)",
        prefix[0], prefix[1]);
}

// The DomainParticipant (null when Fast DDS refused it); a secured one that Fast DDS refused is
// an error naming the enclave's files at fault and what Fast DDS logged meanwhile.
core::Expected<dds::DomainParticipant*> create_domain_participant(
    int domain_id, const dds::DomainParticipantQos& qos, dds::DomainParticipantListener* listener,
    const SecurityPlan& security_plan) {
  // One secured creation at a time, so the log captured is this participant's.
  static std::mutex secured_creation;
  std::unique_lock<std::mutex> secured_lock(secured_creation, std::defer_lock);
  if (security_plan.secured) {
    secured_lock.lock();
    SecurityLogCapture::instance().start();
  }
  dds::DomainParticipant* participant =
      dds::DomainParticipantFactory::get_instance()->create_participant(
          domain_id, qos, listener,
          // Discovery callbacks (always delivered) and, from every reader and writer,
          // incompatible QoS: their own listeners leave those statuses out of their masks, so
          // they come here.
          listener != nullptr ? dds::StatusMask::requested_incompatible_qos()
                                    << dds::StatusMask::offered_incompatible_qos()
                              : dds::StatusMask::none());
  if (!security_plan.secured) return participant;
  const std::vector<std::string> logged = SecurityLogCapture::instance().stop();
  if (participant == nullptr) {
    return core::Status::error(
        core::StatusCode::kInvalidRequest,
        security_failure_message(security_plan, diagnose_enclave(security_plan), logged));
  }
  spdlog::info("security: enclave '{}' ({}), DDS Security on", security_plan.enclave,
               security_plan.enclave_directory);
  warn_if_identity_sorts_low(*participant);
  return participant;
}

}  // namespace

core::Expected<std::unique_ptr<Participant>> Participant::create(
    int domain_id, const std::string& name, dds::DomainParticipantListener* listener,
    bool localhost_only, const SecurityConfig& security,
    const std::vector<std::string>& discovery_servers, const std::string& participant_profile) {
  if (domain_id < 0 || domain_id > 232) {
    return core::Status::error(core::StatusCode::kInvalidRequest,
                               "domain id " + std::to_string(domain_id) + " is outside 0..232");
  }
  // Security first: a missing or unreadable file is named before any DDS entity exists.
  const core::Expected<SecurityPlan> security_plan = plan_security(security);
  if (!security_plan) return security_plan.error();
  for (const std::string& note : security_plan->notes) spdlog::warn("{}", note);
  const core::Expected<dds::DomainParticipantQos> qos =
      participant_qos(name, localhost_only, *security_plan, discovery_servers, participant_profile);
  if (!qos) return qos.error();
  std::unique_ptr<Participant> self(new Participant());
  self->domain_id_ = domain_id;
  core::Expected<dds::DomainParticipant*> participant =
      create_domain_participant(domain_id, *qos, listener, *security_plan);
  if (!participant) return participant.error();
  self->participant_ = *participant;
  if (self->participant_ == nullptr)
    return dds_error("create_participant(domain " + std::to_string(domain_id) + ")");
  self->publisher_ = self->participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  if (self->publisher_ == nullptr) return dds_error("create_publisher");
  self->subscriber_ = self->participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (self->subscriber_ == nullptr) return dds_error("create_subscriber");
  return self;
}

core::Expected<std::unique_ptr<Participant>> Participant::create_configured(
    const NodeConfig& config, const std::string& name, const std::string& default_enclave,
    dds::DomainParticipantListener* listener) {
  return create(config.domain_id, name, listener, config.localhost_only,
                with_default_enclave(config.security, default_enclave), config.discovery_servers,
                config.participant_profile);
}

core::Expected<dds::Topic*> Participant::make_topic(const std::string& topic_name,
                                                    dds::TypeSupport type) {
  const std::string type_name = type.get_type_name();
  if (participant_->find_type(type_name).empty() &&
      type.register_type(participant_) != ReturnCode_t::RETCODE_OK) {
    return dds_error("register_type(" + type_name + ")");
  }
  dds::Topic* topic = participant_->create_topic(topic_name, type_name, dds::TOPIC_QOS_DEFAULT);
  if (topic == nullptr) return dds_error("create_topic(" + topic_name + ", " + type_name + ")");
  topics_[topic_name] = topic;
  return topic;
}

dds::DataWriterQos profiled_writer_qos(const dds::Publisher& publisher,
                                       const std::string& topic_name,
                                       const dds::DataWriterQos& rules) {
  dds::DataWriterQos qos = publisher.get_default_datawriter_qos();
  for (const std::string& profile : topic_profile_names(topic_name))
    if (publisher.get_datawriter_qos_from_profile(profile, qos) == ReturnCode_t::RETCODE_OK) break;
  overlay_topic_rules(rules, qos);
  return qos;
}

dds::DataReaderQos profiled_reader_qos(const dds::Subscriber& subscriber,
                                       const std::string& topic_name,
                                       const dds::DataReaderQos& rules) {
  dds::DataReaderQos qos = subscriber.get_default_datareader_qos();
  for (const std::string& profile : topic_profile_names(topic_name))
    if (subscriber.get_datareader_qos_from_profile(profile, qos) == ReturnCode_t::RETCODE_OK) break;
  overlay_topic_rules(rules, qos);
  return qos;
}

core::Expected<dds::DataWriter*> Participant::writer(dds::Topic* topic,
                                                     const dds::DataWriterQos& qos,
                                                     dds::DataWriterListener* listener) {
  const dds::DataWriterQos effective = profiled_writer_qos(*publisher_, topic->get_name(), qos);
  dds::DataWriter* writer = publisher_->create_datawriter(
      topic, effective, listener,
      listener ? dds::StatusMask::publication_matched() : dds::StatusMask::none());
  if (writer == nullptr) return dds_error("create_datawriter(" + topic->get_name() + ")");
  return writer;
}

core::Expected<dds::DataReader*> Participant::reader(dds::Topic* topic,
                                                     const dds::DataReaderQos& qos,
                                                     dds::DataReaderListener* listener) {
  const dds::DataReaderQos effective = profiled_reader_qos(*subscriber_, topic->get_name(), qos);
  dds::DataReader* reader = subscriber_->create_datareader(
      topic, effective, listener,
      listener ? dds::StatusMask::data_available() << dds::StatusMask::subscription_matched()
               : dds::StatusMask::none());
  if (reader == nullptr) return dds_error("create_datareader(" + topic->get_name() + ")");
  return reader;
}

void Participant::delete_readers() {
  if (subscriber_ != nullptr) subscriber_->delete_contained_entities();
}

void Participant::shutdown() {
  if (participant_ == nullptr) return;
  // Readers go first so that no listener is called on a half-destroyed owner.
  if (subscriber_ != nullptr) subscriber_->delete_contained_entities();
  participant_->delete_contained_entities();
  dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  participant_ = nullptr;
  publisher_ = nullptr;
  subscriber_ = nullptr;
  topics_.clear();
}

Participant::~Participant() {
  shutdown();
}

int matched_readers(dds::DataWriter* writer) {
  dds::PublicationMatchedStatus status;
  if (writer == nullptr ||
      writer->get_publication_matched_status(status) != ReturnCode_t::RETCODE_OK)
    return 0;
  return status.current_count;
}

namespace {

// `write` once, and once more if it was refused before the writer's max_blocking_time passed:
// the refusal write_sample works around comes early; a real timeout keeps its bound.
template <class Write>
bool write_refused_early_again(dds::DataWriter* writer, Write write) {
  const auto started = std::chrono::steady_clock::now();
  if (write()) return true;
  const auto blocking =
      std::chrono::nanoseconds(writer->get_qos().reliability().max_blocking_time.to_ns());
  return std::chrono::steady_clock::now() - started < blocking && write();
}

}  // namespace

bool write_sample(dds::DataWriter* writer, void* sample) {
  return write_refused_early_again(writer, [&] { return writer->write(sample); });
}

bool write_sample(dds::DataWriter* writer, void* sample,
                  eprosima::fastrtps::rtps::WriteParams& params) {
  return write_refused_early_again(writer, [&] { return writer->write(sample, params); });
}

std::string guid_prefix_text(const eprosima::fastrtps::rtps::GuidPrefix_t& prefix) {
  std::ostringstream out;
  out << prefix;
  return out.str();
}

void ParticipantWatch::on_participant_discovery(
    dds::DomainParticipant* participant,
    eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) {
  if (report_refused_) refused_.on_participant_discovery(participant, info);
  using Status = eprosima::fastrtps::rtps::ParticipantDiscoveryInfo;
  const std::string key = guid_prefix_text(info.info.m_guid.guidPrefix);
  std::lock_guard<std::mutex> lock(mutex_);
  if (info.status == Status::REMOVED_PARTICIPANT || info.status == Status::DROPPED_PARTICIPANT) {
    vendors_.erase(key);  // bounded by the participants alive
    return;
  }
  names_[key] = info.info.m_participantName.to_string();
  vendors_[key] = info.info.m_VendorId;
}

std::optional<std::array<uint8_t, 2>> ParticipantWatch::vendor_of(
    const eprosima::fastrtps::rtps::GuidPrefix_t& prefix) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = vendors_.find(guid_prefix_text(prefix));
  if (it == vendors_.end()) return std::nullopt;
  return it->second;
}

void ParticipantWatch::on_publisher_discovery(
    dds::DomainParticipant* participant, eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) {
  using Status = eprosima::fastrtps::rtps::WriterDiscoveryInfo;
  if (info.status != Status::DISCOVERED_WRITER) return;
  if (topic_names_.count(info.info.topicName().to_string()) == 0) return;
  const auto& prefix = info.info.guid().guidPrefix;
  if (participant != nullptr && prefix == participant->guid().guidPrefix) return;  // ours
  const std::string key = guid_prefix_text(prefix);
  std::string name;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!reported_.insert(key).second) return;
    const auto it = names_.find(key);
    name = it != names_.end() ? it->second : "";
  }
  if (on_other_) on_other_(name, key);
}

namespace {

// The policies a ROS 2 or DDS peer most often sets differently; the rest by their number.
std::string policy_name(uint32_t id) {
  switch (id) {
    case dds::DURABILITY_QOS_POLICY_ID:
      return "DURABILITY";
    case dds::DEADLINE_QOS_POLICY_ID:
      return "DEADLINE";
    case dds::LIVELINESS_QOS_POLICY_ID:
      return "LIVELINESS";
    case dds::RELIABILITY_QOS_POLICY_ID:
      return "RELIABILITY";
    case dds::OWNERSHIP_QOS_POLICY_ID:
      return "OWNERSHIP";
    case dds::DESTINATIONORDER_QOS_POLICY_ID:
      return "DESTINATION_ORDER";
    case dds::PRESENTATION_QOS_POLICY_ID:
      return "PRESENTATION";
    case dds::DATAREPRESENTATION_QOS_POLICY_ID:
      return "DATA_REPRESENTATION";
    default:
      return "QoS policy " + std::to_string(id);
  }
}

}  // namespace

void ParticipantWatch::report_incompatible(const std::string& topic, bool ours_reads,
                                           uint32_t policy_id, int32_t new_endpoints) {
  if (new_endpoints <= 0) return;
  incompatible_qos_ += static_cast<size_t>(new_endpoints);
  const std::string policy = policy_name(policy_id);
  const std::string fix = fix_ ? fix_(topic, policy) : "";
  spdlog::warn("incompatible QoS on '{}': {} remote {} never match the node's {} ({}){}{}", topic,
               new_endpoints, ours_reads ? "writer(s)" : "reader(s)",
               ours_reads ? "reader" : "writer", policy, fix.empty() ? "" : ": ", fix);
}

void ParticipantWatch::on_requested_incompatible_qos(
    dds::DataReader* reader, const dds::RequestedIncompatibleQosStatus& status) {
  report_incompatible(reader->get_topicdescription()->get_name(), true, status.last_policy_id,
                      status.total_count_change);
}

void ParticipantWatch::on_offered_incompatible_qos(
    dds::DataWriter* writer, const dds::OfferedIncompatibleQosStatus& status) {
  report_incompatible(writer->get_topic()->get_name(), false, status.last_policy_id,
                      status.total_count_change);
}

size_t ParticipantWatch::incompatible_qos() const {
  return incompatible_qos_.load();
}

size_t ParticipantWatch::count() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return reported_.size();
}

std::array<uint8_t, 16> guid_bytes(const eprosima::fastrtps::rtps::GUID_t& guid) {
  std::array<uint8_t, 16> out{};
  std::copy(std::begin(guid.guidPrefix.value), std::end(guid.guidPrefix.value), out.begin());
  std::copy(std::begin(guid.entityId.value), std::end(guid.entityId.value), out.begin() + 12);
  return out;
}

namespace {

RequestIdentity identity_from(const eprosima::fastrtps::rtps::SampleIdentity& sample,
                              uint8_t subject) {
  RequestIdentity id;
  id.subject = subject;
  id.writer_guid = guid_bytes(sample.writer_guid());
  id.sequence_number = sample.sequence_number().to64long();
  return id;
}

}  // namespace

RequestIdentity identity_of(const dds::SampleInfo& info, uint8_t subject) {
  return identity_from(info.sample_identity, subject);
}

RequestIdentity identity_of(const eprosima::fastrtps::rtps::WriteParams& params, uint8_t subject) {
  return identity_from(params.sample_identity(), subject);
}

}  // namespace vnsba::node
