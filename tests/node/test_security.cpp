// DDS Security (issue 18, item 1): the security section and SROS2's environment, the enclave
// checks, and real secured processes over loopback with a keystore made at test time by
// tools/make_keystore.sh: a secured node and clients plan; an unsecured participant and a client
// without permission to publish requests reach nothing; broken enclaves stop the executable
// naming the file.
//
// Domains 201..230 (201 + pid % 30; the keystore allows 0..230): the other bus tests use 1..200
// and the demo 100..199. Each test process makes its own keystore (its own CA), so two runs that
// share a domain cannot authenticate each other and stay apart.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include "bus_client.hpp"
#include "child_process.hpp"
#include "log_capture.hpp"
#include "temp_dir.hpp"
#include "vnsba/node/refused_peers.hpp"
#include "vnsba/node/security.hpp"

namespace vnsba::test {
namespace {

namespace fs = std::filesystem;

const std::string kMakeKeystore = VNSBA_MAKE_KEYSTORE;
const std::string kScene = std::string(VNSBA_CONFIG_DIR) + "/scenes/geb079.bt";

int security_domain() {
  return 201 + static_cast<int>(getpid() % 30);
}

// The keystore of this test process: the four enclaves of the script and /test/no_request, which
// may only read statuses (no publish permission at all).
const std::string& keystore() {
  static const std::string path = [] {
    // make_keystore.sh makes the folder itself.
    const std::string dir = (FreshTempDir("keystore") / "keystore").string();
    const std::string command = "bash '" + kMakeKeystore + "' '" + dir +
                                "' --enclave /test/no_request - plan_status >/dev/null";
    EXPECT_EQ(std::system(command.c_str()), 0) << command;
    return dir;
  }();
  return path;
}

// A config file for the processes: this test's domain, security from the security section.
std::string secured_config(const std::string& name, const std::string& enclave = "",
                           const std::string& strategy = "Enforce") {
  std::string yaml = "domain_id: " + std::to_string(security_domain()) +
                     "\nsecurity:\n  enable: true\n  keystore: " + keystore() +
                     "\n  strategy: " + strategy + "\n";
  if (!enclave.empty()) yaml += "  enclave: " + enclave + "\n";
  return write_temp_file(name, yaml);
}

// A copy of `from`'s files (links followed) as enclave /test/<name>, to break one of them.
fs::path copy_enclave(const std::string& from, const std::string& name) {
  const fs::path source = fs::path(keystore()) / "enclaves" / from.substr(1);
  const fs::path target = fs::path(keystore()) / "enclaves" / "test" / name;
  fs::remove_all(target);
  fs::create_directories(target);
  for (const auto& entry : fs::directory_iterator(source))
    fs::copy_file(fs::canonical(entry.path()), target / entry.path().filename());
  return target;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// The node's last log line after SIGINT ("stopped: N requests, N statuses, N maps ...").
std::string stop_and_summary(ChildProcess& node_process) {
  node_process.signal(SIGINT);
  EXPECT_EQ(node_process.wait(), 0) << node_process.output();
  const std::string out = node_process.output();
  const size_t at = out.find("stopped: ");
  return at == std::string::npos ? out : out.substr(at, out.find('\n', at) - at);
}

TEST(SecurityConfig, SectionIsReadAndEveryBadKeyNamed) {
  const auto good = node::parse_config(
      "security:\n  enable: true\n  keystore: ks\n  enclave: /vnsba/node\n  strategy: "
      "Permissive\n");
  ASSERT_TRUE(good.config) << good.errors.front();
  EXPECT_TRUE(good.config->security.enable);
  EXPECT_EQ(good.config->security.keystore, "ks");
  EXPECT_EQ(good.config->security.enclave, "/vnsba/node");
  EXPECT_EQ(good.config->security.strategy, node::SecurityStrategy::kPermissive);
  // Defaults: off, Enforce.
  const auto empty = node::parse_config("");
  ASSERT_TRUE(empty.config);
  EXPECT_FALSE(empty.config->security.enable);
  EXPECT_EQ(empty.config->security.strategy, node::SecurityStrategy::kEnforce);

  const auto bad = node::parse_config(
      "security:\n  enable: yes please\n  enclave: vnsba//node\n  strategy: enforce\n  "
      "keystor: ks\n");
  ASSERT_FALSE(bad.config);
  std::string all;
  for (const auto& e : bad.errors) all += e + "\n";
  for (const char* key : {"security.enable", "security.enclave", "security.strategy",
                          "security.keystor", "did you mean \"Enforce\""}) {
    EXPECT_NE(all.find(key), std::string::npos) << key << " not in:\n" << all;
  }
}

TEST(SecurityConfig, EnvironmentAsSros2ReadsIt) {
  std::map<std::string, std::string> env;
  auto lookup = [&](const char* name) -> const char* {
    const auto it = env.find(name);
    return it == env.end() ? nullptr : it->second.c_str();
  };
  node::SecurityConfig s;
  ASSERT_TRUE(node::apply_security_environment(s, lookup));
  EXPECT_FALSE(s.enable);  // nothing set: the config's values

  env = {{"ROS_SECURITY_ENABLE", "true"},
         {"ROS_SECURITY_KEYSTORE", "/ks"},
         {"ROS_SECURITY_STRATEGY", "Permissive"},
         {"ROS_SECURITY_ENCLAVE", "/a/b"}};
  ASSERT_TRUE(node::apply_security_environment(s, lookup));
  EXPECT_TRUE(s.enable);
  EXPECT_EQ(s.keystore, "/ks");
  EXPECT_EQ(s.enclave, "/a/b");
  EXPECT_EQ(s.strategy, node::SecurityStrategy::kPermissive);

  // rcl's override wins over ROS_SECURITY_ENCLAVE; "Enforce" exactly enforces, anything else is
  // Permissive; a value other than "true" never turns a configured security off.
  env = {{"ROS_SECURITY_ENABLE", "false"},
         {"ROS_SECURITY_STRATEGY", "Enforce"},
         {"ROS_SECURITY_ENCLAVE_OVERRIDE", "/c"},
         {"ROS_SECURITY_ENCLAVE", "/a/b"}};
  ASSERT_TRUE(node::apply_security_environment(s, lookup));
  EXPECT_TRUE(s.enable);
  EXPECT_EQ(s.enclave, "/c");
  EXPECT_EQ(s.strategy, node::SecurityStrategy::kEnforce);
  env = {{"ROS_SECURITY_STRATEGY", "enforce"}};
  ASSERT_TRUE(node::apply_security_environment(s, lookup));
  EXPECT_EQ(s.strategy, node::SecurityStrategy::kPermissive);

  env = {{"ROS_SECURITY_ENCLAVE_OVERRIDE", "no slash"}};
  const auto refused = node::apply_security_environment(s, lookup);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("ROS_SECURITY_ENCLAVE_OVERRIDE"), std::string::npos);

  EXPECT_EQ(node::with_default_enclave({}, "/vnsba/node").enclave, "/vnsba/node");
  EXPECT_EQ(node::with_default_enclave(s, "/vnsba/node").enclave, "/c");
}

TEST(SecurityConfig, EnforceNamesEveryMissingFilePermissiveRunsOpen) {
  const fs::path dir = copy_enclave("/vnsba/send_goal", "plan_missing");
  fs::remove(dir / "key.pem");
  fs::remove(dir / "permissions.p7s");
  node::SecurityConfig s;
  s.enable = true;
  s.keystore = keystore();
  s.enclave = "/test/plan_missing";
  const auto enforced = node::plan_security(s);
  ASSERT_FALSE(enforced);
  for (const char* file : {"key.pem", "permissions.p7s"})
    EXPECT_NE(enforced.error().message.find((dir / file).string()), std::string::npos)
        << enforced.error().message;

  s.strategy = node::SecurityStrategy::kPermissive;
  const auto open = node::plan_security(s);
  ASSERT_TRUE(open) << open.error().message;
  EXPECT_FALSE(open->secured);
  ASSERT_EQ(open->notes.size(), 1u);
  EXPECT_NE(open->notes[0].find("key.pem"), std::string::npos);

  // Complete: the six files as rmw_fastrtps passes them, and the three plugins.
  s.enclave = "/vnsba/send_goal";
  const auto secured = node::plan_security(s);
  ASSERT_TRUE(secured) << secured.error().message;
  EXPECT_TRUE(secured->secured);
  EXPECT_EQ(secured->properties.size(), 9u);

  if (geteuid() != 0) {  // root reads any file
    const fs::path unreadable = copy_enclave("/vnsba/send_goal", "plan_unreadable");
    fs::permissions(unreadable / "cert.pem", fs::perms::none);
    s.enclave = "/test/plan_unreadable";
    const auto refused = node::plan_security(s);  // Permissive too: the file is there
    ASSERT_FALSE(refused);
    EXPECT_NE(refused.error().message.find((unreadable / "cert.pem").string()), std::string::npos);
  }
}

// A secured slicer serves the map, a secured node plans, a secured send_goal gets its answer.
TEST(SecureBus, SecuredNodeAndClientsPlan) {
  ChildProcess node_process(kNode, {"--config", secured_config("secure_node.yaml")});
  ASSERT_TRUE(node_process.wait_for_output("up on domain", 10s)) << node_process.output();
  EXPECT_NE(node_process.output().find("DDS Security on"), std::string::npos);
  ChildProcess slicer(kSlicer, {kScene, "--publish", "--config", secured_config("slicer.yaml")});
  ASSERT_TRUE(node_process.wait_for_output("map accepted", 15s))
      << node_process.output() << slicer.output();
  const auto [code, output] =
      run_to_exit(kSendGoal, {"--config", secured_config("send_goal.yaml"), "--start", "2", "-6",
                              "--goal", "16", "-6.5", "--wait", "15"});
  EXPECT_EQ(code, 0) << output;
  EXPECT_NE(output.find(" OK "), std::string::npos) << output;
  // Nav2's action through the secured bus: the keystore grants its rq/ rr/ rt/ topics.
  const auto [action_code, action_output] =
      run_to_exit(kSendGoal, {"--config", secured_config("send_goal.yaml"), "--action", "--start",
                              "2", "-6", "--goal", "16", "-6.5", "--wait", "15"});
  EXPECT_EQ(action_code, 0) << action_output;
  EXPECT_NE(action_output.find("SUCCEEDED"), std::string::npos) << action_output;
  slicer.signal(SIGINT);
  EXPECT_EQ(slicer.wait(), 0) << slicer.output();
  EXPECT_EQ(stop_and_summary(node_process),
            "stopped: 2 requests, 2 statuses, 1 maps accepted, 0 rejected");
}

// An open participant on the secured node's domain and topics: it matches nothing, gets no
// status, and its map, goal and request never reach the node.
TEST(SecureBus, UnsecuredParticipantReachesNothing) {
  ChildProcess node_process(kNode, {"--config", secured_config("secure_node_open.yaml")});
  ASSERT_TRUE(node_process.wait_for_output("up on domain", 10s)) << node_process.output();
  node::NodeConfig cfg =
      paper_test_config();  // the default topic names, this test's domain, no security
  cfg.domain_id = security_domain();
  {
    BusClient intruder(cfg);
    EXPECT_FALSE(intruder.wait_for_node(3s));
    core::OccupancyGrid room;
    room.width = room.height = 10;
    room.resolution = 1.0;
    room.data.assign(100, core::kOccupancyFree);
    intruder.publish_slice(room);
    intruder.publish_goal(5, 5);
    intruder.publish_request("intruder", 1, 1, 8, 8);
    EXPECT_FALSE(intruder.wait_status("intruder", 2s));
    EXPECT_TRUE(intruder.statuses.snapshot().empty());
  }
  EXPECT_EQ(node_process.output().find("plan '"), std::string::npos) << node_process.output();
  EXPECT_EQ(stop_and_summary(node_process),
            "stopped: 0 requests, 0 statuses, 0 maps accepted, 0 rejected");
}

// An authenticated client whose permissions grant no publication cannot create its request
// writer (Access-Permissions refuses it), so nothing reaches the node.
TEST(SecureBus, ClientWithoutPublishPermissionCannotRequest) {
  ChildProcess node_process(kNode, {"--config", secured_config("secure_node_perm.yaml")});
  ASSERT_TRUE(node_process.wait_for_output("up on domain", 10s)) << node_process.output();
  const auto [code, output] =
      run_to_exit(kSendGoal, {"--config", secured_config("no_request.yaml", "/test/no_request"),
                              "--start", "1", "1", "--goal", "2", "2", "--wait", "3"});
  EXPECT_NE(code, 0) << output;
  EXPECT_NE(output.find("rt/plan_request"), std::string::npos) << output;
  EXPECT_EQ(stop_and_summary(node_process),
            "stopped: 0 requests, 0 statuses, 0 maps accepted, 0 rejected");
}

// Issue 18, item 3: security enabled by a Fast DDS XML participant profile alone, as
// rmw_fastrtps users enable it (the properties of the send_goal enclave in a <participant>
// profile, no security section): the client authenticates with the secured node and plans;
// without the profile the same client is open and gets no answer.
TEST(SecureBus, AnXmlProfileEnablingSecurityIsHonoured) {
  ChildProcess node_process(kNode, {"--config", secured_config("secure_node_xml.yaml")});
  ASSERT_TRUE(node_process.wait_for_output("up on domain", 10s)) << node_process.output();
  ChildProcess slicer(kSlicer,
                      {kScene, "--publish", "--config", secured_config("slicer_xml.yaml")});
  ASSERT_TRUE(node_process.wait_for_output("map accepted", 15s))
      << node_process.output() << slicer.output();

  node::SecurityConfig security;
  security.enable = true;
  security.keystore = keystore();
  security.enclave = "/vnsba/send_goal";
  const auto plan = node::plan_security(security);
  ASSERT_TRUE(plan && plan->secured) << (plan ? "open" : plan.error().message);
  std::string properties;
  for (const auto& [name, value] : plan->properties)
    properties += "<property><name>" + name + "</name><value>" + value + "</value></property>\n";
  const std::string profiles = write_temp_file(
      "secured_profiles.xml",
      "<?xml version=\"1.0\" encoding=\"UTF-8\" ?>\n<profiles "
      "xmlns=\"http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles\">\n<participant "
      "profile_name=\"secured_by_xml\"><rtps><propertiesPolicy><properties>\n" +
          properties + "</properties></propertiesPolicy></rtps></participant>\n</profiles>\n");
  const std::string open_config = write_temp_file(
      "open_send_goal.yaml", "domain_id: " + std::to_string(security_domain()) + "\n");
  setenv("FASTRTPS_DEFAULT_PROFILES_FILE", profiles.c_str(), 1);
  const auto [code, output] =
      run_to_exit(kSendGoal, {"--config", open_config, "--participant-profile", "secured_by_xml",
                              "--start", "2", "-6", "--goal", "16", "-6.5", "--wait", "15"});
  const auto [open_code, open_output] = run_to_exit(
      kSendGoal,
      {"--config", open_config, "--start", "2", "-6", "--goal", "16", "-6.5", "--wait", "3"});
  unsetenv("FASTRTPS_DEFAULT_PROFILES_FILE");
  EXPECT_EQ(code, 0) << output;
  EXPECT_NE(output.find(" OK "), std::string::npos) << output;
  EXPECT_EQ(open_code, 3) << open_output;
  slicer.signal(SIGINT);
  EXPECT_EQ(slicer.wait(), 0) << slicer.output();
  EXPECT_EQ(stop_and_summary(node_process),
            "stopped: 1 requests, 1 statuses, 1 maps accepted, 0 rejected");
}

// The security section's files replace a profile's properties of the same name: a profile
// naming a governance file that does not exist does not break the enclave's participant.
TEST(SecureBus, TheSecuritySectionWinsOverAProfilesProperties) {
  // In an empty directory of its own: nothing can have made it.
  const std::string stale = (FreshTempDir("stale_governance") / "governance.p7s").string();
  const std::string profiles = write_temp_file("stale_security_profiles.xml",
                                               R"(<?xml version="1.0" encoding="UTF-8" ?>
<profiles xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <participant profile_name="stale_security"><rtps><propertiesPolicy><properties>
    <property><name>dds.sec.access.builtin.Access-Permissions.governance</name>
      <value>file://)" + stale + R"(</value></property>
    <property><name>vnsba.test.kept</name><value>yes</value></property>
  </properties></propertiesPolicy></rtps></participant>
</profiles>
)");
  setenv("FASTRTPS_DEFAULT_PROFILES_FILE", profiles.c_str(), 1);
  node::SecurityConfig security;
  security.enable = true;
  security.keystore = keystore();
  security.enclave = "/vnsba/node";
  auto participant = node::Participant::create(security_domain(), "stale", nullptr, false, security,
                                               {}, "stale_security");
  unsetenv("FASTRTPS_DEFAULT_PROFILES_FILE");
  ASSERT_TRUE(participant) << participant.error().message;
  int governance = 0;
  bool kept = false;
  for (const auto& p : (*participant)->get()->get_qos().properties().properties()) {
    if (p.name() == "dds.sec.access.builtin.Access-Permissions.governance") {
      ++governance;
      EXPECT_NE(p.value().find(keystore()), std::string::npos) << p.value();
    }
    kept = kept || (p.name() == "vnsba.test.kept" && p.value() == "yes");
  }
  EXPECT_EQ(governance, 1);
  EXPECT_TRUE(kept);
}

// Broken enclaves stop the node before it is up, naming the file; Enforce never runs open.
TEST(SecureBus, TamperedGovernanceIsRefusedNamingIt) {
  const fs::path dir = copy_enclave("/vnsba/node", "tampered");
  std::string governance = read_text(dir / "governance.p7s");
  const size_t at = governance.find("<rtps_protection_kind>SIGN");
  ASSERT_NE(at, std::string::npos);
  governance.replace(at, std::string("<rtps_protection_kind>SIGN").size(),
                     "<rtps_protection_kind>NONE");
  std::ofstream(dir / "governance.p7s") << governance;
  const auto [code, output] =
      run_to_exit(kNode, {"--config", secured_config("tampered.yaml", "/test/tampered")});
  EXPECT_NE(code, 0) << output;
  EXPECT_NE(output.find((dir / "governance.p7s").string() + ": its signature does not verify"),
            std::string::npos)
      << output;
  EXPECT_EQ(output.find("up on domain"), std::string::npos) << output;
}

TEST(SecureBus, MissingKeyAndExpiredCertificateAreNamed) {
  const fs::path no_key = copy_enclave("/vnsba/node", "no_key");
  fs::remove(no_key / "key.pem");
  {
    const auto [code, output] =
        run_to_exit(kNode, {"--config", secured_config("no_key.yaml", "/test/no_key")});
    EXPECT_NE(code, 0) << output;
    EXPECT_NE(output.find("missing " + (no_key / "key.pem").string()), std::string::npos) << output;
    EXPECT_EQ(output.find("up on domain"), std::string::npos) << output;
  }
  // Permissive (SROS2's meaning): the same enclave runs unsecured, saying so.
  {
    ChildProcess open_node(kNode, {"--config", secured_config("no_key_permissive.yaml",
                                                              "/test/no_key", "Permissive")});
    EXPECT_TRUE(open_node.wait_for_output("up on domain", 10s)) << open_node.output();
    EXPECT_NE(open_node.output().find("running WITHOUT security"), std::string::npos);
    open_node.signal(SIGINT);
    EXPECT_EQ(open_node.wait(), 0);
  }
  // A certificate that expired yesterday (signed by the keystore's CA): Fast DDS refuses it.
  const fs::path expired = copy_enclave("/vnsba/node", "expired");
  const std::string ks = keystore();
  const std::string command = "openssl req -new -key '" + (expired / "key.pem").string() +
                              "' -subj '/CN=\\/vnsba\\/node' 2>/dev/null | openssl x509 -req "
                              "-days -1 -CA '" +
                              ks + "/public/ca.cert.pem' -CAkey '" + ks +
                              "/private/ca.key.pem' -set_serial 7 -out '" +
                              (expired / "cert.pem").string() + "' 2>/dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  const auto [code, output] =
      run_to_exit(kNode, {"--config", secured_config("expired.yaml", "/test/expired")});
  EXPECT_NE(code, 0) << output;
  EXPECT_NE(output.find((expired / "cert.pem").string() +
                        ": does not verify against "
                        "identity_ca.cert.pem: certificate has expired"),
            std::string::npos)
      << output;
}

// Issue 31 item 7: a peer from another CA was rejected with no line on the node. The node's
// participant listener hands discovery and authentication to RefusedPeers; this listener does
// the same for a participant secured as the node is.
class RefusalListener : public node::dds::DomainParticipantListener {
 public:
  explicit RefusalListener(node::RefusedPeers& peers) : peers_(peers) {}
  void on_participant_discovery(
      node::dds::DomainParticipant* participant,
      eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override {
    peers_.on_participant_discovery(participant, info);
  }
  void onParticipantAuthentication(
      node::dds::DomainParticipant*,
      eprosima::fastrtps::rtps::ParticipantAuthenticationInfo&& info) override {
    peers_.on_participant_authentication(info);
  }

 private:
  node::RefusedPeers& peers_;
};

std::string prefix_text(node::Participant& participant) {
  std::ostringstream out;
  out << participant.get()->guid().guidPrefix;
  return out.str();
}

node::SecurityConfig enclave_of(const std::string& store, const std::string& enclave) {
  node::SecurityConfig s;
  s.enable = true;
  s.keystore = store;
  s.enclave = enclave;
  return s;
}

// A participant secured as the node is (this process's keystore, /vnsba/node) whose listener
// reports to RefusedPeers, then a peer secured with `peer_security`, both on this test's domain.
struct RefusalScene {
  RefusalScene(std::chrono::milliseconds timeout, const node::SecurityConfig& peer_security)
      : refused(timeout),
        listener(refused),
        ours(secured("vnsba_node", &listener, enclave_of(keystore(), "/vnsba/node"))),
        peer(secured("peer", nullptr, peer_security)) {}
  ~RefusalScene() {
    if (peer) peer->shutdown();
    if (ours) ours->shutdown();
  }
  static std::unique_ptr<node::Participant> secured(const std::string& name,
                                                    node::dds::DomainParticipantListener* listener,
                                                    const node::SecurityConfig& security) {
    auto created = node::Participant::create(security_domain(), name, listener, false, security);
    EXPECT_TRUE(created) << created.error().message;
    return created ? std::move(created).value() : nullptr;
  }
  // The lines about the peer.
  std::vector<std::string> peer_lines() const {
    return log.matching({"refused remote participant " + prefix_text(*peer)});
  }

