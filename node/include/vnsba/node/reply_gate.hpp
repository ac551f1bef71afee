// Answers that arrive (issue 17, item 2), without DDS. Discovery is not symmetric in time: a
// fresh client's request can reach the node before the node's status writer has matched that
// client's status reader, and a volatile reader (ROS 2's default) never sees a status written
// in between. As rmw_fastrtps does for service replies, the node holds a request's status until
// a status reader of the requesting participant (the GUID prefix of the request's writer) is
// matched, at most `reply_wait`; then it writes it anyway (a client without a status reader
// must not hold anyone up for longer).
//
// Rules:
// - A status with no requester (a slice report, a goal_pose goal: rviz2 reads no status) is
//   ready at once.
// - Statuses are released in the order they were held, except that one whose requester is
//   matched does not wait behind another client's: per client the order is kept (the same
//   prefix is matched for all its statuses at once, and deadlines grow with arrival).
// The node calls it under its own lock from the DDS matching callbacks and the replier thread.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <vector>

namespace vnsba::node {

using GuidPrefix = std::array<uint8_t, 12>;

template <class Payload>
class ReplyGate {
 public:
  using Clock = std::chrono::steady_clock;

  explicit ReplyGate(std::chrono::milliseconds reply_wait) : reply_wait_(reply_wait) {}

  // A status reader of participant `prefix` matched (+1) or went away (-1).
  void reader_matched(const GuidPrefix& prefix, int change) {
    int& count = matched_[prefix];
    count += change;
    if (count <= 0) matched_.erase(prefix);
  }
  bool matched(const GuidPrefix& prefix) const { return matched_.count(prefix) > 0; }
  // Every participant with a matched reader, in order.
  std::vector<GuidPrefix> matched_participants() const {
    std::vector<GuidPrefix> out;
    for (const auto& entry : matched_) out.push_back(entry.first);
    return out;
  }

  // Holds `payload` for `requester` (none: ready at once) until matched or now + reply_wait.
  void hold(std::optional<GuidPrefix> requester, Payload payload, Clock::time_point now) {
    held_.push_back({requester, now + reply_wait_, std::move(payload)});
  }

  // Removes and returns, in order, what may be written at `now`; `timed_out` (may be null)
  // counts those released by their deadline rather than by a match.
  std::vector<Payload> release(Clock::time_point now, size_t* timed_out = nullptr) {
    std::vector<Payload> out;
    for (auto it = held_.begin(); it != held_.end();) {
      const bool ready = !it->requester || matched(*it->requester);
      if (ready || now >= it->deadline) {
        if (!ready && timed_out != nullptr) ++*timed_out;
        out.push_back(std::move(it->payload));
        it = held_.erase(it);
      } else {
        ++it;
      }
    }
    return out;
  }

  // The earliest deadline of what is held (none when nothing is).
  std::optional<Clock::time_point> next_deadline() const {
    std::optional<Clock::time_point> earliest;
    for (const Held& h : held_)
      if (!earliest || h.deadline < *earliest) earliest = h.deadline;
    return earliest;
  }
  bool empty() const { return held_.empty(); }

 private:
  struct Held {
    std::optional<GuidPrefix> requester;
    Clock::time_point deadline;
    Payload payload;
  };
  std::chrono::milliseconds reply_wait_;
  std::map<GuidPrefix, int> matched_;  // status readers matched, per remote participant
  std::deque<Held> held_;
};

}  // namespace vnsba::node
