// The action goal state machine and the request/reply mapping, without DDS (action_goals.hpp,
// service_wire.hpp), against rcl_action's rules as written in its documentation.
#include <gtest/gtest.h>

#include "nav2_msgs/action/ComputePathToPose.h"
#include "vnsba/node/action_goals.hpp"
#include "vnsba/node/service_wire.hpp"

namespace vnsba::test {
namespace {

using node::CancelCode;
using node::GoalStamp;
using node::GoalState;
using node::GoalUuid;
using Goals = node::ActionGoals<std::string, int>;
using namespace std::chrono_literals;

GoalUuid id(uint8_t n) {
  GoalUuid u{};
  u[0] = n;
  return u;
}

TEST(ActionGoals, AGoalRunsToItsEndAndAWaitingGetResultIsAnsweredThen) {
  Goals goals(10s, 10);
  const auto now = Goals::Clock::now();
  ASSERT_TRUE(goals.accept(id(1), {5, 0}));
  EXPECT_EQ(goals.state(id(1)), GoalState::kAccepted);
  EXPECT_FALSE(goals.accept(id(1), {6, 0})) << "an id in use is rejected";
  EXPECT_FALSE(goals.result_or_wait(id(1), 7).has_value()) << "not finished: parked";
  EXPECT_TRUE(goals.execute(id(1)));
  EXPECT_FALSE(goals.execute(id(1))) << "only an ACCEPTED goal starts executing";
  EXPECT_FALSE(goals.result_or_wait(id(1), 8).has_value());
  const std::vector<int> waiting = goals.finish(id(1), GoalState::kSucceeded, "path", now);
  EXPECT_EQ(waiting, (std::vector<int>{7, 8}));
  EXPECT_TRUE(goals.finish(id(1), GoalState::kAborted, "again", now).empty())
      << "a finished goal does not finish twice";
  const auto answer = goals.result_or_wait(id(1), 9);
  ASSERT_TRUE(answer.has_value());
  EXPECT_EQ(answer->state, GoalState::kSucceeded);
  EXPECT_EQ(answer->result, "path");
  EXPECT_FALSE(goals.accept(id(1), {7, 0})) << "a kept result still holds its id";
  // An id never seen: answered at once with UNKNOWN.
  const auto unknown = goals.result_or_wait(id(2), 1);
  ASSERT_TRUE(unknown.has_value());
  EXPECT_EQ(unknown->state, GoalState::kUnknown);
}

TEST(ActionGoals, CancelFollowsRclActionsRules) {
  const auto now = Goals::Clock::now();
  auto fresh = [&] {
    auto goals = std::make_unique<Goals>(10s, 10);
    goals->accept(id(1), {1, 0});
    goals->accept(id(2), {2, 0});
    goals->accept(id(3), {3, 0});
    goals->execute(id(2));
    goals->accept(id(4), {4, 0});
    goals->finish(id(4), GoalState::kSucceeded, "", now);
    return goals;
  };
  auto ids = [](const Goals::CancelOutcome& o) {
    std::set<uint8_t> out;
    for (const auto& e : o.canceling) out.insert(e.id[0]);
    return out;
  };
  {  // zero id, zero stamp: every goal not finished
    auto goals = fresh();
    const auto o = goals->cancel(GoalUuid{}, {});
    EXPECT_EQ(o.code, CancelCode::kNone);
    EXPECT_EQ(ids(o), (std::set<uint8_t>{1, 2, 3}));
    EXPECT_EQ(goals->state(id(2)), GoalState::kCanceling);
    EXPECT_EQ(goals->state(id(4)), GoalState::kSucceeded);
  }
  {  // zero id, a stamp: every goal accepted at or before it
    auto goals = fresh();
    EXPECT_EQ(ids(goals->cancel(GoalUuid{}, {2, 0})), (std::set<uint8_t>{1, 2}));
  }
  {  // an id, zero stamp: that goal only
    auto goals = fresh();
    EXPECT_EQ(ids(goals->cancel(id(3), {})), (std::set<uint8_t>{3}));
    EXPECT_EQ(goals->state(id(1)), GoalState::kAccepted);
  }
  {  // an id and a stamp: that goal and those before the stamp
    auto goals = fresh();
    EXPECT_EQ(ids(goals->cancel(id(3), {1, 0})), (std::set<uint8_t>{1, 3}));
  }
  {  // unknown and finished goals
    auto goals = fresh();
    EXPECT_EQ(goals->cancel(id(9), {}).code, CancelCode::kUnknownGoalId);
    const auto finished = goals->cancel(id(4), {});
    EXPECT_EQ(finished.code, CancelCode::kGoalTerminated);
    EXPECT_TRUE(finished.canceling.empty());
  }
}

TEST(ActionGoals, FinishedGoalsAreForgottenAfterTheTimeoutOrBeyondTheCap) {
  Goals goals(1000ms, 3);
  const auto t0 = Goals::Clock::now();
  for (uint8_t n = 1; n <= 5; ++n) {
    goals.accept(id(n), {n, 0});
    goals.finish(id(n), GoalState::kAborted, "r", t0 + std::chrono::milliseconds(n));
  }
  goals.accept(id(6), {6, 0});  // running: never forgotten
  EXPECT_EQ(goals.expire(t0 + 10ms), 2u) << "the cap keeps the 3 newest finished";
  EXPECT_EQ(goals.state(id(1)), GoalState::kUnknown);
  EXPECT_EQ(goals.state(id(3)), GoalState::kAborted);
  EXPECT_EQ(goals.size(), 4u);
  ASSERT_TRUE(goals.next_expiry().has_value());
  EXPECT_EQ(*goals.next_expiry(), t0 + 3ms + 1000ms);
  EXPECT_EQ(goals.expire(t0 + 1004ms), 2u);
  EXPECT_EQ(goals.expire(t0 + 2000ms), 1u);
  EXPECT_EQ(goals.size(), 1u);
  EXPECT_EQ(goals.state(id(6)), GoalState::kAccepted);
  EXPECT_TRUE(goals.accept(id(1), {9, 0})) << "a forgotten id may be used again";
}

TEST(ActionGoals, OverTheCapADeliveredResultGoesBeforeOneNobodyHasAskedFor) {
  Goals goals(1000s, 2);
  const auto t0 = Goals::Clock::now();
  for (uint8_t n = 1; n <= 2; ++n) {
    goals.accept(id(n), {n, 0});
    goals.finish(id(n), GoalState::kSucceeded, "r", t0);
  }
  ASSERT_TRUE(goals.result_or_wait(id(2), 0).has_value());  // 2's client has its result
  goals.accept(id(3), {3, 0});
  goals.finish(id(3), GoalState::kSucceeded, "r", t0);
  EXPECT_EQ(goals.expire(t0), 1u);
  EXPECT_EQ(goals.state(id(2)), GoalState::kUnknown) << "the delivered one went";
  EXPECT_EQ(goals.state(id(1)), GoalState::kSucceeded) << "the undelivered older one stays";
  goals.accept(id(4), {4, 0});
  goals.finish(id(4), GoalState::kSucceeded, "r", t0);
  EXPECT_EQ(goals.expire(t0), 1u);
  EXPECT_EQ(goals.state(id(1)), GoalState::kUnknown) << "none delivered: the oldest goes";
}

TEST(ServiceWire, TheMappingFollowsTheVendorThenTheRequestThenTheOverride) {
  using node::ReplyMapping;
  using node::WireMapping;
  EXPECT_EQ(node::choose_mapping(ReplyMapping::kAuto, node::kVendorCyclone, true),
            WireMapping::kRequestHeader);
  EXPECT_EQ(node::choose_mapping(ReplyMapping::kAuto, node::kVendorEprosima, false),
            WireMapping::kSampleIdentity);
  EXPECT_EQ(node::choose_mapping(ReplyMapping::kAuto, std::nullopt, true),
            WireMapping::kSampleIdentity);
  EXPECT_EQ(node::choose_mapping(ReplyMapping::kAuto, std::nullopt, false),
            WireMapping::kRequestHeader);
  EXPECT_EQ(node::choose_mapping(ReplyMapping::kCycloneDds, node::kVendorEprosima, true),
            WireMapping::kRequestHeader);
  EXPECT_EQ(node::choose_mapping(ReplyMapping::kFastRtps, node::kVendorCyclone, false),
            WireMapping::kSampleIdentity);
}

// rmw_cyclonedds's request: the 16-byte header right after the encapsulation, then the message
// as plain CDR; the same bytes without the header are rmw_fastrtps's.
TEST(ServiceWire, ARequestHeaderPrecedesTheMessageAndComesBackWithIt) {
  using Request = nav2_msgs::action::dds_::ComputePathToPose_GetResult_Request_;
  Request request;
  GoalUuid goal_id;
  for (size_t i = 0; i < goal_id.size(); ++i) goal_id[i] = static_cast<uint8_t>(0xa0 + i);
  request.goal_id().uuid(goal_id);
  node::RequestHeader header;
  for (size_t i = 0; i < header.size(); ++i) header[i] = static_cast<uint8_t>(i + 1);
  const auto with = node::encode_request(request, node::WireMapping::kRequestHeader, header);
  const auto without = node::encode_request(request, node::WireMapping::kSampleIdentity, header);
  ASSERT_EQ(with.bytes.size(), 4u + 16u + 16u);
  ASSERT_EQ(without.bytes.size(), 4u + 16u);
  EXPECT_EQ(with.bytes[0], 0);
  EXPECT_EQ(with.bytes[1], 1) << "little-endian plain CDR";
  EXPECT_TRUE(std::equal(header.begin(), header.end(), with.bytes.begin() + 4));
  EXPECT_TRUE(std::equal(goal_id.begin(), goal_id.end(), with.bytes.begin() + 20));
  EXPECT_TRUE(std::equal(goal_id.begin(), goal_id.end(), without.bytes.begin() + 4));
  Request decoded;
  node::RequestHeader back{};
  EXPECT_EQ(node::decode_request(with, node::WireMapping::kRequestHeader, decoded, back), "");
  EXPECT_EQ(back, header);
  EXPECT_EQ(decoded.goal_id().uuid(), goal_id);
  // Truncated or not CDR: a message, never a throw.
  node::RawSample truncated{{0, 1, 0, 0, 1, 2}};
  EXPECT_NE(node::decode_request(truncated, node::WireMapping::kRequestHeader, decoded, back), "");
  node::RawSample xcdr2{{0, 7, 0, 0}};
  EXPECT_NE(node::decode_request(xcdr2, node::WireMapping::kSampleIdentity, decoded, back), "");
}

}  // namespace
}  // namespace vnsba::test
