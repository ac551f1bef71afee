// Issue 18, item 3: Fast DDS XML profiles, honoured as rmw_fastrtps honours them. Real
// participants over loopback; the profiles file is handed over through
// FASTRTPS_DEFAULT_PROFILES_FILE, the variable Fast DDS and ROS 2 users set.
#include <fastrtps/xmlparser/XMLProfileManager.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <mutex>

#include "bus_client.hpp"
#include "child_process.hpp"
#include "temp_dir.hpp"
#include "vnsba/node/planner_node.hpp"

namespace vnsba::test {
namespace {

// FASTRTPS_DEFAULT_PROFILES_FILE set for one test, unset after it (tests may share a process).
class ProfilesFile {
 public:
  explicit ProfilesFile(const std::string& path) {
    setenv("FASTRTPS_DEFAULT_PROFILES_FILE", path.c_str(), 1);
  }
  ~ProfilesFile() { unsetenv("FASTRTPS_DEFAULT_PROFILES_FILE"); }
};

// Sees other participants' announced lease durations (seconds), by participant name.
class LeaseWatch : public node::dds::DomainParticipantListener {
 public:
  void on_participant_discovery(
      node::dds::DomainParticipant*,
      eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override {
    std::lock_guard<std::mutex> lock(mutex_);
    leases_[info.info.m_participantName.to_string()] = info.info.m_leaseDuration.seconds;
  }
  std::optional<int32_t> lease_of(const std::string& name) {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = leases_.find(name);
    return it == leases_.end() ? std::nullopt : std::optional<int32_t>(it->second);
  }

 private:
  std::mutex mutex_;
  std::map<std::string, int32_t> leases_;
};

std::string profiles_xml(const std::string& participant_profile, const std::string& writer_topic) {
  return R"(<?xml version="1.0" encoding="UTF-8" ?>
<profiles xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <participant profile_name=")" +
         participant_profile + R"(">
    <rtps>
      <builtin>
        <discovery_config>
          <leaseDuration><sec>42</sec></leaseDuration>
        </discovery_config>
      </builtin>
    </rtps>
  </participant>
  <data_writer profile_name=")" +
         writer_topic + R"(">
    <qos>
      <lifespan><duration><sec>7</sec></duration></lifespan>
      <reliability><kind>BEST_EFFORT</kind></reliability>
    </qos>
  </data_writer>
  <data_reader profile_name=")" +
         writer_topic + R"(">
    <topic><historyQos><kind>KEEP_LAST</kind><depth>3</depth></historyQos></topic>
    <propertiesPolicy>
      <properties>
        <property><name>vnsba.test.reader</name><value>from_profile</value></property>
      </properties>
    </propertiesPolicy>
  </data_reader>
</profiles>
)";
}

// The value of property `name` in `properties`, or nullopt.
std::optional<std::string> property_of(const eprosima::fastrtps::rtps::PropertyPolicy& properties,
                                       const std::string& name) {
  for (const auto& p : properties.properties())
    if (p.name() == name) return p.value();
  return std::nullopt;
}

// The working directory changed for one test, restored after it.
class WorkingDirectory {
 public:
  explicit WorkingDirectory(const std::filesystem::path& dir)
      : previous_(std::filesystem::current_path()) {
    std::filesystem::current_path(dir);
  }
  ~WorkingDirectory() { std::filesystem::current_path(previous_); }

