// The managed node's lifecycle over loopback DDS (managed_node.hpp): a ManagedNode in this process
// on real participants, its lifecycle_msgs services called by the generic service client
// (service_client.hpp) in both rmw mappings, its transition_event read, and its work checked at
// each step (plan_request answered NODE_INACTIVE and action goals rejected while inactive,
// planned while active, the work released at cleanup).
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "bus_client.hpp"
#include "lifecycle_msgs/msg/TransitionEventPubSubTypes.h"
#include "lifecycle_msgs/srv/ChangeStatePubSubTypes.h"
#include "lifecycle_msgs/srv/GetAvailableStatesPubSubTypes.h"
#include "lifecycle_msgs/srv/GetAvailableTransitionsPubSubTypes.h"
#include "lifecycle_msgs/srv/GetStatePubSubTypes.h"
#include "log_capture.hpp"
#include "vnsba/node/action_client.hpp"
#include "vnsba/node/managed_node.hpp"
#include "vnsba/node/service_client.hpp"

namespace vnsba::test {
namespace {

namespace lsrv = lifecycle_msgs::srv::dds_;
namespace lmsg = lifecycle_msgs::msg::dds_;
using node::ServiceClient;
using node::WireMapping;

struct LifecycleRun {
  LifecycleRun(const std::string& tag, WireMapping mapping) : cfg(configure(tag, mapping)) {
    node = std::make_unique<node::ManagedNode>(cfg, [this] { return reread(); });
    participant = node::Participant::create(cfg.domain_id, "vnsba_lifecycle_client").value();
    const std::string name = node::node_full_name(cfg);
    change_state = ServiceClient::create<lsrv::ChangeState_Request_PubSubType,
                                         lsrv::ChangeState_Response_PubSubType>(
                       *participant, name + "/change_state", mapping)
                       .value();
    get_state = ServiceClient::create<lsrv::GetState_Request_PubSubType,
                                      lsrv::GetState_Response_PubSubType>(
                    *participant, name + "/get_state", mapping)
                    .value();
    get_states = ServiceClient::create<lsrv::GetAvailableStates_Request_PubSubType,
                                       lsrv::GetAvailableStates_Response_PubSubType>(
                     *participant, name + "/get_available_states", mapping)
                     .value();
    get_transitions = ServiceClient::create<lsrv::GetAvailableTransitions_Request_PubSubType,
                                            lsrv::GetAvailableTransitions_Response_PubSubType>(
                          *participant, name + "/get_available_transitions", mapping)
                          .value();
    events_reader = participant
                        ->reader_on<lmsg::TransitionEvent_PubSubType>(
                            node::dds_topic_name(cfg, name + "/transition_event"),
                            node::reader_qos(node::TopicQos::kEvents), &events)
                        .value();
    action = node::ActionClient::create(*participant,
                                        node::ros_topic_name(cfg, cfg.topics.compute_path_to_pose),
                                        node::ActionKind::kComputePathToPose, mapping)
                 .value();
  }
  ~LifecycleRun() {
    node->stop();
    change_state.reset();
    get_state.reset();
    get_states.reset();
    get_transitions.reset();
    action.reset();
    participant->shutdown();
  }
  static node::NodeConfig configure(const std::string& tag, WireMapping mapping) {
    node::NodeConfig cfg = test_config(tag);
    cfg.lifecycle = node::LifecycleMode::kManaged;
    cfg.node_name = "lc" + std::to_string(getpid()) + "_" + tag;
    // A Fast DDS client is announced as eProsima's: told so, the node answers every client in
    // rmw_cyclonedds's mapping (as the action tests do).
    cfg.actions.reply_mapping = mapping == WireMapping::kRequestHeader
                                    ? node::ReplyMapping::kCycloneDds
                                    : node::ReplyMapping::kAuto;
    return cfg;
  }
  std::optional<node::NodeConfig> reread() {
    if (config_broken) return std::nullopt;
    return cfg;
  }

  bool wait_for_services() {
    for (ServiceClient* client :
         {change_state.get(), get_state.get(), get_states.get(), get_transitions.get()})
      if (!client->wait_for_server(10s)) return false;
    // The event reader matched too: transition_event is volatile.
    const auto end = std::chrono::steady_clock::now() + 10s;
    for (;;) {
      node::dds::SubscriptionMatchedStatus matched;
      events_reader->get_subscription_matched_status(matched);
      // Both sides: the node's writer must have matched our reader as well.
      if (matched.current_count > 0 && node->event_readers() > 0) return true;
      if (std::chrono::steady_clock::now() > end) return false;
      std::this_thread::sleep_for(10ms);
    }
  }

