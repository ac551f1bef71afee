// ReplyGate (reply_gate.hpp) without DDS: statuses wait for their requester's status reader, at
// most reply_wait, and are released in order per client.
#include <gtest/gtest.h>

#include <string>
#include <vector>

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

}  // namespace
}  // namespace vnsba::test