  const LogCapture log;  // first made, last gone: it outlives everything that logs
  node::RefusedPeers refused;
  RefusalListener listener;
  std::unique_ptr<node::Participant> ours, peer;
};

// The peer has a keystore of its own (another CA). PKI-DH's handshake runs from the smaller GUID
// to the larger, which checks the certificate first: when that is this participant, it refuses
// the peer itself and Fast DDS logs why; otherwise the peer refuses this participant and never
// answers, and the timeout reports it. Either way: one line, naming the peer's GUID prefix, its
// name and certificate, and why, however often the handshake is retried.
TEST(SecureBus, APeerFromAnotherCaIsLoggedOnceNamingItsGuidPrefixAndWhy) {
  const std::string other_keystore = (FreshTempDir("keystore_other_ca") / "keystore").string();
  const std::string command = "bash '" + kMakeKeystore + "' '" + other_keystore + "' >/dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  // A peer of this participant's own keystore authenticates: nothing is said of it, also after
  // the timeout. (Participants of other runs on this domain may be refused, rightly.)
  {
    RefusalScene friendly(5s, enclave_of(keystore(), "/vnsba/send_goal"));
    ASSERT_TRUE(friendly.ours && friendly.peer);
    std::this_thread::sleep_for(6s);  // a handshake took 2 s on a loaded machine
    EXPECT_TRUE(friendly.peer_lines().empty()) << friendly.peer_lines().front();
  }
  // Without security (or Permissive running open) no peer ever authenticates: none is followed.
  {
    const LogCapture log;
    node::RefusedPeers refused(1s);
    RefusalListener listener(refused);
    auto open = node::Participant::create(security_domain(), "open", &listener).value();
    auto peer = node::Participant::create(security_domain(), "open_peer").value();
    std::this_thread::sleep_for(2s);
    EXPECT_TRUE(log.matching({"refused remote participant " + prefix_text(*peer)}).empty());
    peer->shutdown();
    open->shutdown();
  }
  // An unsecured peer is refused at once, and said to be one.
  {
    RefusalScene open(1s, node::SecurityConfig());
    ASSERT_TRUE(open.ours && open.peer);
    ASSERT_TRUE(open.log.wait_for({"refused remote participant " + prefix_text(*open.peer)}, 10s));
    EXPECT_NE(open.peer_lines().front().find(
                  "('peer' on Fast DDS, no DDS Security identity): it runs without DDS Security"),
              std::string::npos)
        << open.peer_lines().front();
  }
  std::set<bool> directions;  // whether this participant checked the peer's certificate
  // The peer's enclave decides the direction: a secured participant's GUID prefix starts with a
  // hash of its certificate's subject. Enclaves of the other keystore until both were seen.
  for (const char* enclave :
       {"/vnsba/recorder", "/vnsba/send_goal", "/vnsba/slicer", "/vnsba/node"}) {
    SCOPED_TRACE(std::string("peer enclave ") + enclave);
    RefusalScene foreign(3s, enclave_of(other_keystore, enclave));
    ASSERT_TRUE(foreign.ours && foreign.peer);
    const bool we_check = foreign.peer->get()->guid() < foreign.ours->get()->guid();
    const std::string prefix = prefix_text(*foreign.peer);
    ASSERT_TRUE(foreign.log.wait_for({"refused remote participant " + prefix}, 20s))
        << "no line for the peer " << prefix;
    std::this_thread::sleep_for(2s);  // the peer's handshake is resent every 0.5 s
    const auto lines = foreign.peer_lines();
    ASSERT_EQ(lines.size(), 1u) << "one line per refused participant";
    EXPECT_EQ(lines[0].rfind("[warning] security: refused remote participant " + prefix, 0), 0u)
        << lines[0];
    // make_keystore's own enclaves carry a serial number that makes them sort high.
    EXPECT_NE(lines[0].find("('peer' on Fast DDS, certificate /CN=" + std::string(enclave) +
                            "/serialNumber="),
              std::string::npos)
        << lines[0];
    EXPECT_NE(lines[0].find(" of CA /CN=vnsba keystore CA)"), std::string::npos) << lines[0];
    const char* why = we_check ? "this participant checked its certificate and handshake and "
                                 "refused them (a certificate of another CA"
                               : "has not answered this participant's handshake";
    EXPECT_NE(lines[0].find(why), std::string::npos) << lines[0];
    directions.insert(we_check);
    if (directions.size() == 2) break;
  }
  EXPECT_EQ(directions.size(), 2u) << "both handshake directions were to be seen";
}

}  // namespace
}  // namespace vnsba::test