  std::optional<bool> change(uint8_t id, const std::string& label = "") {
    lsrv::ChangeState_Request_ request;
    request.transition().id(id);
    request.transition().label(label);
    auto reply = change_state->call<lsrv::ChangeState_Response_>(request, 30s);
    if (!reply) return std::nullopt;
    return reply->success();
  }
  int state() {
    auto reply = get_state->call<lsrv::GetState_Response_>(lsrv::GetState_Request_(), 10s);
    EXPECT_TRUE(reply) << "no get_state reply";
    if (!reply) return -1;
    EXPECT_EQ(reply->current_state().label(),
              node::state_label(static_cast<node::LifecycleState>(reply->current_state().id())));
    return reply->current_state().id();
  }
  std::vector<int> transitions() {
    auto reply = get_transitions->call<lsrv::GetAvailableTransitions_Response_>(
        lsrv::GetAvailableTransitions_Request_(), 10s);
    EXPECT_TRUE(reply) << "no get_available_transitions reply";
    std::vector<int> ids;
    if (reply)
      for (const auto& d : reply->available_transitions()) ids.push_back(d.transition().id());
    return ids;
  }
  // The events received since the last call, as {transition id, start id, goal id}, waiting
  // for `count` of them.
  std::vector<std::array<int, 3>> take_events(size_t count) {
    events.wait([&](const auto& all) { return all.size() >= count; }, 10s);
    std::vector<std::array<int, 3>> out;
    for (const auto& e : events.take_all())
      out.push_back({e.transition().id(), e.start_state().id(), e.goal_state().id()});
    return out;
  }

