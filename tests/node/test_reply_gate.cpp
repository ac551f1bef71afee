// ReplyGate (reply_gate.hpp) without DDS: statuses wait for their requester's status reader, at
// most reply_wait, and are released in order per client; with a settle, the first reply to a
// client also waits that long after a heartbeat the gate asks for (issue 44).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "vnsba/node/reply_flow.hpp"
#include "vnsba/node/reply_gate.hpp"

namespace vnsba::test {
namespace {

using node::GuidPrefix;
using Gate = node::ReplyGate<std::string>;
using namespace std::chrono_literals;

GuidPrefix client(uint8_t n) {
  GuidPrefix p{};
  p[0] = n;
  return p;
}

TEST(ReplyGate, AStatusWithoutARequesterIsReadyAtOnce) {
  Gate gate(2000ms);
  const auto t0 = Gate::Clock::now();
  gate.hold(std::nullopt, "map report", t0);
  EXPECT_EQ(gate.release(t0), std::vector<std::string>{"map report"});
  EXPECT_TRUE(gate.empty());
}

TEST(ReplyGate, AStatusWaitsForItsRequestersReaderThenGoes) {
  Gate gate(2000ms);
  const auto t0 = Gate::Clock::now();
  gate.hold(client(1), "answer", t0);
  EXPECT_TRUE(gate.release(t0 + 1999ms).empty());
  gate.reader_matched(client(2), +1);  // someone else's reader does not release it
  EXPECT_TRUE(gate.release(t0 + 1999ms).empty());
  gate.reader_matched(client(1), +1);
  size_t timed_out = 0;
  EXPECT_EQ(gate.release(t0 + 1ms, &timed_out), std::vector<std::string>{"answer"});
  EXPECT_EQ(timed_out, 0u);
}

TEST(ReplyGate, AtItsDeadlineAStatusGoesAnywayAndIsCounted) {
  Gate gate(500ms);
  const auto t0 = Gate::Clock::now();
  gate.hold(client(1), "answer", t0);
  EXPECT_EQ(gate.next_deadline(), t0 + 500ms);
  size_t timed_out = 0;
  EXPECT_TRUE(gate.release(t0 + 499ms, &timed_out).empty());
  EXPECT_EQ(gate.release(t0 + 500ms, &timed_out), std::vector<std::string>{"answer"});
  EXPECT_EQ(timed_out, 1u);
  EXPECT_FALSE(gate.next_deadline().has_value());
}

TEST(ReplyGate, ZeroWaitNeverHolds) {
  Gate gate(0ms);
  const auto t0 = Gate::Clock::now();
  gate.hold(client(1), "answer", t0);
  EXPECT_EQ(gate.release(t0), std::vector<std::string>{"answer"});
}

TEST(ReplyGate, AMatchedClientDoesNotWaitBehindAnotherAndEachClientKeepsItsOrder) {
  Gate gate(2000ms);
  const auto t0 = Gate::Clock::now();
  gate.hold(client(1), "a1", t0);
  gate.hold(client(2), "b1", t0 + 1ms);
  gate.hold(client(1), "a2", t0 + 2ms);
  gate.hold(client(2), "b2", t0 + 3ms);
  gate.reader_matched(client(2), +1);
  EXPECT_EQ(gate.release(t0 + 4ms), (std::vector<std::string>{"b1", "b2"}));
  gate.reader_matched(client(1), +1);
  EXPECT_EQ(gate.release(t0 + 5ms), (std::vector<std::string>{"a1", "a2"}));
}

TEST(ReplyGate, AReaderThatWentAwayNoLongerReleases) {
  Gate gate(2000ms);
  const auto t0 = Gate::Clock::now();
  gate.reader_matched(client(1), +1);
  gate.reader_matched(client(1), +1);  // two status readers in one participant
  gate.reader_matched(client(1), -1);
  EXPECT_TRUE(gate.matched(client(1)));
  gate.reader_matched(client(1), -1);
  EXPECT_FALSE(gate.matched(client(1)));
  gate.hold(client(1), "answer", t0);
  EXPECT_TRUE(gate.release(t0 + 1ms).empty());
}

// Issue 44: the first reply to a matched client goes a settle after the heartbeat the gate asks
// for, which a Cyclone DDS reader must handle before the reply's own heartbeat.
TEST(ReplyGate, TheFirstReplyToAClientGoesASettleAfterTheHeartbeatItAsksFor) {
  Gate gate(2000ms, 20ms);
  const auto t0 = Gate::Clock::now();
  gate.reader_matched(client(1), +1);
  gate.hold(client(1), "accepted", t0);
  bool heartbeat = false;
  EXPECT_TRUE(gate.release(t0 + 1ms, nullptr, &heartbeat).empty());
  EXPECT_TRUE(heartbeat);  // sent now: the settle counts from here
  EXPECT_EQ(gate.next_deadline(), t0 + 21ms);
  heartbeat = false;
  EXPECT_TRUE(gate.release(t0 + 20ms, nullptr, &heartbeat).empty());
  EXPECT_FALSE(heartbeat);  // asked for once
  EXPECT_FALSE(gate.synced(client(1)));
  size_t timed_out = 0;
  EXPECT_EQ(gate.release(t0 + 21ms, &timed_out, &heartbeat), std::vector<std::string>{"accepted"});
  EXPECT_EQ(timed_out, 0u);
  EXPECT_TRUE(gate.synced(client(1)));
  // In step now: its next replies go at once, without a heartbeat of their own.
  gate.hold(client(1), "result", t0 + 30ms);
  EXPECT_EQ(gate.release(t0 + 30ms, nullptr, &heartbeat), std::vector<std::string>{"result"});
  EXPECT_FALSE(heartbeat);
}

TEST(ReplyGate, TheSettleStartsOnceTheRequestersReaderIsMatched) {
  Gate gate(2000ms, 20ms);
  const auto t0 = Gate::Clock::now();
  gate.hold(client(1), "accepted", t0);
  bool heartbeat = false;
  EXPECT_TRUE(gate.release(t0 + 100ms, nullptr, &heartbeat).empty());
  EXPECT_FALSE(heartbeat);  // nothing to send it to yet
  gate.reader_matched(client(1), +1);
  EXPECT_TRUE(gate.release(t0 + 150ms, nullptr, &heartbeat).empty());
  EXPECT_TRUE(heartbeat);
  EXPECT_EQ(gate.release(t0 + 170ms), std::vector<std::string>{"accepted"});
}

TEST(ReplyGate, ASettlingClientHoldsUpNoOtherClient) {
  Gate gate(2000ms, 20ms);
  const auto t0 = Gate::Clock::now();
  gate.reader_matched(client(1), +1);
  gate.reader_matched(client(2), +1);
  gate.hold(client(2), "b1", t0);
  bool heartbeat = false;
  EXPECT_TRUE(gate.release(t0, nullptr, &heartbeat).empty());
  EXPECT_EQ(gate.release(t0 + 20ms), std::vector<std::string>{"b1"});  // client 2 is synced
  gate.hold(client(1), "a1", t0 + 21ms);
  gate.hold(client(2), "b2", t0 + 22ms);
  gate.hold(std::nullopt, "map report", t0 + 23ms);
  heartbeat = false;
  EXPECT_EQ(gate.release(t0 + 23ms, nullptr, &heartbeat),
            (std::vector<std::string>{"b2", "map report"}));
  EXPECT_TRUE(heartbeat);  // client 1's settle starts
  gate.hold(client(1), "a2", t0 + 30ms);
  EXPECT_TRUE(gate.release(t0 + 42ms).empty());
  EXPECT_EQ(gate.release(t0 + 43ms), (std::vector<std::string>{"a1", "a2"}));  // in order
}

TEST(ReplyGate, AClientWhoseReadersWentAwaySettlesAgain) {
  Gate gate(2000ms, 20ms);
  const auto t0 = Gate::Clock::now();
  gate.reader_matched(client(1), +1);
  gate.hold(client(1), "a1", t0);
  gate.release(t0);
  EXPECT_EQ(gate.release(t0 + 20ms), std::vector<std::string>{"a1"});
  EXPECT_TRUE(gate.synced(client(1)));
  gate.reader_matched(client(1), -1);
  gate.reader_matched(client(1), +1);  // a new reader: it has heard no heartbeat of ours
  EXPECT_FALSE(gate.synced(client(1)));
  gate.hold(client(1), "a2", t0 + 30ms);
  bool heartbeat = false;
  EXPECT_TRUE(gate.release(t0 + 30ms, nullptr, &heartbeat).empty());
  EXPECT_TRUE(heartbeat);
  EXPECT_EQ(gate.release(t0 + 50ms), std::vector<std::string>{"a2"});
}

TEST(ReplyGate, AShutdownReleasesASettlingReplyAtOnce) {
  Gate gate(2000ms, 20ms);
  const auto t0 = Gate::Clock::now();
  gate.reader_matched(client(1), +1);
  gate.hold(client(1), "accepted", t0);
  gate.hold(client(2), "unmatched", t0);
  size_t timed_out = 0;
  EXPECT_EQ(gate.release(Gate::Clock::time_point::max(), &timed_out),
            (std::vector<std::string>{"accepted", "unmatched"}));
  EXPECT_EQ(timed_out, 1u);  // only the one without a matched reader
}

}  // namespace
}  // namespace vnsba::test

