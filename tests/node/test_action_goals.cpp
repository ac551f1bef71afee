// The action goal state machine and the request/reply mapping, without DDS (action_goals.hpp,
// service_wire.hpp), against rcl_action's rules as written in its documentation; the catalog of
// the Nav2 actions (action_catalog.hpp) against nav2_msgs' definitions in idl/.
#include <gtest/gtest.h>

#include <cctype>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "nav2_msgs/action/ComputePathToPose.h"
#include "vnsba/node/action_catalog.hpp"
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
  // rcl_action_process_cancel_request's two cases the node once answered otherwise (issue 44):
  {  // an id with a stamp: ERROR_NONE, never UNKNOWN_GOAL_ID or GOAL_TERMINATED
    auto goals = fresh();
    const auto unknown = goals->cancel(id(9), {2, 0});
    EXPECT_EQ(unknown.code, CancelCode::kNone);
    EXPECT_EQ(ids(unknown), (std::set<uint8_t>{1, 2}));
    auto goals2 = fresh();
    const auto finished = goals2->cancel(id(4), {0, 5});  // a stamp before every goal
    EXPECT_EQ(finished.code, CancelCode::kNone);
    EXPECT_TRUE(finished.canceling.empty());
  }
  {  // a goal that is CANCELING already cannot be canceled: GOAL_TERMINATED with an id alone,
     // and left out of the list otherwise
    auto goals = fresh();
    ASSERT_EQ(ids(goals->cancel(id(2), {})), (std::set<uint8_t>{2}));
    const auto again = goals->cancel(id(2), {});
    EXPECT_EQ(again.code, CancelCode::kGoalTerminated);
    EXPECT_TRUE(again.canceling.empty());
    const auto all = goals->cancel(GoalUuid{}, {});
    EXPECT_EQ(all.code, CancelCode::kNone);
    EXPECT_EQ(ids(all), (std::set<uint8_t>{1, 3}));
  }
}

// rcl_action_transition_goal_state: SUCCEEDED and ABORTED only from EXECUTING or CANCELING, and
// CANCELED only from CANCELING. A goal that ends while ACCEPTED passes through EXECUTING or
// CANCELING (an rclcpp_action server calls execute() first); a finished goal stays as it is.
TEST(ActionGoals, OnlyRclActionsTransitionsHappen) {
  const auto now = Goals::Clock::now();
  for (const GoalState end : {GoalState::kSucceeded, GoalState::kAborted, GoalState::kCanceled}) {
    Goals goals(10s, 10);
    ASSERT_TRUE(goals.accept(id(1), {1, 0}));
    EXPECT_TRUE(goals.finish(id(1), end, "r", now).empty());
    EXPECT_EQ(goals.state(id(1)), end);
    EXPECT_FALSE(goals.execute(id(1))) << "a finished goal does not execute";
    EXPECT_EQ(goals.cancel(id(1), {}).code, CancelCode::kGoalTerminated);
  }
  Goals goals(10s, 10);
  goals.accept(id(1), {1, 0});
  EXPECT_TRUE(goals.finish(id(1), GoalState::kExecuting, "r", now).empty());
  EXPECT_EQ(goals.state(id(1)), GoalState::kAccepted) << "finish() takes a terminal state only";
}

// The one byte budget over several servers (forget_beyond_budget): the oldest delivered result of
// any server goes first, then the oldest of any; running goals are never forgotten.
TEST(ActionGoals, OneByteBudgetOverSeveralServersForgetsTheOldestDeliveredFirst) {
  const auto t0 = Goals::Clock::now();
  Goals a(1000s, 100), b(1000s, 100);
  auto finish = [&](Goals& g, uint8_t n, int ms, size_t bytes) {
    g.accept(id(n), {n, 0});
    g.finish(id(n), GoalState::kSucceeded, "r", t0 + std::chrono::milliseconds(ms), bytes);
  };
  finish(a, 1, 1, 100);
  finish(b, 2, 2, 100);
  finish(a, 3, 3, 100);
  finish(b, 4, 4, 100);
  b.accept(id(5), {5, 0});                              // running
  ASSERT_TRUE(b.result_or_wait(id(4), 0).has_value());  // 4's client has it
  EXPECT_EQ(a.kept_bytes() + b.kept_bytes(), 400u);
  const std::vector<Goals*> both = {&a, &b};
  EXPECT_EQ(node::forget_beyond_budget(both, 400), 0u);
  EXPECT_EQ(node::forget_beyond_budget(both, 300), 1u);
  EXPECT_EQ(b.state(id(4)), GoalState::kUnknown) << "the delivered one went first";
  EXPECT_EQ(node::forget_beyond_budget(both, 150), 2u);
  EXPECT_EQ(a.state(id(1)), GoalState::kUnknown) << "then the oldest of any server";
  EXPECT_EQ(b.state(id(2)), GoalState::kUnknown);
  EXPECT_EQ(a.state(id(3)), GoalState::kSucceeded);
  EXPECT_EQ(node::forget_beyond_budget(both, 0), 1u);
  EXPECT_EQ(a.kept_bytes() + b.kept_bytes(), 0u);
  EXPECT_EQ(b.state(id(5)), GoalState::kAccepted) << "a running goal is never forgotten";
}

