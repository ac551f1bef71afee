// Search state in flat arrays, reused across queries on one map (internal).
//
// Memory per map cell: per direction, one 16-byte record of g (8 bytes), the parent (4) and the
// heap position (4), plus two bytes shared by both directions (CellStates): 34 bytes for a
// bidirectional planner, plus the open lists' entries (16 bytes each, only for open nodes).
// The shared state is its own dense array because the inner loops read it first (seen or
// closed, by which search) for every neighbour; the record holds what is then read and written
// together. As three separate arrays, a search touching cells far apart (jump point search)
// took three cache misses where the record takes one; A*'s time and every output are the same
// (identical results on the Moving AI sample).
//
// The open list is a binary heap indexed by cell (each open cell knows its heap position), so a
// key can be changed in place. Keys move both ways: the VNS-BA* heuristic is re-evaluated against
// the opposite search's current node of the moment when g improves, so f can rise as well as
// fall (docs/algorithm.md section 3); update() restores heap order in whichever direction it broke.
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

// What each search knows of each cell in the current query, shared by the two searches of a
// planner: seen (pushed) by the forward or backward search, closed by either. One 16-bit word
// per padded cell: the query's epoch (12 bits) and four flags, so a new query starts in O(1) (a
// word of an older epoch reads as "nothing known"); the array is cleared once every 4095 queries.
// No search expands a cell the other has closed: a bidirectional search that pops such a cell
// stops there (docs/algorithm.md section 3), so both closed flags of a cell are set only at a
// meeting of the two searches.
class CellStates {
 public:
  static constexpr uint16_t kSeen[2] = {1, 2};    // by side 0 (forward) / 1 (backward)
  static constexpr uint16_t kClosed[2] = {4, 8};  // likewise

  void allocate(size_t cells) {
    if (words_.size() == cells) return;
    words_.assign(cells, 0);
    epoch_ = 0;
  }

  // Every cell becomes unknown to both searches.
  void begin_query(size_t cells) {
    allocate(cells);
    if (++epoch_ == kEpochs) {
      std::fill(words_.begin(), words_.end(), uint16_t{0});
      epoch_ = 1;
    }
  }

  // The flags of `n` in this query (0 when neither search has seen it).
  uint16_t flags(uint32_t n) const {
    const uint16_t word = words_[n];
    return (word >> kFlagBits) == epoch_ ? (word & kFlagMask) : 0;
  }
  void add(uint32_t n, uint16_t flag) {
    words_[n] = static_cast<uint16_t>(epoch_ << kFlagBits | flags(n) | flag);
  }

  size_t bytes() const { return words_.capacity() * sizeof(uint16_t); }

 private:
  static constexpr int kFlagBits = 4;
  static constexpr uint16_t kFlagMask = (1 << kFlagBits) - 1;
  static constexpr uint16_t kEpochs = 1 << (16 - kFlagBits);
  std::vector<uint16_t> words_;
  uint16_t epoch_ = 0;
};

class SearchSpace {
 public:
  static constexpr uint32_t kNoParent = std::numeric_limits<uint32_t>::max();

  // `states` is shared with the other direction of a bidirectional search; `side` is 0 for the
  // forward search, 1 for the backward one.
  SearchSpace(CellStates* states, int side)
      : states_(states),
        seen_flag_(CellStates::kSeen[side]),
        closed_flag_(CellStates::kClosed[side]),
        other_closed_flag_(CellStates::kClosed[1 - side]) {}

  // Sizes the per-cell arrays for `cells` padded cells (no-op when already that size). Called
  // when a planner is made for a map, so that no query pays for the allocation.
  void allocate(size_t cells) {
    if (nodes_.size() == cells) return;
    nodes_.assign(cells, Node{0.0, kNoParent, 0});
  }

  // Starts a new query on `cells` padded cells with an empty open list. The shared CellStates
  // must begin the query too (once for both directions).
  void begin_query(size_t cells) {
    allocate(cells);
    heap_.clear();
  }

  // The flags this search tests in CellStates::flags().
  uint16_t seen_flag() const { return seen_flag_; }
  uint16_t closed_flag() const { return closed_flag_; }
  uint16_t other_closed_flag() const { return other_closed_flag_; }

  bool seen(uint32_t n) const { return (states_->flags(n) & seen_flag_) != 0; }
  bool closed(uint32_t n) const { return (states_->flags(n) & closed_flag_) != 0; }
  bool closed_by_other(uint32_t n) const { return (states_->flags(n) & other_closed_flag_) != 0; }
  bool empty() const { return heap_.empty(); }
  double g(uint32_t n) const { return nodes_[n].g; }
  uint32_t parent(uint32_t n) const { return nodes_[n].parent; }

  // Opens an unseen node.
  void push(uint32_t n, double g, double f, uint32_t parent) {
    states_->add(n, seen_flag_);
    nodes_[n].g = g;
    nodes_[n].parent = parent;
    heap_.push_back({f, n, static_cast<float>(g)});
    sift_up(heap_.size() - 1);
  }

  // Gives an open node a lower g and a new f, which may be lower or higher than its old f (see
  // the file comment), and restores heap order in that direction.
  void update(uint32_t n, double g, double f, uint32_t parent) {
    nodes_[n].g = g;
    nodes_[n].parent = parent;
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
    states_->add(top, closed_flag_);
    const Entry last = heap_.back();
    heap_.pop_back();
    if (!heap_.empty()) {
      heap_.front() = last;
      nodes_[last.node].heap_pos = 0;
      sift_down(0);
    }
    return top;
  }

  // This direction's arrays and open list (not the shared CellStates).
  size_t bytes() const {
    return nodes_.capacity() * sizeof(Node) + heap_.capacity() * sizeof(Entry);
  }

 private:
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

  CellStates* states_;
  uint16_t seen_flag_, closed_flag_, other_closed_flag_;
  // What one direction knows of a cell, in one record: a search that reaches a cell reads and
  // writes its g, parent and heap position together, so they share a cache line (one miss
  // instead of three where the cells touched are far apart, as a jump point search's are).
  struct Node {
    double g;           // valid where seen
    uint32_t parent;    // padded index of the predecessor, kNoParent at the root
    uint32_t heap_pos;  // index into heap_ while open
  };
  static_assert(sizeof(Node) == 16);
  std::vector<Node> nodes_;  // one per padded cell
  std::vector<Entry> heap_;
};

}  // namespace vnsba::core::detail
