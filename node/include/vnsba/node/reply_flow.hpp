// When an action server may write its next reply on one reply writer (issue 44, item 3), without
// DDS.
//
// Every client's replies to one service share a DDS writer, and a reliable writer keeps a reply
// until every matched reader has acknowledged it. A keep-all writer whose history filled with
// replies one client never acknowledged (a reader that stopped taking: legal QoS, and a stopped
// process looks the same) blocked every other client's replies. The node's reply writers keep
// their last kReplyHistory replies instead (reply_writer_qos), so a write never blocks, and this
// class bounds the bytes they hold and who can lose what:
// - Replies go out as long as the bytes written since every reader last acknowledged everything
//   (the window, `budget_bytes` at most, and always at least one reply) fit; then the next waits
//   for the acknowledgements (all_acknowledged(), from DataWriter::wait_for_acknowledgments).
//   Under a burst of ten clients on two cores that took 0.2-0.75 s.
// - A window not acknowledged within `ack_timeout` means a reader that does not acknowledge. Its
//   replies' clients are reported once (stalled()), and replies go on without waiting for it:
//   when the window is full again and nothing was written for `ack_timeout` (every reader that
//   acknowledges has done so), the writer's history is cleared (kClearHistory), which drops what
//   only that reader still lacks, and the window starts afresh. So the writer holds at most
//   `budget_bytes` and one reply, a client that acknowledges within `ack_timeout` loses nothing,
//   and the others wait at most about twice `ack_timeout` per window for the one that does not.
//   Everything acknowledged ends the episode.
// DDS does not say which reader has not acknowledged: the report lists the clients of the
// replies in the window, the most replies first (a client that asks and never takes keeps adding
// its own), and the node names the participants of the writer's readers beside it.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "vnsba/node/reply_gate.hpp"

namespace vnsba::node {

class ReplyFlow {
 public:
  using Clock = std::chrono::steady_clock;
  enum class Step {
    kWrite,         // write it now
    kWait,          // not yet: next_check() says when to look again
    kClearHistory,  // clear the writer's history (history_cleared()), then write it
  };

  ReplyFlow(size_t budget_bytes, std::chrono::milliseconds ack_timeout)
      : budget_(budget_bytes), ack_timeout_(ack_timeout) {}

  // Every reply written so far has been acknowledged by every reader.
  void all_acknowledged() {
    window_bytes_ = 0;
    window_clients_.clear();
    stalled_ = false;
    reported_ = false;
  }

  // What to do with a reply of `bytes` now.
  Step next(size_t bytes, Clock::time_point now) {
    note_time(now);
    if (window_bytes_ == 0 || window_bytes_ + bytes <= budget_) return Step::kWrite;
    if (stalled_ && now - last_write_ >= ack_timeout_) return Step::kClearHistory;
    return Step::kWait;
  }
  void written(const GuidPrefix& client, size_t bytes, Clock::time_point now) {
    if (window_bytes_ == 0) window_start_ = now;
    window_bytes_ += bytes;
    last_write_ = now;
    ++window_clients_[client];
  }
  // The writer's history was cleared: the window is empty (the episode goes on until everything
  // is acknowledged).
  void history_cleared() {
    window_bytes_ = 0;
    window_clients_.clear();
  }

  // Once per episode, when the window has waited ack_timeout: the clients of its replies, each
  // with its count, the most first.
  std::optional<std::vector<std::pair<GuidPrefix, size_t>>> stalled(Clock::time_point now) {
    note_time(now);
    if (!stalled_ || reported_) return std::nullopt;
    reported_ = true;
    std::vector<std::pair<GuidPrefix, size_t>> out(window_clients_.begin(), window_clients_.end());
    std::stable_sort(out.begin(), out.end(),
                     [](const auto& a, const auto& b) { return a.second > b.second; });
    return out;
  }
  bool is_stalled() const { return stalled_; }
  // Bytes written since every reader last acknowledged everything (or the history was cleared).
  size_t unacknowledged_bytes() const { return window_bytes_; }

  // When to look at the flow again without an acknowledgement: with a reply waiting
  // (`reply_waiting`), when it may go (the window's timeout, or, a reader not acknowledging,
  // ack_timeout after the last write); with none, when a reader that does not acknowledge is to
  // be reported, once. None when nothing is in flight or nothing is left to do.
  std::optional<Clock::time_point> next_check(bool reply_waiting) const {
    if (window_bytes_ == 0) return std::nullopt;
    if (!reply_waiting) {
      if (reported_) return std::nullopt;
      return window_start_ + ack_timeout_;
    }
    return (stalled_ ? last_write_ : window_start_) + ack_timeout_;
  }

 private:
  void note_time(Clock::time_point now) {
    if (!stalled_ && window_bytes_ > 0 && now - window_start_ >= ack_timeout_) stalled_ = true;
  }

  size_t budget_;
  std::chrono::milliseconds ack_timeout_;
  size_t window_bytes_ = 0;
  std::map<GuidPrefix, size_t> window_clients_;  // replies in the window, per client
  Clock::time_point window_start_{}, last_write_{};
  bool stalled_ = false;
  bool reported_ = false;
};

}  // namespace vnsba::node