// The status list: every goal not finished and the newest `max_finished` finished ones.
TEST(ActionGoals, TheStatusListHoldsRunningGoalsAndTheLastFinished) {
  const auto t0 = Goals::Clock::now();
  Goals goals(1000s, 100);
  for (uint8_t n = 1; n <= 10; ++n) {
    goals.accept(id(n), {n, 0});
    if (n <= 8) goals.finish(id(n), GoalState::kAborted, "r", t0 + std::chrono::milliseconds(n));
  }
  std::set<uint8_t> listed;
  for (const auto& entry : goals.statuses(3)) listed.insert(entry.id[0]);
  EXPECT_EQ(listed, (std::set<uint8_t>{6, 7, 8, 9, 10}));
  EXPECT_EQ(goals.statuses(0).size(), 2u);
  EXPECT_EQ(goals.statuses(100).size(), 10u);
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

// A result encoded once and sent to many clients: every reply shares the message's bytes (none
// copied per requester), and each decodes, under its client's mapping, to the message with the
// client's own header.
TEST(ServiceWire, RepliesOfOneEncodedMessageShareItsBytes) {
  using Response = nav2_msgs::action::dds_::ComputePathToPose_GetResult_Response_;
  Response response;
  response.status(4);
  response.result().error_msg("ok");
  response.result().path().header().frame_id("map");
  response.result().path().poses().resize(1000);
  for (size_t i = 0; i < 1000; ++i)
    response.result().path().poses()[i].pose().position().x(0.05 * static_cast<double>(i));
  const auto message = node::encode_message(response);
  node::RequestHeader header;
  for (size_t i = 0; i < header.size(); ++i) header[i] = static_cast<uint8_t>(0x40 + i);
  std::vector<node::RawSample> replies;
  for (int i = 0; i < 50; ++i)
    replies.push_back(node::reply_with_message(
        message, i % 2 ? node::WireMapping::kRequestHeader : node::WireMapping::kSampleIdentity,
        header));
  EXPECT_EQ(message.use_count(), 51) << "every reply holds the one message";
  for (int i = 0; i < 2; ++i) {
    const auto mapping = i ? node::WireMapping::kRequestHeader : node::WireMapping::kSampleIdentity;
    const node::RawSample& reply = replies[static_cast<size_t>(i)];
    EXPECT_LE(reply.bytes.size(), 20u) << "only the encapsulation and the header are its own";
    // The same bytes as encoding the message for this client alone.
    const node::RawSample whole = node::encode_reply(response, mapping, header);
    std::vector<uint8_t> joined = reply.bytes;
    joined.insert(joined.end(), reply.shared_tail->begin(), reply.shared_tail->end());
    EXPECT_EQ(joined, whole.bytes);
    EXPECT_EQ(reply.size(), whole.bytes.size());
    Response decoded;
    node::RequestHeader back{};
    node::RawSample flat;
    flat.bytes = joined;
    ASSERT_EQ(node::decode_reply(flat, mapping, decoded, back), "");
    EXPECT_EQ(decoded.result().path().poses().size(), 1000u);
    EXPECT_EQ(decoded.result().path().poses()[999].pose().position().x(), 0.05 * 999);
    if (i) {
      EXPECT_EQ(back, header);
    }
  }
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
  node::RawSample truncated;
  truncated.bytes = {0, 1, 0, 0, 1, 2};
  EXPECT_NE(node::decode_request(truncated, node::WireMapping::kRequestHeader, decoded, back), "");
  node::RawSample xcdr2;
  xcdr2.bytes = {0, 7, 0, 0};
  EXPECT_NE(node::decode_request(xcdr2, node::WireMapping::kSampleIdentity, decoded, back), "");
}

// The result error codes an action's IDL file documents ("error_code: 0 none, 200 unknown, 201
// invalid planner, ..."), as code -> nav2_msgs constant name ("INVALID_PLANNER").
std::map<uint16_t, std::string> documented_error_codes(const std::string& type_name) {
  std::ifstream file(std::string(VNSBA_SOURCE_DIR) + "/idl/" + type_name + ".idl");
  std::string comment, line;
  while (std::getline(file, line) && line.rfind("//", 0) == 0) comment += line.substr(2);
  const size_t from = comment.find("error_code:");
  const std::string list = comment.substr(from, comment.find('.', from) - from);
  std::map<uint16_t, std::string> codes;
  const std::regex entry(R"((\d+) ([A-Za-z ]+?)\s*(,|$))");
  for (auto it = std::sregex_iterator(list.begin(), list.end(), entry);
       it != std::sregex_iterator(); ++it) {
    std::string name;
    for (char c : (*it)[2].str()) name += c == ' ' ? '_' : static_cast<char>(std::toupper(c));
    codes[static_cast<uint16_t>(std::stoi((*it)[1].str()))] = name;
  }
  return codes;
}

TEST(ActionCatalog, EachActionNamesTheErrorCodesItsIdlDocuments) {
  ASSERT_GE(node::nav2_actions().size(), 2u);
  std::set<std::string> options;
  for (size_t i = 0; i < node::nav2_actions().size(); ++i) {
    const node::Nav2ActionInfo& action = node::nav2_actions()[i];
    SCOPED_TRACE(action.type_name);
    EXPECT_EQ(static_cast<size_t>(action.kind), i) << "an ActionKind is its place in the list";
    EXPECT_TRUE(options.insert(action.option_name).second) << "vnsba_send_goal --action names";
    const std::map<uint16_t, std::string> documented = documented_error_codes(action.type_name);
    ASSERT_GE(documented.size(), 3u) << "the IDL file documents its codes";
    ASSERT_EQ(documented.begin()->second, "NONE");
    EXPECT_EQ(action.errors.base, std::next(documented.begin())->first);
    EXPECT_EQ(action.errors.count, documented.size() - 1);
    for (const auto& [code, name] : documented) {
      EXPECT_EQ(action.errors.name(code), name) << code;
      if (code != 0) {
        EXPECT_EQ(action.errors.code(name), code) << name;
      }
    }
    EXPECT_EQ(action.errors.name(documented.rbegin()->first + 1), "NOT_A_NAV2_CODE");
    EXPECT_EQ(action.errors.code("NO_SUCH_NAME"), action.errors.base) << "UNKNOWN";
  }
}

TEST(ActionCatalog, APlanFailureGetsTheCodeOfItsNav2Name) {
  namespace wire = node::wire;
  // A plan's failure and the nav2_msgs name the planner server gives it.
  const std::map<uint8_t, std::string> nav2_names = {
      {wire::FRAME_MISMATCH, "TF_ERROR"},           {wire::START_OUTSIDE_MAP, "START_OUTSIDE_MAP"},
      {wire::GOAL_OUTSIDE_MAP, "GOAL_OUTSIDE_MAP"}, {wire::START_OCCUPIED, "START_OCCUPIED"},
      {wire::GOAL_OCCUPIED, "GOAL_OCCUPIED"},       {wire::TIMEOUT, "TIMEOUT"},
      {wire::NO_VALID_PATH, "NO_VALID_PATH"},       {wire::NO_MAP, "UNKNOWN"},
      {wire::INVALID_REQUEST, "UNKNOWN"},           {wire::INTERNAL_ERROR, "UNKNOWN"}};
  for (const node::Nav2ActionInfo& action : node::nav2_actions()) {
    SCOPED_TRACE(action.type_name);
    std::map<std::string, uint16_t> by_name;
    for (const auto& [code, name] : documented_error_codes(action.type_name)) by_name[name] = code;
    EXPECT_EQ(node::nav2_error_code(action.kind, wire::OK, false), 0);
    EXPECT_EQ(node::nav2_error_code(action.kind, wire::NO_VALID_PATH, true),
              by_name.at("INVALID_PLANNER"));
    for (const auto& [wire_code, name] : nav2_names)
      EXPECT_EQ(node::nav2_error_code(action.kind, wire_code, false), by_name.at(name)) << name;
  }
}

}  // namespace
}  // namespace vnsba::test
