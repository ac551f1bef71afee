#include "map_input.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <utility>

#include "answers.hpp"
#include "nav_msgs/msg/OccupancyGridPubSubTypes.h"

namespace vnsba::node {

namespace {

// Bytes as MiB (2^20 bytes), the unit of every memory figure the node logs.
double mib(size_t bytes) {
  return static_cast<double>(bytes) / double(size_t{1} << 20);
}

}  // namespace

MapInput::MapInput(const NodeConfig& config, int workers, Answers& answers, Resubmit resubmit)
    : cfg_(config), workers_(workers), answers_(answers), resubmit_(std::move(resubmit)) {}

std::string MapInput::topic() const {
  return dds_topic_name(cfg_, cfg_.topics.projected_map);
}

core::Status MapInput::add_reader(NodeReaders& readers) {
  dds::DataReaderQos slice_qos = reader_qos(TopicQos::kLatched);
  if (cfg_.map_durability == MapDurability::kVolatile)
    slice_qos.durability().kind = dds::VOLATILE_DURABILITY_QOS;
  return readers.add<nav_msgs::msg::dds_::OccupancyGrid_PubSubType>(
      topic(), slice_qos,
      make_listener<OccupancyGridMsg>(
          [this](OccupancyGridMsg&& m, const dds::SampleInfo&) { on_slice(std::move(m)); }));
}

std::shared_ptr<const ActiveMap> MapInput::current() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return active_;
}

bool MapInput::wait_for_map(std::chrono::milliseconds timeout) const {
  std::unique_lock<std::mutex> lock(mutex_);
  return changed_.wait_for(lock, timeout, [&] { return active_ != nullptr; });
}

MapInput::ForRequest MapInput::map_for(const Robot& robot, Job& job) {
  ForRequest out;
  out.map = current();
  // Before the first map, a request waits for one (requests.map_wait): a client that latches its
  // map and asks at once must not lose the race to its own map.
  if (out.map || cfg_.map_wait.count() <= 0) return out;
  std::unique_lock<std::mutex> lock(mutex_);
  if (active_) {
    out.map = active_;  // arrived meanwhile
    return out;
  }
  if (waiting_.empty()) {
    spdlog::info("request '{}'{}: no map yet; waiting up to requests.map_wait ({:g} s)",
                 printable(job.id), robot.label(),
                 static_cast<double>(cfg_.map_wait.count()) / 1000.0);
  }
  waiting_.push_back({&robot, std::move(job), Clock::now() + cfg_.map_wait});
  lock.unlock();
  changed_.notify_all();  // the map thread times the wait
  out.waits = true;
  return out;
}

std::vector<Job> MapInput::take_waiting(const Robot& robot,
                                        const std::function<bool(const Job&)>& match) {
  std::vector<Job> removed;
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto it = waiting_.begin(); it != waiting_.end();) {
    if (it->robot == &robot && match(it->job)) {
      removed.push_back(std::move(it->job));
      it = waiting_.erase(it);
    } else {
      ++it;
    }
  }
  return removed;
}

void MapInput::on_slice(OccupancyGridMsg&& msg) {
  SliceSlot::PutResult put;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    put = slices_.put(std::move(msg));  // only the newest slice matters
  }
  if (put.superseded_converting)
    spdlog::info("a newer slice arrived: the conversion in progress stops");
  changed_.notify_all();
}

void MapInput::start() {
  thread_ = std::thread([this] { loop(); });
}

