// The runs the recorder has heard of but not written yet (a request or a status or debug data
// came, the rest may still come), bounded in count and in bytes: a recorder may run for days next
// to a busy node, and one debug message of a large map holds megabytes of cells.
//
// No DDS here, so the accounting is tested alone. Bytes are counted as what a run's record holds
// (its object, the capacity of its strings and cell/point lists); the map entry's own overhead is
// a fixed amount a run.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "vnsba/records/run_record.hpp"

namespace vnsba::records {

// The bytes of a list's elements (its capacity).
template <class T>
size_t list_bytes(const std::vector<T>& list) {
  return list.capacity() * sizeof(T);
}

// The bytes debug data holds beyond its object: its planner's name and its lists.
inline size_t debug_bytes(const DebugRecord& d) {
  return d.planner.capacity() + list_bytes(d.expanded_forward) + list_bytes(d.expanded_backward) +
         list_bytes(d.raw_path) + list_bytes(d.pruned_waypoints);
}

// The bytes `record` holds, about: the objects and the capacity of their strings and lists.
inline size_t record_bytes(const RunRecord& r) {
  size_t n = sizeof(RunRecord) + r.request_id.capacity() + list_bytes(r.path);
  if (r.request) n += r.request->source.capacity() + r.request->planner.capacity();
  if (r.status)
    n += r.status->code_name.capacity() + r.status->message.capacity() +
         r.status->planner.capacity();
  if (r.debug) n += debug_bytes(*r.debug);
  if (r.map) n += r.map->file.capacity() + r.map->frame_id.capacity();
  return n;
}

struct OpenRun {
  RunRecord record;
  std::optional<std::chrono::steady_clock::time_point> status_time;  // when its status came
  uint64_t opened = 0;  // order of arrival: the oldest runs are dropped first
  size_t bytes = 0;     // record_bytes(record) plus the entry's overhead
};

// Something dropped to stay within the limits.
struct DroppedPart {
  std::string request_id;
  size_t bytes = 0;        // what it held
  bool whole_run = false;  // the run itself; otherwise only its debug data
  std::string reason;      // "more than N open runs", "open runs over N bytes"
};

struct DropTotals {
  size_t runs = 0;   // whole runs dropped
  size_t debug = 0;  // runs whose debug data was dropped
  uint64_t bytes = 0;
};

class OpenRuns {
 public:
  // A fixed amount a run for the map entry, its key and allocator headers.
  static constexpr size_t kEntryOverhead = 96;

  OpenRuns(size_t max_runs, size_t max_bytes) : max_runs_(max_runs), max_bytes_(max_bytes) {}

  // Applies `change` to the run of `id` (a new, empty one when none is open), then keeps the
  // limits: past max_runs the oldest other run is dropped; past max_bytes the debug data of the
  // open runs is dropped, oldest first and this run's last, then (if debug was not enough) whole
  // runs, oldest first. Returns what was dropped, in order.
  std::vector<DroppedPart> update(const std::string& id,
                                  const std::function<void(OpenRun&)>& change) {
    std::vector<DroppedPart> dropped;
    auto it = runs_.find(id);
    if (it == runs_.end()) {
      while (!runs_.empty() && runs_.size() >= max_runs_)
        drop_run(oldest_except(""), "more than " + std::to_string(max_runs_) + " open runs",
                 dropped);
      it = runs_.emplace(id, OpenRun{}).first;
      it->second.record.request_id = id;
      it->second.opened = ++opened_;
      it->second.bytes = count(it->second);
      bytes_ += it->second.bytes;
    }
    change(it->second);
    recount(it->second);
    const std::string reason = "open runs over " + std::to_string(max_bytes_) + " bytes";
    while (bytes_ > max_bytes_) {
      auto victim = oldest_with_debug(id);
      if (victim == runs_.end() && it->second.record.debug) victim = it;
      if (victim != runs_.end()) {
        DroppedPart part{victim->first, 0, false, reason};
        const size_t before = victim->second.bytes;
        victim->second.record.debug.reset();
        recount(victim->second);
        part.bytes = before - victim->second.bytes;
        totals_.debug += 1;
        totals_.bytes += part.bytes;
        dropped.push_back(std::move(part));
        continue;
      }
      auto run = oldest_except(id);
      if (run == runs_.end()) run = it;
      const bool last = run == it;
      drop_run(run, reason, dropped);
      if (last) break;
    }
    return dropped;
  }

  // The open run of `id`, or nullptr.
  const OpenRun* find(const std::string& id) const {
    const auto it = runs_.find(id);
    return it == runs_.end() ? nullptr : &it->second;
  }

  // The id of the oldest open run for which `match` holds.
  std::optional<std::string> oldest(
      const std::function<bool(const std::string&, const OpenRun&)>& match) const {
    const auto best = oldest_in(runs_.begin(), runs_.end(), [&](const Map::value_type& entry) {
      return match(entry.first, entry.second);
    });
    if (best == runs_.end()) return std::nullopt;
    return best->first;
  }

  // Removes the runs for which `ready` holds and returns them, in id order.
  std::vector<OpenRun> take(const std::function<bool(const OpenRun&)>& ready) {
    std::vector<OpenRun> out;
    for (auto it = runs_.begin(); it != runs_.end();) {
      if (!ready(it->second)) {
        ++it;
        continue;
      }
      bytes_ -= it->second.bytes;
      out.push_back(std::move(it->second));
      it = runs_.erase(it);
    }
    return out;
  }

  size_t size() const { return runs_.size(); }
  size_t bytes() const { return bytes_; }
  size_t max_bytes() const { return max_bytes_; }
  size_t max_runs() const { return max_runs_; }
  const DropTotals& dropped() const { return totals_; }

 private:
  using Map = std::map<std::string, OpenRun>;

  // The record, the map's copy of the id (its key) and the entry.
  static size_t count(const OpenRun& run) {
    return record_bytes(run.record) + run.record.request_id.capacity() + kEntryOverhead;
  }
  void recount(OpenRun& run) {
    bytes_ -= run.bytes;
    run.bytes = count(run);
    bytes_ += run.bytes;
  }
  // The entry in [begin, end) opened first for which `match` holds, else `end`.
  template <class It, class Match>
  static It oldest_in(It begin, It end, Match match) {
    It best = end;
    for (It it = begin; it != end; ++it)
      if (match(*it) && (best == end || it->second.opened < best->second.opened)) best = it;
    return best;
  }
  Map::iterator oldest_except(const std::string& id) {
    return oldest_in(runs_.begin(), runs_.end(),
                     [&](const Map::value_type& entry) { return entry.first != id; });
  }
  Map::iterator oldest_with_debug(const std::string& id) {
    return oldest_in(runs_.begin(), runs_.end(), [&](const Map::value_type& entry) {
      return entry.first != id && entry.second.record.debug.has_value();
    });
  }
  void drop_run(Map::iterator run, const std::string& reason, std::vector<DroppedPart>& dropped) {
    dropped.push_back({run->first, run->second.bytes, true, reason});
    totals_.runs += 1;
    totals_.bytes += run->second.bytes;
    bytes_ -= run->second.bytes;
    runs_.erase(run);
  }

  size_t max_runs_;
  size_t max_bytes_;
  Map runs_;
  uint64_t opened_ = 0;
  size_t bytes_ = 0;
  DropTotals totals_;
};

}  // namespace vnsba::records
