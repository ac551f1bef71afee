// Per-direction search state in flat arrays, reused across queries on one map (internal).
//
// Memory per map cell: one 16-byte record {g, heap position, generation stamp} that the inner
// loop reads with a single cache access, plus the parent (4 bytes) written only when g improves:
// 20 bytes, plus the open list's entries (16 bytes each, only for open nodes). The generation
// stamp lets a new query start in O(1): a cell whose stamp differs from the current generation
// is unseen, so the arrays are never cleared between queries (only on stamp wrap-around).
//
// The open list is a binary heap indexed by cell (each open cell knows its heap position), so a
// key can be changed in place. Keys move both ways: the VNS-BA* heuristic is re-evaluated against
// the opposite search's current node of the moment when g improves, so f can rise as well as
// fall (ALGORITHM.md section 3); update() restores heap order in whichever direction it broke.
//
// With VNSBA_CHECK_OPEN_LIST defined (Debug builds, and the checked test build of the core), every
// pop verifies that the entry it returns is the least of the whole open list and aborts with a
// message otherwise: O(open list) per pop, for tests only.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <vector>

namespace vnsba::core::detail {

class SearchSpace {
 public:
  static constexpr uint32_t kClosed = std::numeric_limits<uint32_t>::max();
  static constexpr uint32_t kNoParent = std::numeric_limits<uint32_t>::max();

  // Sizes the per-cell arrays for `cells` padded cells (no-op when already that size). Called
  // when a planner is made for a map, so that no query pays for the allocation.
  void allocate(size_t cells) {
    if (nodes_.size() == cells) return;
    nodes_.assign(cells, Node{});
    parent_.assign(cells, kNoParent);
    generation_ = 0;
  }

  // Starts a new query on `cells` padded cells: every cell becomes unseen and the open list
  // empty. O(1) unless the arrays were sized for another map.
  void begin_query(size_t cells) {
    allocate(cells);
    if (++generation_ == 0) {  // wrapped: clear once, then start over
      for (Node& node : nodes_) node.stamp = 0;
      generation_ = 1;
    }
    heap_.clear();
  }

  bool seen(uint32_t n) const { return nodes_[n].stamp == generation_; }
  bool closed(uint32_t n) const { return seen(n) && nodes_[n].heap_pos == kClosed; }
  bool empty() const { return heap_.empty(); }
  double g(uint32_t n) const { return nodes_[n].g; }
  uint32_t parent(uint32_t n) const { return parent_[n]; }

  // Opens an unseen node.
  void push(uint32_t n, double g, double f, uint32_t parent) {
    nodes_[n] = {g, static_cast<uint32_t>(heap_.size()), generation_};
    parent_[n] = parent;
    heap_.push_back({f, n, static_cast<float>(g)});
    sift_up(heap_.size() - 1);
  }

  // Gives an open node a lower g and a new f, which may be lower or higher than its old f (see
  // the file comment), and restores heap order in that direction.
  void update(uint32_t n, double g, double f, uint32_t parent) {
    nodes_[n].g = g;
    parent_[n] = parent;
    const uint32_t pos = nodes_[n].heap_pos;
    const Entry old = heap_[pos];
    heap_[pos].f = f;
    heap_[pos].g = static_cast<float>(g);
    if (before(heap_[pos], old)) {
      sift_up(pos);
    } else {
      sift_down(pos);
    }
  }

  // Removes the open node with the least f (ties: the larger g, i.e. the deeper node, which
  // expands fewer nodes on open ground) and marks it closed.
  uint32_t pop() {
#ifdef VNSBA_CHECK_OPEN_LIST
    check_top_is_least();
#endif
    const uint32_t top = heap_.front().node;
    nodes_[top].heap_pos = kClosed;
    const Entry last = heap_.back();
    heap_.pop_back();
    if (!heap_.empty()) {
      heap_.front() = last;
      nodes_[last.node].heap_pos = 0;
      sift_down(0);
    }
    return top;
  }

  size_t bytes() const {
    return nodes_.capacity() * sizeof(Node) + parent_.capacity() * sizeof(uint32_t) +
           heap_.capacity() * sizeof(Entry);
  }

 private:
  struct Node {
    double g = 0.0;
    uint32_t heap_pos = kClosed;  // position in heap_ while open, kClosed once closed
    uint32_t stamp = 0;           // generation in which g and heap_pos were last written
  };
  static_assert(sizeof(Node) == 16);

  // g is kept in the entry (as float: it only breaks ties between equal f) so that comparing
  // two entries never touches the per-cell arrays.
  struct Entry {
    double f;
    uint32_t node;
    float g;
  };
  static_assert(sizeof(Entry) == 16);

  static bool before(const Entry& a, const Entry& b) {
    return a.f < b.f || (a.f == b.f && a.g > b.g);
  }

#ifdef VNSBA_CHECK_OPEN_LIST
  void check_top_is_least() const {
    for (size_t i = 1; i < heap_.size(); ++i) {
      if (before(heap_[i], heap_[0])) {
        std::fprintf(stderr,
                     "open list out of order: popping f = %.17g (g %.9g) while entry %zu has "
                     "f = %.17g (g %.9g)\n",
                     heap_[0].f, double{heap_[0].g}, i, heap_[i].f, double{heap_[i].g});
        std::abort();
      }
    }
  }
#endif

  void sift_up(size_t pos) {
    const Entry moving = heap_[pos];
    while (pos > 0) {
      const size_t parent = (pos - 1) / 2;
      if (!before(moving, heap_[parent])) break;
      heap_[pos] = heap_[parent];
      nodes_[heap_[pos].node].heap_pos = static_cast<uint32_t>(pos);
      pos = parent;
    }
    heap_[pos] = moving;
    nodes_[moving.node].heap_pos = static_cast<uint32_t>(pos);
  }

  void sift_down(size_t pos) {
    const size_t size = heap_.size();
    const Entry moving = heap_[pos];
    for (;;) {
      size_t child = 2 * pos + 1;
      if (child >= size) break;
      if (child + 1 < size && before(heap_[child + 1], heap_[child])) ++child;
      if (!before(heap_[child], moving)) break;
      heap_[pos] = heap_[child];
      nodes_[heap_[pos].node].heap_pos = static_cast<uint32_t>(pos);
      pos = child;
    }
    heap_[pos] = moving;
    nodes_[moving.node].heap_pos = static_cast<uint32_t>(pos);
  }

  std::vector<Node> nodes_;
  std::vector<uint32_t> parent_;
  std::vector<Entry> heap_;
  uint32_t generation_ = 0;
};

}  // namespace vnsba::core::detail