// ReplyFlow (reply_flow.hpp): when an action server may write its next reply on a writer whose
// unacknowledged replies may hold at most a budget of bytes.
namespace vnsba::test {
namespace {

using node::ReplyFlow;
using Step = ReplyFlow::Step;

// Replies go while the bytes not yet acknowledged fit the budget (one always goes); an
// acknowledgement of everything empties the window.
TEST(ReplyFlow, RepliesGoWhileTheUnacknowledgedBytesFitTheBudget) {
  ReplyFlow flow(1000, 2000ms);
  const auto t0 = ReplyFlow::Clock::now();
  EXPECT_EQ(flow.next(5000, t0), Step::kWrite) << "one reply always goes, whatever its size";
  flow.written(client(1), 5000, t0);
  EXPECT_EQ(flow.next(1, t0), Step::kWait);
  flow.all_acknowledged();
  for (int i = 0; i < 4; ++i) {
    ASSERT_EQ(flow.next(250, t0), Step::kWrite) << i;
    flow.written(client(1), 250, t0);
  }
  EXPECT_EQ(flow.unacknowledged_bytes(), 1000u);
  EXPECT_EQ(flow.next(1, t0 + 1999ms), Step::kWait);
  ASSERT_TRUE(flow.next_check(true).has_value());
  EXPECT_EQ(*flow.next_check(true), t0 + 2000ms);
  EXPECT_EQ(*flow.next_check(false), t0 + 2000ms) << "when it would be reported";
  flow.all_acknowledged();
  EXPECT_EQ(flow.next(1000, t0 + 1999ms), Step::kWrite);
  EXPECT_FALSE(flow.is_stalled());
  EXPECT_FALSE(flow.stalled(t0 + 1h).has_value()) << "nothing in flight: nothing stalled";
  EXPECT_FALSE(flow.next_check(true).has_value());
}

// A window not acknowledged within ack_timeout is a reader that does not acknowledge: reported
// once, with the clients of its replies (most first). Writes go on while the window has room;
// once it is full, and nothing was written for ack_timeout (every reader that acknowledges has),
// the history is cleared and the window starts afresh. Everything acknowledged ends the episode.
TEST(ReplyFlow, AReaderThatDoesNotAcknowledgeDelaysTheOthersBoundedly) {
  ReplyFlow flow(100, 500ms);
  const auto t0 = ReplyFlow::Clock::now();
  for (int i = 0; i < 3; ++i) flow.written(client(7), 30, t0);
  flow.written(client(2), 10, t0);
  EXPECT_EQ(flow.next(10, t0 + 499ms), Step::kWait);
  EXPECT_FALSE(flow.stalled(t0 + 499ms).has_value());
  EXPECT_EQ(flow.next(10, t0 + 500ms), Step::kClearHistory)
      << "stalled, full, and nothing written for ack_timeout";
  EXPECT_TRUE(flow.is_stalled());
  const auto report = flow.stalled(t0 + 500ms);
  ASSERT_TRUE(report.has_value());
  ASSERT_EQ(report->size(), 2u);
  EXPECT_EQ((*report)[0], std::make_pair(client(7), size_t{3}));
  EXPECT_EQ((*report)[1], std::make_pair(client(2), size_t{1}));
  EXPECT_FALSE(flow.stalled(t0 + 600ms).has_value()) << "reported once per episode";
  EXPECT_FALSE(flow.next_check(false).has_value()) << "reported, nothing waits: nothing to do";
  flow.history_cleared();
  EXPECT_EQ(flow.unacknowledged_bytes(), 0u);
  // Still stalled: the window fills again, then waits ack_timeout after its last write.
  const auto t1 = t0 + 600ms;
  for (int i = 0; i < 10; ++i) {
    ASSERT_EQ(flow.next(10, t1), Step::kWrite) << i;
    flow.written(client(2), 10, t1);
  }
  EXPECT_EQ(flow.next(10, t1 + 499ms), Step::kWait);
  EXPECT_EQ(*flow.next_check(true), t1 + 500ms);
  EXPECT_EQ(flow.next(10, t1 + 500ms), Step::kClearHistory);
  flow.all_acknowledged();
  EXPECT_FALSE(flow.is_stalled());
  flow.written(client(2), 100, t1 + 600ms);
  EXPECT_EQ(flow.next(1, t1 + 600ms + 499ms), Step::kWait) << "a new episode waits afresh";
  EXPECT_FALSE(flow.stalled(t1 + 600ms + 499ms).has_value());
}

}  // namespace
}  // namespace vnsba::test
