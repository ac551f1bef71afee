// The map thread's intake, without DDS: the newest slice not yet converted, and the cancel flag
// of the one being converted. A newer slice supersedes both: the waiting one is replaced, and
// the conversion in progress is told to stop (GridMap::build polls the flag), so a valid map
// never waits behind an older one. But a conversion that follows kMaxSupersededInARow stopped
// ones is let finish: slices arriving faster than a map converts must not keep every map from
// going live. Not thread-safe: the node holds its map lock.
#pragma once

#include <atomic>
#include <memory>
#include <optional>
#include <utility>

#include "vnsba/node/convert.hpp"

namespace vnsba::node {

class SliceSlot {
 public:
  static constexpr int kMaxSupersededInARow = 2;

  struct Taken {
    OccupancyGridMsg slice;
    std::shared_ptr<const std::atomic<bool>> superseded;  // raised by a newer put()
  };
  struct PutResult {
    bool replaced_waiting = false;       // an unconverted slice was dropped for this one
    bool superseded_converting = false;  // the conversion in progress was told to stop
  };

  PutResult put(OccupancyGridMsg&& slice) {
    PutResult result;
    result.replaced_waiting = waiting_.has_value();
    waiting_ = std::move(slice);
    if (converting_ && superseded_in_a_row_ < kMaxSupersededInARow &&
        !converting_->exchange(true)) {
      result.superseded_converting = true;
      ++superseded_in_a_row_;
    }
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

  // The slice taken last is converted: `finished` when it was accepted or rejected, false when
  // it stopped because a newer one superseded it.
  void finish(bool finished) {
    converting_.reset();
    if (finished) superseded_in_a_row_ = 0;
  }

 private:
  std::optional<OccupancyGridMsg> waiting_;
  std::shared_ptr<std::atomic<bool>> converting_;
  int superseded_in_a_row_ = 0;
};

}  // namespace vnsba::node