 private:
  std::filesystem::path previous_;
};

// A participant profile's lease duration reaches the participant and what its peers see of it;
// a data_writer profile named after a topic reaches that topic's writer, with the node's own
// rule (reliable) on top of the profile's best effort.
TEST(XmlProfiles, AProfilesSettingsReachTheParticipantItsPeersAndTheTopicsWriter) {
  const node::NodeConfig cfg = test_config("xml_profiles");
  const std::string status_topic = node::dds_topic_name(cfg, cfg.topics.plan_status);
  const std::string profile = "vnsba_lease_42_" + std::to_string(getpid());
  ProfilesFile env(write_temp_file("profiles.xml", profiles_xml(profile, status_topic)));

  LeaseWatch watch;
  auto observer = node::Participant::create(cfg.domain_id, "observer", &watch);
  ASSERT_TRUE(observer) << observer.error().message;
  const std::string name = "profiled_" + std::to_string(getpid());
  auto profiled = node::Participant::create(cfg.domain_id, name, nullptr, false, {}, {}, profile);
  ASSERT_TRUE(profiled) << profiled.error().message;
  EXPECT_EQ((*profiled)->get()->get_qos().wire_protocol().builtin.discovery_config.leaseDuration,
            eprosima::fastrtps::Duration_t(42, 0));
  // Without the name: the file has no default profile, so Fast DDS's 20 s.
  auto plain = node::Participant::create(cfg.domain_id, "plain");
  ASSERT_TRUE(plain) << plain.error().message;
  EXPECT_EQ((*plain)->get()->get_qos().wire_protocol().builtin.discovery_config.leaseDuration,
            eprosima::fastrtps::Duration_t(20, 0));
  // What the observer learns over the wire.
  const auto end = std::chrono::steady_clock::now() + 10s;
  while (!watch.lease_of(name) && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(20ms);
  ASSERT_TRUE(watch.lease_of(name)) << "the profiled participant was never discovered";
  EXPECT_EQ(*watch.lease_of(name), 42);

  auto writer = (*profiled)->writer_on<vnsba_msgs::msg::dds_::PlanStatus_PubSubType>(
      status_topic, node::writer_qos(node::TopicQos::kStatus, false));
  ASSERT_TRUE(writer) << writer.error().message;
  EXPECT_EQ((*writer)->get_qos().lifespan().duration, eprosima::fastrtps::Duration_t(7, 0));
  EXPECT_EQ((*writer)->get_qos().reliability().kind, node::dds::RELIABLE_RELIABILITY_QOS);
  // Another topic's writer gets no lifespan from it.
  auto other = (*profiled)->writer_on<vnsba_msgs::msg::dds_::PlanStatus_PubSubType>(
      status_topic + "_other", node::writer_qos(node::TopicQos::kStatus, false));
  ASSERT_TRUE(other) << other.error().message;
  EXPECT_EQ((*other)->get_qos().lifespan().duration,
            node::dds::DataWriterQos().lifespan().duration);

  // The topic's data_reader profile: its property reaches the reader; its history (keep last 3)
  // gives way to the node's rule for status readers (keep all).
  auto reader = (*profiled)->reader_on<vnsba_msgs::msg::dds_::PlanStatus_PubSubType>(
      status_topic, node::reader_qos(node::TopicQos::kStatus), nullptr);
  ASSERT_TRUE(reader) << reader.error().message;
  EXPECT_EQ(property_of((*reader)->get_qos().properties(), "vnsba.test.reader"), "from_profile");
  EXPECT_EQ((*reader)->get_qos().history().kind, node::dds::KEEP_ALL_HISTORY_QOS);
  EXPECT_EQ((*reader)->get_qos().reliability().kind, node::dds::RELIABLE_RELIABILITY_QOS);
}

// The node takes dds.participant_profile from its config; a name no profile has stops it,
// naming the key.
TEST(XmlProfiles, TheNodeUsesItsConfiguredProfileAndRefusesAnUnknownOne) {
  node::NodeConfig cfg = test_config("xml_node");
  const std::string profile = "vnsba_node_profile_" + std::to_string(getpid());
  ProfilesFile env(write_temp_file("node_profiles.xml", profiles_xml(profile, profile + "_topic")));
  cfg.participant_profile = profile + "_missing";
  {
    node::PlannerNode planner_node(cfg);
    const core::Status status = planner_node.start();
    ASSERT_FALSE(status.is_ok());
    EXPECT_NE(status.message.find("dds.participant_profile"), std::string::npos) << status.message;
    EXPECT_NE(status.message.find("node_profiles.xml"), std::string::npos) << status.message;
  }
  cfg.participant_profile = profile;
  LeaseWatch watch;
  auto observer = node::Participant::create(cfg.domain_id, "observer", &watch).value();
  node::PlannerNode planner_node(cfg);
  ASSERT_TRUE(planner_node.start().is_ok());
  const auto end = std::chrono::steady_clock::now() + 10s;
  while (!watch.lease_of("vnsba_node") && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(20ms);
  ASSERT_TRUE(watch.lease_of("vnsba_node"));
  EXPECT_EQ(*watch.lease_of("vnsba_node"), 42);
  // And it still serves.
  BusClient client(cfg);
  ASSERT_TRUE(client.wait_for_node());
  client.publish_slice([] {
    core::OccupancyGrid g;
    g.width = g.height = 4;
    g.resolution = 1.0;
    g.data.assign(16, 0);
    return g;
  }());
  ASSERT_TRUE(planner_node.wait_for_map(10s));
  client.publish_request("profiled", 0.5, 0.5, 3.5, 3.5);
  const auto status = client.wait_status("profiled");
  ASSERT_TRUE(status);
  EXPECT_EQ(node::code_name(status->code()), "OK") << status->message();
}

// A missing or malformed profiles file stops participant creation, naming the file.
TEST(XmlProfiles, AMissingOrMalformedFileIsAnErrorNamingIt) {
  const node::NodeConfig cfg = test_config("xml_bad");
  {
    // In an empty directory of its own: nothing can have made it.
    const std::string missing = (FreshTempDir("xml_bad") / "no_such_profiles.xml").string();
    ProfilesFile env(missing);
    auto participant = node::Participant::create(cfg.domain_id, "bad");
    ASSERT_FALSE(participant);
    EXPECT_NE(participant.error().message.find(missing), std::string::npos)
        << participant.error().message;
    EXPECT_NE(participant.error().message.find("no such file"), std::string::npos);
  }
  // Text, and what the message says of it: tinyxml2's line for XML that does not parse.
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"<profiles><participant profile_name=\"x\">", "not well-formed XML: "},
      {"not xml at all", "not well-formed XML: "},
      {"<profiles xmlns=\"http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles\"><participant "
       "profile_name=\"x\"><rtps><builtin><discovery_config><leaseDuration><sec>forty</sec>"
       "</leaseDuration></discovery_config></builtin></rtps></participant></profiles>",
       "well-formed XML, but not Fast DDS profiles"}};
  for (const auto& [text, why] : cases) {
    const std::string path = write_temp_file("malformed_profiles.xml", text);
    ProfilesFile env(path);
    auto participant = node::Participant::create(cfg.domain_id, "bad");
    ASSERT_FALSE(participant) << text;
    EXPECT_NE(
        participant.error().message.find(path + ": not a valid Fast DDS XML profiles file: " + why),
        std::string::npos)
        << participant.error().message;
  }
}

// A profile Fast DDS refuses (two profiles of one name) is an error naming the file, at every
// creation, not only the first.
TEST(XmlProfiles, AFileWithARefusedProfileIsAnErrorNamingIt) {
  const node::NodeConfig cfg = test_config("xml_dup");
  const std::string name = "vnsba_dup_" + std::to_string(getpid());
  const std::string path = write_temp_file("duplicate_profiles.xml",
                                           R"(<?xml version="1.0" encoding="UTF-8" ?>
<profiles xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <participant profile_name=")" + name + R"("><rtps><name>one</name></rtps></participant>
  <participant profile_name=")" + name + R"("><rtps><name>two</name></rtps></participant>
</profiles>
)");
  ProfilesFile env(path);
  for (int attempt = 0; attempt < 2; ++attempt) {
    auto participant =
        node::Participant::create(cfg.domain_id, "dup", nullptr, false, {}, {}, name);
    ASSERT_FALSE(participant) << "attempt " << attempt;
    EXPECT_NE(participant.error().message.find(path), std::string::npos)
        << participant.error().message;
  }
}

// DEFAULT_FASTRTPS_PROFILES.xml in the working directory is read as Fast DDS reads it: alone,
// together with the variable naming that same file (read once), and not at all with
// SKIP_DEFAULT_XML_FILE=1.
TEST(XmlProfiles, TheWorkingDirectorysFileIsReadOnceAndSkippedOnRequest) {
  const node::NodeConfig cfg = test_config("xml_cwd");
  const std::string profile = "vnsba_cwd_" + std::to_string(getpid());
  const std::filesystem::path good = FreshTempDir("xml_cwd_good");
  std::ofstream(good / "DEFAULT_FASTRTPS_PROFILES.xml")
      << profiles_xml(profile, profile + "_topic");
  const std::filesystem::path bad = FreshTempDir("xml_cwd_bad");
  std::ofstream(bad / "DEFAULT_FASTRTPS_PROFILES.xml") << "<profiles><participant";
  {
    WorkingDirectory cwd(good);
    auto alone = node::Participant::create(cfg.domain_id, "cwd", nullptr, false, {}, {}, profile);
    ASSERT_TRUE(alone) << alone.error().message;
    EXPECT_EQ((*alone)->get()->get_qos().wire_protocol().builtin.discovery_config.leaseDuration,
              eprosima::fastrtps::Duration_t(42, 0));
    ProfilesFile env((good / "DEFAULT_FASTRTPS_PROFILES.xml").string());
    for (int i = 0; i < 2; ++i) {
      auto both = node::Participant::create(cfg.domain_id, "cwd", nullptr, false, {}, {}, profile);
      ASSERT_TRUE(both) << both.error().message;
    }
  }
  WorkingDirectory cwd(bad);
  {
    auto refused = node::Participant::create(cfg.domain_id, "cwd_bad");
    ASSERT_FALSE(refused);
    EXPECT_NE(refused.error().message.find("DEFAULT_FASTRTPS_PROFILES.xml"), std::string::npos)
        << refused.error().message;
  }
  setenv("SKIP_DEFAULT_XML_FILE", "1", 1);
  auto skipped = node::Participant::create(cfg.domain_id, "cwd_skipped");
  unsetenv("SKIP_DEFAULT_XML_FILE");
  EXPECT_TRUE(skipped) << skipped.error().message;
}

// --participant-profile on every executable: a name no profile has stops it as bad input
// (exit 2) naming the option; dds.participant_profile in a config file the same, naming the key;
// a known name runs (send_goal without a node: no answer, exit 3).
TEST(XmlProfiles, ExecutablesTakeTheProfileFromTheFlagOrTheConfigAndNameAnUnknownOne) {
  const node::NodeConfig cfg = test_config("xml_cli");
  const std::string profile = "vnsba_cli_" + std::to_string(getpid());
  ProfilesFile env(write_temp_file("cli_profiles.xml", profiles_xml(profile, profile + "_topic")));
  const std::string config = write_temp_file("xml_cli.yaml", config_yaml(cfg));
  const std::string out_dir = FreshTempDir("xml_cli_out").string();
  const std::string map = std::string(VNSBA_CONFIG_DIR) + "/scenes/geb079.bt";
  const std::vector<std::pair<std::string, std::vector<std::string>>> runs = {
      {kNode, {"--config", config}},
      {kSendGoal, {"--config", config, "--start", "0", "0", "--goal", "1", "1", "--wait", "1"}},
      {kSlicer, {map, "--publish", "--config", config}},
      {kRecorder, {"--out", out_dir, "--config", config, "--duration", "1"}},
  };
  for (const auto& [binary, args] : runs) {
    std::vector<std::string> flagged = args;
    flagged.insert(flagged.end(), {"--participant-profile", profile + "_missing"});
    const auto [code, output] = run_to_exit(binary, flagged);
    EXPECT_EQ(code, 2) << binary << "\n" << output;
    EXPECT_NE(output.find("--participant-profile: found \"" + profile + "_missing\""),
              std::string::npos)
        << binary << "\n"
        << output;
  }
  const std::string bad_config = write_temp_file(
      "xml_cli_bad.yaml", config_yaml(cfg) + "dds:\n  participant_profile: " + profile + "_x\n");
  {
    const auto [code, output] = run_to_exit(kNode, {"--config", bad_config});
    EXPECT_EQ(code, 2) << output;
    EXPECT_NE(output.find("dds.participant_profile: found \"" + profile + "_x\""),
              std::string::npos)
        << output;
    EXPECT_EQ(output.find("up on domain"), std::string::npos) << output;
  }
  // The flag wins over the key.
  const auto [code, output] =
      run_to_exit(kSendGoal, {"--config", bad_config, "--participant-profile", profile, "--start",
                              "0", "0", "--goal", "1", "1", "--wait", "1"});
  EXPECT_EQ(code, 3) << output;
  EXPECT_NE(output.find("no planner node"), std::string::npos) << output;
}

// Intraprocess delivery stays off in every process of ours, even when a profiles file turns it
// on (Fast DDS 2.9 can write through a dangling pointer with it on when participants of one
// process are deleted one after another); the file's other settings still apply, and the node
// says which file's setting it ignored.
TEST(XmlProfiles, IntraprocessDeliveryStaysOffWhateverAFileSays) {
  using eprosima::fastrtps::xmlparser::XMLProfileManager;
  node::NodeConfig cfg = test_config("xml_intraprocess");
  // Without any file: Fast DDS's own default (FULL, as in a fresh process) is turned off.
  {
    auto settings = XMLProfileManager::library_settings();
    settings.intraprocess_delivery = eprosima::fastrtps::INTRAPROCESS_FULL;
    XMLProfileManager::library_settings(settings);
    setenv("SKIP_DEFAULT_XML_FILE", "1", 1);
    auto plain = node::Participant::create(cfg.domain_id, "no_file");
    unsetenv("SKIP_DEFAULT_XML_FILE");
    ASSERT_TRUE(plain) << plain.error().message;
    EXPECT_EQ(XMLProfileManager::library_settings().intraprocess_delivery,
              eprosima::fastrtps::INTRAPROCESS_OFF);
  }
  // A file that turns it on (and, last, one that turns it on and is refused): off after each.
  const std::string profile = "vnsba_intraprocess_" + std::to_string(getpid());
  const std::string path =
      write_temp_file("intraprocess_profiles.xml", R"(<?xml version="1.0" encoding="UTF-8" ?>
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <library_settings><intraprocess_delivery>FULL</intraprocess_delivery></library_settings>
  <profiles>
    <participant profile_name=")" + profile + R"(">
      <rtps><builtin><discovery_config><leaseDuration><sec>44</sec></leaseDuration></discovery_config></builtin></rtps>
    </participant>
  </profiles>
</dds>
)");
  ProfilesFile env(path);
  auto participant =
      node::Participant::create(cfg.domain_id, "intraprocess", nullptr, false, {}, {}, profile);
  ASSERT_TRUE(participant) << participant.error().message;
  EXPECT_EQ(XMLProfileManager::library_settings().intraprocess_delivery,
            eprosima::fastrtps::INTRAPROCESS_OFF);
  EXPECT_EQ((*participant)->get()->get_qos().wire_protocol().builtin.discovery_config.leaseDuration,
            eprosima::fastrtps::Duration_t(44, 0));
  // A node process reading the same file: up, and the setting it ignored named with its file.
  cfg.participant_profile = profile;
  ChildProcess node_process(
      kNode, {"--config", write_temp_file("xml_intraprocess.yaml",
                                          config_yaml(cfg) +
                                              "dds:\n  participant_profile: " + profile + "\n")});
  ASSERT_TRUE(node_process.wait_for_output("up on domain", 10s)) << node_process.output();
  EXPECT_NE(
      node_process.output().find(path + ": <library_settings><intraprocess_delivery> ignored"),
      std::string::npos)
      << node_process.output();
  node_process.signal(SIGINT);
  EXPECT_EQ(node_process.wait(), 0) << node_process.output();
  {
    const std::string refused =
        write_temp_file("intraprocess_refused.xml", R"(<?xml version="1.0" encoding="UTF-8" ?>
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <library_settings><intraprocess_delivery>FULL</intraprocess_delivery></library_settings>
  <profiles>
    <participant profile_name=")" + profile + R"(_twice"><rtps><name>one</name></rtps></participant>
    <participant profile_name=")" + profile + R"(_twice"><rtps><name>two</name></rtps></participant>
  </profiles>
</dds>
)");
    ProfilesFile refused_env(refused);
    ASSERT_FALSE(node::Participant::create(cfg.domain_id, "refused"));
    EXPECT_EQ(XMLProfileManager::library_settings().intraprocess_delivery,
              eprosima::fastrtps::INTRAPROCESS_OFF);
  }
}

// Last in this file: a default profile, once loaded, is the process's default for every later
// participant and endpoint (as in Fast DDS). Without a name, the file's default participant
// profile gives the participant its lease; the default data_writer profile every writer its
// lifespan, under the node's rules.
TEST(XmlProfiles, TheDefaultProfilesApplyWithoutAName) {
  const node::NodeConfig cfg = test_config("xml_default");
  ProfilesFile env(
      write_temp_file("default_profiles.xml", R"(<?xml version="1.0" encoding="UTF-8" ?>
<profiles xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <participant profile_name="vnsba_default_participant" is_default_profile="true">
    <rtps>
      <builtin><discovery_config><leaseDuration><sec>33</sec></leaseDuration></discovery_config></builtin>
      <userData><value>76.6e.73.62.61</value></userData>
    </rtps>
  </participant>
  <data_writer profile_name="vnsba_default_writer" is_default_profile="true">
    <qos><lifespan><duration><sec>5</sec></duration></lifespan></qos>
  </data_writer>
</profiles>
)"));
  auto participant = node::Participant::create(cfg.domain_id, "defaulted");
  ASSERT_TRUE(participant) << participant.error().message;
  const auto qos = (*participant)->get()->get_qos();
  EXPECT_EQ(qos.wire_protocol().builtin.discovery_config.leaseDuration,
            eprosima::fastrtps::Duration_t(33, 0));
  EXPECT_EQ(qos.user_data().data_vec(),
            (std::vector<eprosima::fastrtps::rtps::octet>{'v', 'n', 's', 'b', 'a'}));
  EXPECT_EQ(qos.name().to_string(), "defaulted");  // the node's rule: its own name
  auto writer = (*participant)
                    ->writer_on<vnsba_msgs::msg::dds_::PlanStatus_PubSubType>(
                        node::dds_topic_name(cfg, cfg.topics.plan_status),
                        node::writer_qos(node::TopicQos::kStatus, false))
                    .value();
  EXPECT_EQ(writer->get_qos().lifespan().duration, eprosima::fastrtps::Duration_t(5, 0));
  // The node's rule on top: keep all, at most kStatusHistory unacknowledged statuses.
  EXPECT_EQ(writer->get_qos().history().kind, eprosima::fastdds::dds::KEEP_ALL_HISTORY_QOS);
  EXPECT_EQ(writer->get_qos().resource_limits().max_samples, node::kStatusHistory);
}

}  // namespace
}  // namespace vnsba::test
