// Search state, reused across queries on one map (internal), in memory that grows with what the
// searches touch, not with the map.
//
// The searches that step from cell to cell (A* and the bidirectional ones) keep their state in
// arrays indexed by cell, with no indirection in the inner loops, but reserved as LazyArrays: the
// system commits a 4 KiB page of them where a search first writes, so a query pays for the pages
// it touches and nothing is committed before the first query. Per touched page of cells: per
// direction, one 16-byte record of g (8 bytes), the parent (4) and the heap position (4) a cell,
// plus two bytes a cell shared by both directions (CellStates); a direction no query has used
// (the backward one of a unidirectional planner) holds nothing. The shared state is its own array
// because the inner loops read it first (seen or closed, by which search) for every neighbour;
// the record holds what is then read and written together.
//
// Jump point search touches a few cells far apart (its jump points), so a page of records would
// hold one or two of them: SparseSearchSpace keeps a record per touched cell instead, found
// through a hash table (about 40 bytes a touched cell in all), as warthog's node pool does.
//
// Both keep the open list's entries (16 bytes an open node) in an OpenList.
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

#include "lazy_array.hpp"

namespace vnsba::core::detail {

// What each search knows of each cell in the current query, shared by the two searches of a
// planner: seen (pushed) by the forward or backward search, closed by either. One 16-bit word
// per padded cell (a LazyArray, committed where touched): the query's epoch (12 bits) and four
// flags, so a new query starts in O(1) (a word of an older epoch reads as "nothing known"); once
// every 4095 queries the array's pages are handed back (zero again).
// No search expands a cell the other has closed: a bidirectional search that pops such a cell
// stops there (docs/algorithm.md section 3), so both closed flags of a cell are set only at a
// meeting of the two searches.
class CellStates {
 public:
  static constexpr uint16_t kSeen[2] = {1, 2};    // by side 0 (forward) / 1 (backward)
  static constexpr uint16_t kClosed[2] = {4, 8};  // likewise