void MapInput::stop() {
  {
    // Under the lock, so that the map thread cannot miss it between its check and its wait.
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void MapInput::expire_waiting(bool all) {
  std::vector<WaitingForMap> expired;
  bool stopping = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping = stopping_;
    const Clock::time_point now = Clock::now();
    while (!waiting_.empty() && (all || waiting_.front().deadline <= now)) {
      expired.push_back(std::move(waiting_.front()));
      waiting_.pop_front();
    }
  }
  for (WaitingForMap& waiting : expired) {
    const std::string why =
        all && stopping ? "node is shutting down before a map arrived"
                        : fmt::format("no map received within requests.map_wait ({:g} s) on '{}'",
                                      static_cast<double>(cfg_.map_wait.count()) / 1000.0, topic());
    const WireStatus status{all && stopping ? wire::CANCELED : wire::NO_MAP, why};
    spdlog::warn("request '{}'{}: {} ({})", printable(waiting.job.id), waiting.robot->label(),
                 code_name(status.code), status.message);
    answers_.answer(*waiting.robot, waiting.job, status);
  }
}

std::optional<SliceSlot::Taken> MapInput::next_slice() {
  std::unique_lock<std::mutex> lock(mutex_);
  auto has_work = [&] { return stopping_ || slices_.has_waiting(); };
  for (;;) {
    // Requests waiting for a first map are answered NO_MAP when their wait is over.
    while (!has_work() && !waiting_.empty()) {
      if (changed_.wait_until(lock, waiting_.front().deadline, has_work)) break;
      lock.unlock();
      expire_waiting(/*all=*/false);
      lock.lock();
    }
    changed_.wait(lock, [&] { return has_work() || !waiting_.empty(); });
    if (stopping_) return std::nullopt;
    if (slices_.has_waiting()) return slices_.take();
    // A request came to wait for a map: time it.
  }
}

void MapInput::loop() {
  while (std::optional<SliceSlot::Taken> taken = next_slice()) {
    const TimeMsg stamp = taken->slice.header().stamp();
    WireStatus status;
    try {
      status = convert(std::move(*taken));
    } catch (const std::exception& e) {
      // Resource exhaustion, never bad input (that is refused before any allocation): refuse
      // this map, keep planning on the last one, and keep the thread alive.
      status = {wire::INTERNAL_ERROR, std::string("cannot convert the slice: ") + e.what()};
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      slices_.finish(status.code != wire::CANCELED);
    }
    if (status.ok()) continue;
    if (status.code == wire::CANCELED) {
      ++superseded_;
      spdlog::info("slice superseded by a newer one before its conversion finished");
    } else {
      ++rejected_;
      spdlog::error("map rejected ({}): {}; keeping the previous map", code_name(status.code),
                    status.message);
    }
    // A report on the status topic (SUBJECT_MAP), so tools on the bus see it too.
    answers_.report_map(status, stamp);
  }
}

WireStatus MapInput::convert(SliceSlot::Taken taken) {
  const auto t0 = Clock::now();
  const std::atomic<bool>* superseded = taken.superseded.get();
  const TimeMsg stamp = taken.slice.header().stamp();
  // Every check that bounds the conversion's cost (size against map.max_cells and
  // map.memory_budget_mb, robot_radius against the map) comes before any allocation; the
  // conversion is then linear in the cells. The slice's values are moved, never copied: from the
  // DDS sample into the slot, into check.grid, which the build reads.
  SliceCheck check = from_slice_msg(std::move(taken.slice), cfg_.frame_id, cfg_.map.max_cells);
  if (!check.status.ok()) return check.status;
  const core::GridBuildOptions options = planning_grid_options(cfg_);
  if (WireStatus over_budget = check_memory_budget(check.grid.width, check.grid.height, options,
                                                   cfg_.map_memory_budget_mb);
      !over_budget.ok())
    return over_budget;
  auto built = core::GridMap::build(check.grid, options, superseded);
  if (!built) {
    return {to_wire_code(built.error().code),
            built.error().code == core::StatusCode::kCanceled
                ? "superseded by a newer slice while being converted"
                : built.error().message};
  }
  check.grid = core::OccupancyGrid();  // the raw values are not needed any more
  auto active = std::make_shared<ActiveMap>();
  active->grid = std::make_shared<const core::GridMap>(std::move(built).value());
  active->stamp = stamp;
  if (superseded->load())
    return {wire::CANCELED, "superseded by a newer slice while being converted"};
  size_t search_state_bytes_per_worker = 0;
  if (std::optional<WireStatus> failure = build_planners(*active, search_state_bytes_per_worker))
    return *failure;
  // What the configured planner reads of the map beyond its cells (VNS-BA*'s obstacle density),
  // built before the map goes live so that no query pays for it; a request naming another
  // planner that reads it builds it at its first query.
  if (!active->planners.empty()) active->planners.front()->prepare(cfg_.planner.options());
  const auto ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  // The figures docs/node.md ("Memory") names: the map (GridMap::bytes) and the search state a
  // worker holds now (its planner's search_state_bytes, the largest of the workers).
  spdlog::info(
      "map accepted: {} x {} cells at {} m, {} blocked, map memory {:.1f} MiB, search state "
      "{:.1f} MiB per worker ({} worker(s)), ready in {:.1f} ms",
      active->grid->width(), active->grid->height(), active->grid->resolution(),
      active->grid->blocked_count(), mib(active->grid->bytes()), mib(search_state_bytes_per_worker),
      workers_, ms);
  install(std::move(active));
  return {};
}

std::optional<WireStatus> MapInput::build_planners(ActiveMap& active,
                                                   size_t& search_state_bytes_per_worker) const {
  try {
    for (int w = 0; w < workers_; ++w) {  // see ActiveMap
      active.planners.push_back(std::make_unique<core::Planner>(active.grid));
      search_state_bytes_per_worker =
          std::max(search_state_bytes_per_worker, active.planners.back()->search_state_bytes());
    }
  } catch (const std::exception& e) {
    return WireStatus{
        wire::INTERNAL_ERROR,
        "cannot allocate the search state of " + std::to_string(active.grid->width()) + " x " +
            std::to_string(active.grid->height()) + " cells for " + std::to_string(workers_) +
            " planning worker(s) (requests.workers): " + e.what()};
  }
  return std::nullopt;
}

void MapInput::install(std::shared_ptr<ActiveMap> active) {
  std::shared_ptr<const ActiveMap> previous;
  std::deque<WaitingForMap> waited;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    previous = std::exchange(active_, std::move(active));
    waited.swap(waiting_);
  }
  changed_.notify_all();
  ++accepted_;
  // The requests that waited for a first map, in arrival order, as if they came now.
  for (WaitingForMap& w : waited) resubmit_(*w.robot, std::move(w.job));
  // The previous map and its planner go here, outside the lock, unless a plan still holds
  // them (then when that plan is answered).
  previous.reset();
}

}  // namespace vnsba::node
