// Issue 18, item 3: Fast DDS XML profiles, honoured as rmw_fastrtps honours them. Real
// participants over loopback; the profiles file is handed over through
// FASTRTPS_DEFAULT_PROFILES_FILE, the variable Fast DDS and ROS 2 users set.
#include <gtest/gtest.h>

#include <cstdlib>
#include <mutex>

#include "bus_client.hpp"
#include "child_process.hpp"
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
</profiles>
)";
}

// A participant profile's lease duration reaches the participant and what its peers see of it;
// a data_writer profile named after a topic reaches that topic's writer, with the node's own
// rule (reliable) on top of the profile's best effort.
TEST(XmlProfiles, AProfilesSettingsReachTheParticipantItsPeersAndTheTopicsWriter) {
  const node::NodeConfig cfg = test_config("xml_profiles");
  const std::string status_topic = node::dds_topic_name(cfg, cfg.topics.plan_status);
  const std::string profile = "vnsba_lease_42_" + std::to_string(getpid());
  ProfilesFile env(write_temp_file("profiles.xml", profiles_xml(profile, status_topic)));

  LeaseWatch watch;
  auto observer = node::Participant::create(cfg.domain_id, "observer", &watch).value();
  const std::string name = "profiled_" + std::to_string(getpid());
  auto profiled = node::Participant::create(cfg.domain_id, name, nullptr, false, {}, {}, profile);
  ASSERT_TRUE(profiled) << profiled.error().message;
  EXPECT_EQ((*profiled)->get()->get_qos().wire_protocol().builtin.discovery_config.leaseDuration,
            eprosima::fastrtps::Duration_t(42, 0));
  // Without the name: the file has no default profile, so Fast DDS's 20 s.
  auto plain = node::Participant::create(cfg.domain_id, "plain").value();
  EXPECT_EQ(plain->get()->get_qos().wire_protocol().builtin.discovery_config.leaseDuration,
            eprosima::fastrtps::Duration_t(20, 0));
  // What the observer learns over the wire.
  const auto end = std::chrono::steady_clock::now() + 10s;
  while (!watch.lease_of(name) && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(20ms);
  ASSERT_TRUE(watch.lease_of(name)) << "the profiled participant was never discovered";
  EXPECT_EQ(*watch.lease_of(name), 42);

  auto writer = (*profiled)
                    ->writer_on<vnsba_msgs::msg::dds_::PlanStatus_PubSubType>(
                        status_topic, node::writer_qos(node::TopicQos::kStatus, false))
                    .value();
  EXPECT_EQ(writer->get_qos().lifespan().duration, eprosima::fastrtps::Duration_t(7, 0));
  EXPECT_EQ(writer->get_qos().reliability().kind, node::dds::RELIABLE_RELIABILITY_QOS);
  // Another topic's writer gets no lifespan from it.
  auto other = (*profiled)
                   ->writer_on<vnsba_msgs::msg::dds_::PlanStatus_PubSubType>(
                       status_topic + "_other", node::writer_qos(node::TopicQos::kStatus, false))
                   .value();
  EXPECT_EQ(other->get_qos().lifespan().duration, node::dds::DataWriterQos().lifespan().duration);
}

// The node takes dds.participant_profile from its config; a name no profile has stops it,
// naming the key.
TEST(XmlProfiles, TheNodeUsesItsConfiguredProfileAndRefusesAnUnknownOne) {
  node::NodeConfig cfg = test_config("xml_node");
  const std::string profile = "vnsba_node_profile_" + std::to_string(getpid());
  ProfilesFile env(write_temp_file("node_profiles.xml", profiles_xml(profile, "unused")));
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
    const std::string missing = ::testing::TempDir() + "/no_such_profiles.xml";
    ProfilesFile env(missing);
    auto participant = node::Participant::create(cfg.domain_id, "bad");
    ASSERT_FALSE(participant);
    EXPECT_NE(participant.error().message.find(missing), std::string::npos)
        << participant.error().message;
    EXPECT_NE(participant.error().message.find("no such file"), std::string::npos);
  }
  for (const std::string& text :
       {std::string("<profiles><participant profile_name=\"x\">"), std::string("not xml at all"),
        std::string(
            "<profiles xmlns=\"http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles\"><participant "
            "profile_name=\"x\"><rtps><builtin><discovery_config><leaseDuration><sec>forty</sec>"
            "</leaseDuration></discovery_config></builtin></rtps></participant></profiles>")}) {
    const std::string path = write_temp_file("malformed_profiles.xml", text);
    ProfilesFile env(path);
    auto participant = node::Participant::create(cfg.domain_id, "bad");
    ASSERT_FALSE(participant) << text;
    EXPECT_NE(participant.error().message.find(path), std::string::npos)
        << participant.error().message;
  }
}

}  // namespace
}  // namespace vnsba::test
