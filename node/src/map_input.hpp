// Maps: the slices from the bus, their conversion on the map thread, the active map every
// worker plans on, and the requests that came before the first map.
//
//   slice --listener--> newest-slice slot --map thread--> validate, convert, build (threshold,
//                                                          inflation, density table, a
//                                                          core::Planner per worker), swap in
//
// The listener never converts. A new map is swapped in atomically, with its planners' search
// arrays already allocated (so the first plan on it is as fast, and as quick to cancel, as the
// next); a plan in flight finishes on the map and planner it started with; a newer slice stops
// the conversion of an older one. A rejected or superseded map is reported (SUBJECT_MAP).
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "fleet.hpp"
#include "node_readers.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/node/requests.hpp"
#include "vnsba/node/slice_slot.hpp"

namespace vnsba::node {

class Answers;

// A map as the workers plan on it. The map thread builds the planners with the grid, so that
// their search arrays (both directions, tens of bytes per cell) are allocated before the map
// goes live, not in the first plan on it (about 230 ms at 4096 x 4096, which would also delay
// that plan's cancel). A plan holds its ActiveMap until it is answered: a plan in flight
// finishes on the map, and the planner, it started with.
struct ActiveMap {
  std::shared_ptr<const core::GridMap> grid;
  TimeMsg stamp;
  // One per planning worker, each used by its worker only (a Planner is not thread-safe). Null
  // only after an internal error dropped it (see PlanningWorkers); the worker then builds a
  // fresh one.
  mutable std::vector<std::unique_ptr<core::Planner>> planners;
};

class MapInput {
 public:
  using Clock = std::chrono::steady_clock;
  // A request that waited for the first map, handed on as if it came now (map thread).
  using Resubmit = std::function<void(const Robot&, Job)>;

  // `workers`: the planners to build with each map. `answers` answers the requests whose wait
  // for a first map ran out and reports rejected maps.
  MapInput(const NodeConfig& config, int workers, Answers& answers, Resubmit resubmit);
  MapInput(const MapInput&) = delete;
  MapInput& operator=(const MapInput&) = delete;

  // The slice reader: one map for every robot, under the node's namespace.
  core::Status add_reader(NodeReaders& readers);
  // The DDS topic of the slices.
  std::string topic() const;

  std::shared_ptr<const ActiveMap> current() const;
  // True once a slice has been accepted; waits up to `timeout` for one.
  bool wait_for_map(std::chrono::milliseconds timeout) const;

  // The map a request arriving now is checked against (null: none yet). Before the first map,
  // with requests.map_wait, the request waits for one instead: `job` is kept here and `waits`
  // is true; a map that comes hands it on (Resubmit), else it is answered NO_MAP.
  struct ForRequest {
    bool waits = false;
    std::shared_ptr<const ActiveMap> map;
  };
  ForRequest map_for(const Robot& robot, Job& job);
  // Takes out the requests of `robot` waiting for a first map that `match` (canceled goals).
  std::vector<Job> take_waiting(const Robot& robot, const std::function<bool(const Job&)>& match);

  void start();
  // Ends the map thread (after the readers are gone and the intake refuses requests: a map it
  // installs now hands its waiting requests on, to be answered CANCELED).
  void stop();
  // Answers every request still waiting for a first map (after stop() and the workers).
  void expire_all() { expire_waiting(/*all=*/true); }

  uint64_t accepted() const { return accepted_; }
  uint64_t rejected() const { return rejected_; }
  uint64_t superseded() const { return superseded_; }

 private:
  // Requests that came before the first map, waiting for one at most requests.map_wait; under
  // mutex_. Answered NO_MAP by the map thread when their deadline passes.
  struct WaitingForMap {
    const Robot* robot;
    Job job;
    Clock::time_point deadline;
  };

  const NodeConfig& cfg_;
  const int workers_;
  Answers& answers_;
  const Resubmit resubmit_;

  // The newest unconverted slice and the one being converted, the active map, the waiting
  // requests.
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  SliceSlot slices_;
  std::shared_ptr<const ActiveMap> active_;
  std::deque<WaitingForMap> waiting_;
  bool stopping_ = false;  // under mutex_
  std::thread thread_;

  std::atomic<uint64_t> accepted_{0}, rejected_{0}, superseded_{0};

  // The slice listener (a DDS thread): cheap, only the newest slice matters.
  void on_slice(OccupancyGridMsg&& msg);
  void loop();
  // Waits for a slice to convert (timing the waiting requests meanwhile); nullopt: stop.
  std::optional<SliceSlot::Taken> next_slice();
  // Converts one slice; returns what to report (OK when it went live).
  WireStatus convert(SliceSlot::Taken taken);
  // Builds the workers' planners of a new map; the failure, or nullopt. Sets
  // `search_state_bytes_per_worker` to the most search state one of them holds (bytes).
  std::optional<WireStatus> build_planners(ActiveMap& active,
                                           size_t& search_state_bytes_per_worker) const;
  // Swaps in a new map and hands on the requests that waited for it.
  void install(std::shared_ptr<ActiveMap> active);
  // Answers NO_MAP the requests whose map_wait has passed (all with `all`: CANCELED when
  // stopping); the map thread and stop.
  void expire_waiting(bool all);
};

}  // namespace vnsba::node
