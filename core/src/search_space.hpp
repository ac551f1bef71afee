// Per-direction search state in flat arrays, reused across queries on one map (internal).
//
// Memory per map cell: one 16-byte record {g, heap position, generation stamp} that the inner
// loop reads with a single cache access, plus the parent (4 bytes) written only when g improves:
// 20 bytes, plus the open list's entries (16 bytes each, only for open nodes). The generation
// stamp lets a new query start in O(1): a cell whose stamp differs from the current generation
// is unseen, so the arrays are never cleared between queries (only on stamp wrap-around).
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

namespace vnsba::core::detail {

class SearchSpace {
 public:
  static constexpr uint32_t kClosed = std::numeric_limits<uint32_t>::max();
  static constexpr uint32_t kNoParent = std::numeric_limits<uint32_t>::max();

  // Sizes the arrays for `cells` padded cells (no-op when already that size) and starts a new
  // query: every cell becomes unseen and the open list empty.
  void begin_query(size_t cells) {
    if (nodes_.size() != cells) {
      nodes_.assign(cells, Node{});
      parent_.assign(cells, kNoParent);
      generation_ = 0;
    }
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

  // Lowers the g (and f) of an open node.
  void decrease(uint32_t n, double g, double f, uint32_t parent) {
    nodes_[n].g = g;
    parent_[n] = parent;
    const uint32_t pos = nodes_[n].heap_pos;
    heap_[pos].f = f;
    heap_[pos].g = static_cast<float>(g);
    sift_up(pos);
  }

  // Removes the open node with the least f (ties: the larger g, i.e. the deeper node, which
  // expands fewer nodes on open ground) and marks it closed.
  uint32_t pop() {
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
