// The map thread's intake, without DDS: the newest slice not yet converted, and the cancel flag
// of the one being converted. A newer slice supersedes both: the waiting one is replaced, and
// the conversion in progress is told to stop (GridMap::build polls the flag), so a valid map
// never waits behind an older one. Not thread-safe: the node holds its map lock.
#pragma once

#include <atomic>
#include <memory>
#include <optional>
#include <utility>

#include "vnsba/node/convert.hpp"

namespace vnsba::node {

class SliceSlot {
 public:
  struct Taken {
    OccupancyGridMsg slice;
    std::shared_ptr<const std::atomic<bool>> superseded;  // raised by a newer put()
  };
  struct PutResult {
    bool replaced_waiting = false;      // an unconverted slice was dropped for this one
    bool superseded_converting = false;  // the conversion in progress was told to stop
  };

  PutResult put(OccupancyGridMsg&& slice) {
    PutResult result;
    result.replaced_waiting = waiting_.has_value();
    waiting_ = std::move(slice);
    if (converting_ && !converting_->exchange(true)) result.superseded_converting = true;
    return result;
  }

  bool has_waiting() const { return waiting_.has_value(); }

  // The waiting slice, now the one being converted; nullopt when none waits.
  std::optional<Taken> take() {
    if (!waiting_) return std::nullopt;
    converting_ = std::make_shared<std::atomic<bool>>(false);
    Taken taken{std::move(*waiting_), converting_};
    waiting_.reset();
    return taken;
  }

  // The slice taken last is converted (accepted, rejected or superseded).
  void finish() { converting_.reset(); }

 private:
  std::optional<OccupancyGridMsg> waiting_;
  std::shared_ptr<std::atomic<bool>> converting_;
};

}  // namespace vnsba::node
