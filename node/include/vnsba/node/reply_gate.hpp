// Answers that arrive (issue 17, item 2), without DDS. Discovery is not symmetric in time: a
// fresh client's request can reach the node before the node's status writer has matched that
// client's status reader, and a volatile reader (ROS 2's default) never sees a status written
// in between. As rmw_fastrtps does for service replies, the node holds a request's status until
// a status reader of the requesting participant (the GUID prefix of the request's writer) is
// matched, at most `reply_wait`; then it writes it anyway (a client without a status reader
// must not hold anyone up for longer).
//
// Matched is not enough for Cyclone DDS's volatile readers (issue 44). Such a reader starts
// after the last sequence number of the first heartbeat its participant accepts from our
// writer, and accepts none before it knows the writer (its proxy writer). The node often
// matches a fresh client's reader long before the client learns of our writer, so our first
// heartbeats to it are dropped; the client then requests at once (rcl_action_server_is_available
// holds). Fast DDS 2.9 sends the first sample a reader gets while the writer's history holds an
// older one behind a GAP and a heartbeat of its own that counts the sample, to the reader's
// unicast locator, and the sample itself to the locators of all the writer's readers: the
// multicast group when two or more Cyclone readers share it (Cyclone's default on a LAN; an
// exited client's readers stay matched for its lease, 10 s). Cyclone receives unicast and
// multicast on two threads: when it handles that unicast heartbeat first, the reply is skipped
// as already past (and acknowledged as received: the node never sends it again). So a reply to
// a requester this writer has not answered since its reader matched ("not synced") waits,
// besides the match, `settle` after the gate asked the caller for a heartbeat on the writer (a
// liveliness assertion: it counts nothing held), which it does once the request is held and the
// reader matched: the client knew our writer when it sent the request, and once it has handled
// a heartbeat that does not count the reply, its reader is in step with the writer and gets it.
// A reply released to a matched requester makes it synced for as long as its readers stay
// matched. The wait is per client and bounded: other clients' replies do not wait on it.
//
// Rules:
// - A status with no requester (a slice report, a goal_pose goal: rviz2 reads no status) is
//   ready at once.
// - Statuses are released in the order they were held, except that one whose requester is
//   matched does not wait behind another client's: per client the order is kept (the same
//   prefix is matched and synced for all its statuses at once, and deadlines grow with arrival).
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

// How long a reply to a requester that is not synced waits after the heartbeat asked for it
// (see above): far longer than Cyclone DDS takes to handle a heartbeat it received, also with
// both cores busy.
inline constexpr std::chrono::milliseconds kReaderSettle{20};

template <class Payload>
class ReplyGate {
 public:
  using Clock = std::chrono::steady_clock;

  explicit ReplyGate(std::chrono::milliseconds reply_wait,
                     std::chrono::milliseconds settle = std::chrono::milliseconds(0))
      : reply_wait_(reply_wait), settle_(settle) {}

  // A status reader of participant `prefix` matched (+1) or went away (-1). A participant whose
  // last reader went away is not synced any more.
  void reader_matched(const GuidPrefix& prefix, int change) {
    Peer& peer = peers_[prefix];
    peer.readers += change;
    if (peer.readers <= 0) peers_.erase(prefix);
  }
  bool matched(const GuidPrefix& prefix) const { return peers_.count(prefix) > 0; }
  // Whether a reply has gone to the participant since its reader matched.
  bool synced(const GuidPrefix& prefix) const {
    auto it = peers_.find(prefix);
    return it != peers_.end() && it->second.synced;
  }
  // Every participant with a matched reader, in order.
  std::vector<GuidPrefix> matched_participants() const {
    std::vector<GuidPrefix> out;
    for (const auto& entry : peers_) out.push_back(entry.first);
    return out;
  }

  // Holds `payload` for `requester` (none: ready at once) until it may go (see above) or
  // now + reply_wait.
  void hold(std::optional<GuidPrefix> requester, Payload payload, Clock::time_point now) {
    held_.push_back({requester, now + reply_wait_, std::move(payload)});
  }

  // Removes and returns, in order, what may be written at `now`; `timed_out` (may be null)
  // counts those released by their deadline rather than by a match. When a requester's settle
  // starts, `heartbeat` (may be null) is set: the caller sends one on the writer now. A `now` of
  // time_point::max() releases everything.
  std::vector<Payload> release(Clock::time_point now, size_t* timed_out = nullptr,
                               bool* heartbeat = nullptr) {
    std::vector<Payload> out;
    for (auto it = held_.begin(); it != held_.end();) {
      bool ready = !it->requester;
      Peer* peer = nullptr;
      if (!ready) {
        auto found = peers_.find(*it->requester);
        if (found != peers_.end()) peer = &found->second;
        if (peer != nullptr) ready = may_go(*peer, now, heartbeat);
      }
      if (ready || now >= it->deadline) {
        if (!ready && peer == nullptr && timed_out != nullptr) ++*timed_out;
        if (peer != nullptr) peer->synced = true;
        out.push_back(std::move(it->payload));
        it = held_.erase(it);
      } else {
        ++it;
      }
    }
    return out;
  }

  // The earliest deadline or end of a settle of what is held (none when nothing is).
  std::optional<Clock::time_point> next_deadline() const {
    std::optional<Clock::time_point> earliest;
    auto consider = [&](Clock::time_point t) {
      if (!earliest || t < *earliest) earliest = t;
    };
    for (const Held& h : held_) {
      consider(h.deadline);
      if (!h.requester) continue;
      auto peer = peers_.find(*h.requester);
      if (peer != peers_.end() && !peer->second.synced && peer->second.settle_from)
        consider(*peer->second.settle_from + settle_);
    }
    return earliest;
  }
  bool empty() const { return held_.empty(); }

 private:
  struct Held {
    std::optional<GuidPrefix> requester;
    Clock::time_point deadline;
    Payload payload;
  };
  struct Peer {
    int readers = 0;                               // matched readers of the participant
    bool synced = false;                           // a reply went to it since they matched
    std::optional<Clock::time_point> settle_from;  // when its heartbeat was asked for
  };

  // Whether a reply to a matched requester may go at `now`.
  bool may_go(Peer& peer, Clock::time_point now, bool* heartbeat) {
    if (peer.synced || settle_.count() == 0 || now == Clock::time_point::max()) return true;
    if (!peer.settle_from) {
      peer.settle_from = now;
      if (heartbeat != nullptr) *heartbeat = true;
    }
    return now >= *peer.settle_from + settle_;
  }

  std::chrono::milliseconds reply_wait_;
  std::chrono::milliseconds settle_;
  std::map<GuidPrefix, Peer> peers_;  // participants with a reader matched
  std::deque<Held> held_;
};

}  // namespace vnsba::node