  // Every cell becomes unknown to both searches. The first query reserves the words (nothing
  // is committed until written).
  void begin_query(size_t cells) {
    if (words_.size() != cells) {
      words_.resize(cells);
      epoch_ = 0;
    }
    if (++epoch_ == kEpochs) {
      words_.release();
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

  // Bytes committed (the pages written since the last release); O(pages), for reports.
  size_t bytes() const { return words_.resident_bytes(); }

 private:
  static constexpr int kFlagBits = 4;
  static constexpr uint16_t kFlagMask = (1 << kFlagBits) - 1;
  static constexpr uint16_t kEpochs = 1 << (16 - kFlagBits);
  LazyArray<uint16_t> words_;
  uint16_t epoch_ = 0;
};

// A binary heap of open nodes keyed by f, indexed: each entry names an `id` (a cell for
// SearchSpace, a record for SparseSearchSpace) whose heap position the owner keeps, so that a key
// can be changed in place. `Positions` is the owner's accessor: uint32_t& operator()(uint32_t id).
class OpenList {
 public:
  bool empty() const { return heap_.empty(); }
  void clear() { heap_.clear(); }
  size_t bytes() const { return heap_.capacity() * sizeof(Entry); }
  uint32_t top() const { return heap_.front().id; }

  template <class Positions>
  void push(uint32_t id, double g, double f, Positions&& positions) {
    heap_.push_back({f, id, static_cast<float>(g)});
    sift_up(heap_.size() - 1, positions);
  }

  // The entry at heap position `pos` gets a lower g and a new f, which may be lower or higher
  // than its old f (see the file comment); heap order is restored in that direction.
  template <class Positions>
  void update(uint32_t pos, double g, double f, Positions&& positions) {
    const Entry old = heap_[pos];
    heap_[pos].f = f;
    heap_[pos].g = static_cast<float>(g);
    if (before(heap_[pos], old)) {
      sift_up(pos, positions);
    } else {
      sift_down(pos, positions);
    }
  }

  // Removes the entry with the least f (ties: the larger g, i.e. the deeper node, which expands
  // fewer nodes on open ground) and returns its id.
  template <class Positions>
  uint32_t pop(Positions&& positions) {
#ifdef VNSBA_CHECK_OPEN_LIST
    check_top_is_least();
#endif
    const uint32_t top = heap_.front().id;
    const Entry last = heap_.back();
    heap_.pop_back();
    if (!heap_.empty()) {
      heap_.front() = last;
      positions(last.id) = 0;
      sift_down(0, positions);
    }
    return top;
  }

 private:
  // g is kept in the entry (as float: it only breaks ties between equal f) so that comparing
  // two entries never touches the per-node records.
  struct Entry {
    double f;
    uint32_t id;
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

  template <class Positions>
  void sift_up(size_t pos, Positions& positions) {
    const Entry moving = heap_[pos];
    while (pos > 0) {
      const size_t parent = (pos - 1) / 2;
      if (!before(moving, heap_[parent])) break;
      heap_[pos] = heap_[parent];
      positions(heap_[pos].id) = static_cast<uint32_t>(pos);
      pos = parent;
    }
    heap_[pos] = moving;
    positions(moving.id) = static_cast<uint32_t>(pos);
  }

  template <class Positions>
  void sift_down(size_t pos, Positions& positions) {
    const size_t size = heap_.size();
    const Entry moving = heap_[pos];
    for (;;) {
      size_t child = 2 * pos + 1;
      if (child >= size) break;
      if (child + 1 < size && before(heap_[child + 1], heap_[child])) ++child;
      if (!before(heap_[child], moving)) break;
      heap_[pos] = heap_[child];
      positions(heap_[pos].id) = static_cast<uint32_t>(pos);
      pos = child;
    }
    heap_[pos] = moving;
    positions(moving.id) = static_cast<uint32_t>(pos);
  }

  std::vector<Entry> heap_;
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

  // Starts a new query on `cells` padded cells with an empty open list. The first query reserves
  // the records (nothing is committed until written; a record is read only where the shared
  // CellStates says seen, so pages of an earlier query need no clearing). The shared CellStates
  // must begin the query too (once for both directions).
  void begin_query(size_t cells) {
    nodes_.resize(cells);
    open_.clear();
  }

  // The flags this search tests in CellStates::flags().
  uint16_t seen_flag() const { return seen_flag_; }
  uint16_t closed_flag() const { return closed_flag_; }
  uint16_t other_closed_flag() const { return other_closed_flag_; }

  bool seen(uint32_t n) const { return (states_->flags(n) & seen_flag_) != 0; }
  bool closed(uint32_t n) const { return (states_->flags(n) & closed_flag_) != 0; }
  bool closed_by_other(uint32_t n) const { return (states_->flags(n) & other_closed_flag_) != 0; }
  bool empty() const { return open_.empty(); }
  double g(uint32_t n) const { return nodes_[n].g; }
  uint32_t parent(uint32_t n) const { return nodes_[n].parent; }

  // Opens an unseen node.
  void push(uint32_t n, double g, double f, uint32_t parent) {
    states_->add(n, seen_flag_);
    nodes_[n].g = g;
    nodes_[n].parent = parent;
    open_.push(n, g, f, positions());
  }

  // Gives an open node a lower g and a new f (OpenList::update).
  void update(uint32_t n, double g, double f, uint32_t parent) {
    nodes_[n].g = g;
    nodes_[n].parent = parent;
    open_.update(nodes_[n].heap_pos, g, f, positions());
  }

  // Removes the open node with the least f and marks it closed.
  uint32_t pop() {
    const uint32_t top = open_.top();
    states_->add(top, closed_flag_);
    return open_.pop(positions());
  }

  // This direction's committed records and open list (not the shared CellStates); O(pages),
  // for reports.
  size_t bytes() const { return nodes_.resident_bytes() + open_.bytes(); }

 private:
  // The open list's accessor of heap positions: a cell's, in its record.
  struct HeapPositions {
    SearchSpace* space;
    uint32_t& operator()(uint32_t n) const { return space->nodes_[n].heap_pos; }
  };
  HeapPositions positions() { return {this}; }

  CellStates* states_;
  uint16_t seen_flag_, closed_flag_, other_closed_flag_;
  // What one direction knows of a cell, in one record: a search that reaches a cell reads and
  // writes its g, parent and heap position together, so they share a cache line.
  struct Node {
    double g;           // valid where seen
    uint32_t parent;    // padded index of the predecessor, kNoParent at the root
    uint32_t heap_pos;  // index into the open list while open
  };
  static_assert(sizeof(Node) == 16);
  LazyArray<Node> nodes_;  // one per padded cell, committed where touched
  OpenList open_;
};

// One search's state kept per touched cell (see the file comment): the records of this query in
// the order they were opened, and a hash table from cell to record (open addressing, linear
// probing, at most half full). A new query clears only the slots the last one filled.
class SparseSearchSpace {
 public:
  static constexpr uint32_t kNoParent = SearchSpace::kNoParent;
  static constexpr uint32_t kNoRecord = std::numeric_limits<uint32_t>::max();

  void begin_query() {
    if (records_.size() * 8 >= slots_.size()) {
      std::fill(slots_.begin(), slots_.end(), uint64_t{0});
    } else {
      // Newest first: every slot between a record's home and its own holds an older record (the
      // table is filled, and refilled by grow(), in the order of the records), so the probe
      // that finds a record still runs over filled slots.
      for (auto r = records_.rbegin(); r != records_.rend(); ++r) slots_[slot_of(r->node)] = 0;
    }
    records_.clear();
    open_.clear();
  }

  // The record of cell `n` in this query, kNoRecord when the search has not seen it.
  uint32_t find(uint32_t n) const {
    if (slots_.empty()) return kNoRecord;
    for (size_t slot = home(n);; slot = (slot + 1) & mask_) {
      const uint64_t entry = slots_[slot];
      if (entry == 0) return kNoRecord;
      if (cell_in(entry) == n) return record_in(entry);
    }
  }
  bool closed(uint32_t record) const { return records_[record].closed; }
  double g_of(uint32_t record) const { return records_[record].g; }
  bool empty() const { return open_.empty(); }
  // g and parent of a cell the search has seen.
  double g(uint32_t n) const { return records_[find(n)].g; }
  uint32_t parent(uint32_t n) const { return records_[find(n)].parent; }

  // Opens an unseen cell.
  void push(uint32_t n, double g, double f, uint32_t parent) {
    if ((records_.size() + 1) * 2 > slots_.size()) grow();
    const uint32_t record = static_cast<uint32_t>(records_.size());
    records_.push_back({g, parent, 0, n, false});
    slots_[free_slot(n)] = entry_of(n, record);
    open_.push(record, g, f, positions());
  }

  // Gives an open record a lower g and a new f (OpenList::update).
  void update(uint32_t record, double g, double f, uint32_t parent) {
    records_[record].g = g;
    records_[record].parent = parent;
    open_.update(records_[record].heap_pos, g, f, positions());
  }

  // Removes the open cell with the least f, marks it closed and returns its record.
  uint32_t pop() {
    const uint32_t record = open_.pop(positions());
    records_[record].closed = true;
    return record;
  }
  uint32_t cell_of(uint32_t record) const { return records_[record].node; }
  uint32_t parent_of(uint32_t record) const { return records_[record].parent; }

  size_t bytes() const {
    return records_.capacity() * sizeof(Record) + slots_.capacity() * sizeof(uint64_t) +
           open_.bytes();
  }

 private:
  struct Record {
    double g;
    uint32_t parent;    // padded index of the predecessor, kNoParent at the root
    uint32_t heap_pos;  // index into the open list while open
    uint32_t node;      // padded index of the cell
    bool closed;
  };
  static_assert(sizeof(Record) == 24);

  // The open list's accessor of heap positions: a record's.
  struct HeapPositions {
    SparseSearchSpace* space;
    uint32_t& operator()(uint32_t record) const { return space->records_[record].heap_pos; }
  };
  HeapPositions positions() { return {this}; }
  // Fibonacci hashing of the cell's run of 8 along its row (the top bits of n / 8 times 2^32 /
  // golden ratio), then the cell's place in the run: the slots of up to 8 neighbours in a row
  // share a cache line, as their words did in a per-cell array.
  size_t home(uint32_t n) const {
    return ((static_cast<uint32_t>((n >> 3) * 2654435769u) >> shift_) * 8 + (n & 7)) & mask_;
  }
  size_t free_slot(uint32_t n) const {
    size_t slot = home(n);
    while (slots_[slot] != 0) slot = (slot + 1) & mask_;
    return slot;
  }
  size_t slot_of(uint32_t n) const {
    size_t slot = home(n);
    while (cell_in(slots_[slot]) != n) slot = (slot + 1) & mask_;
    return slot;
  }
  // Doubles the table (at least 4096 slots) and enters this query's records again.
  void grow() {
    const size_t size = std::max<size_t>(4096, slots_.size() * 2);
    slots_.assign(size, uint64_t{0});
    mask_ = size - 1;
    shift_ = 35 - __builtin_ctzll(size);  // size / 8 runs of 8 slots
    for (uint32_t r = 0; r < records_.size(); ++r)
      slots_[free_slot(records_[r].node)] = entry_of(records_[r].node, r);
  }

  std::vector<Record> records_;  // this query's, in the order opened
  // A slot holds the cell (high 32 bits) and its record + 1 (low 32 bits; 0 = empty), so that a
  // lookup reads one slot, not a record as well, per cell it passes: one cache miss, not two.
  static uint64_t entry_of(uint32_t n, uint32_t record) {
    return uint64_t{n} << 32 | (uint64_t{record} + 1);
  }
  static uint32_t cell_in(uint64_t entry) { return static_cast<uint32_t>(entry >> 32); }
  static uint32_t record_in(uint64_t entry) { return static_cast<uint32_t>(entry) - 1; }
  std::vector<uint64_t> slots_;  // entry_of(cell, record), 0 = empty; a power of two long
  size_t mask_ = 0;
  int shift_ = 32;
  OpenList open_;
};

}  // namespace vnsba::core::detail
