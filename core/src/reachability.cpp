#include "reachability.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "vnsba/core/motion_validator.hpp"
#include "vnsba/core/neighborhood.hpp"

namespace vnsba::core::detail {

NearestFreeCells::NearestFreeCells(const GridMap& map, const Point2& point, double radius_cells)
    : map_(map), point_(point) {
  if (!(radius_cells > 0.0) || !point.allFinite()) return;
  radius_squared_ = radius_cells * radius_cells;
  // Centres within the radius lie in cells whose indices are within this box (compared in
  // doubles first: a point far outside the map has indices beyond int32).
  const double x0 = std::floor(point.x() - radius_cells), x1 = std::ceil(point.x() + radius_cells);
  const double y0 = std::floor(point.y() - radius_cells), y1 = std::ceil(point.y() + radius_cells);
  if (x1 < 0 || y1 < 0 || x0 >= map.width() || y0 >= map.height()) return;
  xa_ = static_cast<int32_t>(std::max(x0, 0.0));
  xb_ = static_cast<int32_t>(std::min(x1, map.width() - 1.0));
  ya_ = static_cast<int32_t>(std::max(y0, 0.0));
  yb_ = static_cast<int32_t>(std::min(y1, map.height() - 1.0));
  // The rings' centre: the point's own cell, or the box's cell nearest to it when it lies outside.
  auto clamped = [](double v, int32_t lo, int32_t hi) {
    return static_cast<int32_t>(std::clamp(v, static_cast<double>(lo), static_cast<double>(hi)));
  };
  centre_ = {clamped(std::floor(point.x()), xa_, xb_), clamped(std::floor(point.y()), ya_, yb_)};
  rings_done_ = false;
}

void NearestFreeCells::add_ring() {
  const int32_t k = ++ring_;
  const int32_t cx = centre_.x, cy = centre_.y;
  auto consider = [&](int32_t x, int32_t y) {
    if (map_.blocked(x, y)) return;
    // (x + 0.5) is exact; the bounds below are computed the same way, so rounding keeps every
    // squared distance of a later ring at or above the bound (both roundings are monotonic).
    const double dx = (x + 0.5) - point_.x(), dy = (y + 0.5) - point_.y();
    const double squared = dx * dx + dy * dy;
    if (squared <= radius_squared_) heap_.push({squared, y, x});
  };
  if (k == 0) {
    consider(cx, cy);
  } else {
    const int32_t row_from = std::max(xa_, cx - k), row_to = std::min(xb_, cx + k);
    for (const int32_t y : {cy - k, cy + k})
      if (y >= ya_ && y <= yb_)
        for (int32_t x = row_from; x <= row_to; ++x) consider(x, y);
    const int32_t column_from = std::max(ya_, cy - k + 1), column_to = std::min(yb_, cy + k - 1);
    for (const int32_t x : {cx - k, cx + k})
      if (x >= xa_ && x <= xb_)
        for (int32_t y = column_from; y <= column_to; ++y) consider(x, y);
  }
  // Every cell not added yet lies beyond one of the square's sides that the box still extends
  // past; its centre is at least that side's distance from the point (cells).
  double bound = std::numeric_limits<double>::infinity();
  if (cx - k > xa_) bound = std::min(bound, point_.x() - (cx - k - 0.5));
  if (cx + k < xb_) bound = std::min(bound, (cx + k + 1.5) - point_.x());
  if (cy - k > ya_) bound = std::min(bound, point_.y() - (cy - k - 0.5));
  if (cy + k < yb_) bound = std::min(bound, (cy + k + 1.5) - point_.y());
  if (std::isinf(bound)) {
    rings_done_ = true;  // the square covers the box
    return;
  }
  bound = std::max(bound, 0.0);  // the point lies beyond that side (outside the map)
  bound_squared_ = bound * bound;
  if (bound_squared_ > radius_squared_) rings_done_ = true;  // nothing farther is within reach
}

std::optional<Cell> NearestFreeCells::next() {
  for (;;) {
    // Strictly below the bound: a later cell at exactly the bound may have the lower index.
    if (!heap_.empty() && (rings_done_ || heap_.top().squared < bound_squared_)) {
      const Entry e = heap_.top();
      heap_.pop();
      return Cell{e.x, e.y};
    }
    if (rings_done_) return std::nullopt;
    add_ring();
  }
}

ReachOutcome first_reachable(const GridMap& map, CornerPolicy policy, CellStates& states,
                             PlanningBudget* budget, const std::vector<uint32_t>& anchors,
                             NearestFreeCells& candidates) {
  ReachOutcome out;
  // The two sides' marks: one query's epoch of the planner's words, seen by side 0 / side 1.
  constexpr uint16_t kAnchorSide = CellStates::kSeen[0];
  constexpr uint16_t kCandidateSide = CellStates::kSeen[1];
  states.begin_query(map.padded_size());
  const int32_t stride = map.stride();
  const MotionValidator motion(map, policy);
  // Expands `n`: marks its unmarked neighbours with `own` and queues them; true when one carries
  // `other` (the two floods have met).
  auto expand = [&](uint32_t n, uint16_t own, uint16_t other, std::vector<uint32_t>& queue) {
    const Cell c = map.cell_of(n);
    bool met = false;
    motion.for_each_move(c, c, Neighborhood::kEight, [&](int dx, int dy, double) {
      const uint32_t m = n + dy * stride + dx;
      const uint16_t flags = states.flags(m);
      if ((flags & other) != 0) {
        met = true;
      } else if ((flags & own) == 0) {
        states.add(m, own);
        queue.push_back(m);
      }
    });
    return met;
  };
  auto stopped = [&] {
    if (budget == nullptr || budget->poll() == StatusCode::kOk) return false;
    out.code = budget->state();
    return true;
  };

  std::vector<uint32_t> anchor_queue;
  for (const uint32_t a : anchors) {
    if ((states.flags(a) & kAnchorSide) != 0) continue;
    states.add(a, kAnchorSide);
    anchor_queue.push_back(a);
  }
  size_t anchor_head = 0;
  bool anchors_done = false;  // every cell connected to an anchor is marked
  std::vector<uint32_t> flood;
  while (const std::optional<Cell> candidate = candidates.next()) {
    ++out.candidates;
    if (stopped()) return out;
    const uint32_t start = map.padded_index(*candidate);
    const uint16_t flags = states.flags(start);
    if ((flags & kAnchorSide) != 0) {
      out.cell = candidate;
      return out;
    }
    // In a component an earlier flood exhausted, or not marked by the finished anchors' flood.
    if ((flags & kCandidateSide) != 0 || anchors_done) continue;
    states.add(start, kCandidateSide);
    flood.assign(1, start);
    size_t head = 0;
    bool met = false;
    while (!met) {
      if (stopped()) return out;
      if (head == flood.size()) break;  // the candidate's component is exhausted: sealed off
      met = expand(flood[head++], kCandidateSide, kAnchorSide, flood);
      if (met) break;
      if (anchor_head == anchor_queue.size()) {
        anchors_done = true;  // and the candidate is not among the marked cells
        break;
      }
      met = expand(anchor_queue[anchor_head++], kAnchorSide, kCandidateSide, anchor_queue);
    }
    if (met) {
      out.cell = candidate;
      return out;
    }
  }
  return out;
}

}  // namespace vnsba::core::detail