  node::NodeConfig cfg;
  std::atomic<bool> config_broken{false};
  std::unique_ptr<node::ManagedNode> node;
  std::unique_ptr<node::Participant> participant;
  std::unique_ptr<ServiceClient> change_state, get_state, get_states, get_transitions;
  Collector<lmsg::TransitionEvent_> events;
  node::dds::DataReader* events_reader = nullptr;
  std::unique_ptr<node::ActionClient> action;
};

class LifecycleBothMappings : public ::testing::TestWithParam<WireMapping> {};

std::string lifecycle_mapping_name(const ::testing::TestParamInfo<WireMapping>& info) {
  return info.param == WireMapping::kRequestHeader ? "RequestHeader" : "SampleIdentity";
}

using LifecycleEvents = std::vector<std::array<int, 3>>;

TEST_P(LifecycleBothMappings, WalkUnconfiguredActiveInactiveFinalized) {
  const std::string tag = GetParam() == WireMapping::kRequestHeader ? "lch" : "lci";
  LifecycleRun run(tag, GetParam());
  ASSERT_TRUE(run.node->start().is_ok());
  ASSERT_TRUE(run.wait_for_services());
  BusClient bus(run.cfg);

  // Unconfigured (1): configure (1) and shutdown (5) available; all 11 states listed.
  EXPECT_EQ(run.state(), 1);
  EXPECT_EQ(run.transitions(), (std::vector<int>{1, 5}));
  auto states = run.get_states->call<lsrv::GetAvailableStates_Response_>(
      lsrv::GetAvailableStates_Request_(), 10s);
  ASSERT_TRUE(states);
  std::vector<int> state_ids;
  for (const auto& s : states->available_states()) state_ids.push_back(s.id());
  EXPECT_EQ(state_ids, (std::vector<int>{0, 1, 2, 3, 4, 10, 11, 12, 13, 14, 15}));
  EXPECT_EQ(run.node->planner(), nullptr);  // no work before configure

  // configure: unconfigured -> configuring -> inactive; the work exists, not planning.
  EXPECT_EQ(run.change(1), std::optional<bool>(true));
  EXPECT_EQ(run.take_events(2), (LifecycleEvents{{1, 1, 10}, {10, 10, 2}}));
  EXPECT_EQ(run.state(), 2);
  EXPECT_EQ(run.transitions(), (std::vector<int>{2, 3, 6}));
  ASSERT_NE(run.node->planner(), nullptr);
  ASSERT_TRUE(bus.wait_for_match(*run.node->planner()));
  bus.publish_slice(free_room(30, 20, 0.1));
  ASSERT_TRUE(run.node->planner()->wait_for_map(20s));
  ASSERT_TRUE(run.action->wait_for_server(10s));

  // Inactive: a plan_request is answered NODE_INACTIVE, an action goal rejected.
  auto inactive = bus.wait_status_for(bus.publish_request("r1", 0.5, 0.5, 2.5, 1.5));
  ASSERT_TRUE(inactive);
  EXPECT_EQ(inactive->code(), node::wire::NODE_INACTIVE) << inactive->message();
  EXPECT_EQ(inactive->code_name(), "NODE_INACTIVE");
  EXPECT_NE(inactive->message().find("inactive"), std::string::npos) << inactive->message();
  node::ActionGoalSpec goal;
  goal.goals = {node::to_pose_msg(2.5, 1.5, 0.0, "map", node::now_msg())};
  goal.start = node::to_pose_msg(0.5, 0.5, 0.0, "map", node::now_msg());
  goal.use_start = true;
  EXPECT_EQ(
      run.action->wait_accepted(run.action->send_goal(node::ActionClient::random_id(), goal), 10s),
      std::optional<bool>(false));

  // activate, by label: inactive -> activating -> active; requests and goals are planned.
  EXPECT_EQ(run.change(0, "activate"), std::optional<bool>(true));
  EXPECT_EQ(run.take_events(2), (LifecycleEvents{{3, 2, 13}, {30, 13, 3}}));
  EXPECT_EQ(run.state(), 3);
  EXPECT_EQ(run.transitions(), (std::vector<int>{4, 7}));
  auto planned = bus.wait_status_for(bus.publish_request("r2", 0.5, 0.5, 2.5, 1.5));
  ASSERT_TRUE(planned);
  EXPECT_EQ(planned->code(), node::wire::OK) << planned->message();
  auto result = run.action->plan(node::ActionClient::random_id(), goal, 20s);
  ASSERT_TRUE(result);
  EXPECT_EQ(result->status, node::GoalState::kSucceeded) << result->error_msg;

  // A transition not available from active (configure) changes nothing.
  EXPECT_EQ(run.change(1), std::optional<bool>(false));
  EXPECT_EQ(run.state(), 3);

  // deactivate: active -> deactivating -> inactive; refused again.
  EXPECT_EQ(run.change(4), std::optional<bool>(true));
  EXPECT_EQ(run.take_events(2), (LifecycleEvents{{4, 3, 14}, {40, 14, 2}}));
  EXPECT_EQ(run.state(), 2);
  auto again = bus.wait_status_for(bus.publish_request("r3", 0.5, 0.5, 2.5, 1.5));
  ASSERT_TRUE(again);
  EXPECT_EQ(again->code(), node::wire::NODE_INACTIVE);

  // cleanup: inactive -> cleaningup -> unconfigured; the work and its map released.
  EXPECT_EQ(run.change(2), std::optional<bool>(true));
  EXPECT_EQ(run.take_events(2), (LifecycleEvents{{2, 2, 11}, {20, 11, 1}}));
  EXPECT_EQ(run.state(), 1);
  EXPECT_EQ(run.node->planner(), nullptr);

  // shutdown (by label; from unconfigured it is transition 5): finalized, nothing available,
  // get_state still answered.
  EXPECT_EQ(run.change(0, "shutdown"), std::optional<bool>(true));
  EXPECT_EQ(run.take_events(2), (LifecycleEvents{{5, 1, 12}, {50, 12, 4}}));
  EXPECT_EQ(run.state(), 4);
  EXPECT_TRUE(run.transitions().empty());
  EXPECT_EQ(run.change(1), std::optional<bool>(false));
  EXPECT_EQ(run.state(), 4);
}

INSTANTIATE_TEST_SUITE_P(Lifecycle, LifecycleBothMappings,
                         ::testing::Values(WireMapping::kSampleIdentity,
                                           WireMapping::kRequestHeader),
                         lifecycle_mapping_name);

TEST(LifecycleNode, ABadConfigFailsConfigureAndTheNodeStaysUnconfigured) {
  LifecycleRun run("lcbad", WireMapping::kSampleIdentity);
  ASSERT_TRUE(run.node->start().is_ok());
  ASSERT_TRUE(run.wait_for_services());
  run.config_broken = true;
  EXPECT_EQ(run.change(1), std::optional<bool>(false));
  EXPECT_EQ(run.take_events(2), (LifecycleEvents{{1, 1, 10}, {11, 10, 1}}));
  EXPECT_EQ(run.state(), 1);
  EXPECT_EQ(run.node->planner(), nullptr);
  // Fixed, it configures.
  run.config_broken = false;
  EXPECT_EQ(run.change(0, "configure"), std::optional<bool>(true));
  EXPECT_EQ(run.state(), 2);
}

TEST(LifecycleNode, ConcurrentChangeStatesRunOneTransitionAtATime) {
  LifecycleRun run("lccc", WireMapping::kSampleIdentity);
  ASSERT_TRUE(run.node->start().is_ok());
  ASSERT_TRUE(run.wait_for_services());
  lsrv::ChangeState_Request_ configure;
  configure.transition().id(1);
  // Five at once: the first configures; the others arrive while it runs (refused) or after it
  // (configure is not available from inactive): exactly one succeeds.
  std::vector<int64_t> requests;
  for (int i = 0; i < 5; ++i) requests.push_back(run.change_state->request(configure));
  int succeeded = 0;
  for (int64_t request : requests) {
    auto reply = run.change_state->wait<lsrv::ChangeState_Response_>(request, 30s);
    ASSERT_TRUE(reply) << "a change_state went unanswered";
    succeeded += reply->success() ? 1 : 0;
  }
  EXPECT_EQ(succeeded, 1);
  EXPECT_EQ(run.state(), 2);
  EXPECT_EQ(run.take_events(2), (LifecycleEvents{{1, 1, 10}, {10, 10, 2}}));
}

TEST(LifecycleNode, MalformedRequestsAreDroppedWithOneLinePerClientAndServiceGoesOn) {
  LogCapture log;
  LifecycleRun run("lcbadreq", WireMapping::kSampleIdentity);
  ASSERT_TRUE(run.node->start().is_ok());
  ASSERT_TRUE(run.wait_for_services());
  // A Transition whose label announces 2^31 bytes in a 12-byte sample: not decodable.
  node::RawSample garbage;
  garbage.bytes = {0, 1, 0, 0, 1, 0, 0, 0, 0xff, 0xff, 0xff, 0x7f};
  for (int i = 0; i < 3; ++i) run.change_state->send_raw(garbage);
  // Answered in order after them: a valid change_state and get_state.
  EXPECT_EQ(run.change(1), std::optional<bool>(true));
  EXPECT_EQ(run.state(), 2);
  EXPECT_EQ(log.matching({"change_state request from participant", "dropped"}).size(), 1u);
  EXPECT_EQ(run.change_state->unmatched_replies(), 0u);  // nothing answered the garbage
  run.node->stop();
}

TEST(LifecycleNode, SelfActivatingReportsActiveAndPlans) {
  node::NodeConfig cfg = LifecycleRun::configure("lcself", WireMapping::kSampleIdentity);
  cfg.lifecycle = node::LifecycleMode::kSelfActivating;
  node::ManagedNode managed(cfg, nullptr);
  ASSERT_TRUE(managed.start().is_ok());
  EXPECT_EQ(managed.state(), node::LifecycleState::kActive);
  auto participant = node::Participant::create(cfg.domain_id, "vnsba_lifecycle_client").value();
  auto get_state =
      ServiceClient::create<lsrv::GetState_Request_PubSubType, lsrv::GetState_Response_PubSubType>(
          *participant, node::node_full_name(cfg) + "/get_state", WireMapping::kSampleIdentity)
          .value();
  ASSERT_TRUE(get_state->wait_for_server(10s));
  auto reply = get_state->call<lsrv::GetState_Response_>(lsrv::GetState_Request_(), 10s);
  ASSERT_TRUE(reply);
  EXPECT_EQ(reply->current_state().id(), 3);
  EXPECT_EQ(reply->current_state().label(), "active");
  BusClient bus(cfg);
  ASSERT_NE(managed.planner(), nullptr);
  ASSERT_TRUE(bus.wait_for_match(*managed.planner()));
  bus.publish_slice(free_room(30, 20, 0.1));
  ASSERT_TRUE(managed.planner()->wait_for_map(20s));
  auto planned = bus.wait_status_for(bus.publish_request("s1", 0.5, 0.5, 2.5, 1.5));
  ASSERT_TRUE(planned);
  EXPECT_EQ(planned->code(), node::wire::OK) << planned->message();
  managed.stop();
  get_state.reset();
  participant->shutdown();
}

}  // namespace
}  // namespace vnsba::test
