// The search engines every planner is made of (internal): heuristics, move costs, one
// unidirectional and one bidirectional best-first search, composed by each planner's file in
// core/src/planners/ (warthog's way: the policies are template arguments, so a planner pays only
// for what it uses). Planner::plan gives a planner's search a SearchRequest on free endpoints and
// takes its SearchOutcome.
#pragma once

#include <algorithm>
#include <cstdint>
#include <optional>
#include <vector>

#include "search_space.hpp"
#include "vnsba/core/budget.hpp"
#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/heuristics.hpp"
#include "vnsba/core/motion_validator.hpp"
#include "vnsba/core/neighborhood.hpp"
#include "vnsba/core/planner_options.hpp"
#include "vnsba/core/status.hpp"

namespace vnsba::core::detail {

// The move generation, its per-move visitors and relax() run 8 to 13 times per expansion; GCC
// kept them out of line (a call per move), which made our A* slower than a hand-written loop
// (bench/astar_reference_bench.cpp). MotionValidator::for_each_move carries the same attribute.
#define VNSBA_ALWAYS_INLINE __attribute__((always_inline))

// ---------------------------------------------------------------------------------------------
// Heuristic functors over heuristics.hpp.

// Octile distance to a fixed target: classic A* and BA*. Admissible and consistent for the
// 8-neighbourhood (not for 8-11-13, whose knight moves are shorter than their octile distance).
struct OctileHeuristic {
  const Cell* target;
  double operator()(const Cell& n) const { return octile(n, *target); }
};

// density_weighted_heuristic against the opposite search's current node of the moment (read
// through a pointer, as the search moves it). Evaluated when a node is pushed or its g improves,
// with the opposite current node of that moment; it is not re-evaluated when the opposite current
// node moves later (the paper's open list is keyed on f at insertion).
struct DensityWeightedHeuristic {
  const GridMap* map;
  const Cell* opposite_current;
  Cell opposite_start;
  double omega;
  double eta;
  CornerPolicy policy;

  double operator()(const Cell& n) const {
    return density_weighted_heuristic(*map, n, *opposite_current, opposite_start, omega, eta,
                                      policy);
  }
};

// ---------------------------------------------------------------------------------------------
// Move costs.

// The binary grid of docs/algorithm.md sections 1-7: a move costs its length (the quantized step
// costs of neighborhood.hpp), exactly as before costs existed.
struct UniformMoveCost {
  VNSBA_ALWAYS_INLINE double operator()(uint32_t, uint32_t, int, int, double length) const {
    return length;
  }
};

// Section 8: MotionValidator::move_cost, length * (1 + cost_weight * the highest cell cost the
// move's segment passes), the price pruning and smoothing give the same segment. The validator is
// held by value so that its few fields sit beside the search's other state.
struct CellMoveCost {
  MotionValidator motion;  // weighs_costs()

  VNSBA_ALWAYS_INLINE double operator()(uint32_t from, uint32_t to, int dx, int dy,
                                        double length) const {
    return motion.move_cost(from, to, dx, dy, length);
  }
};

// ---------------------------------------------------------------------------------------------
// Search engines.

struct SearchConfig {
  Neighborhood neighborhood;
  CornerPolicy policy;
  bool record;
};

struct SearchOutcome {
  StatusCode code = StatusCode::kNoValidPath;
  std::vector<Cell> path;
  std::optional<Cell> meeting;
  int64_t expanded = 0;
};

// Follows parents from `node` to the search's root; returns the cells root-first when
// `root_first`, else node-first.
inline std::vector<Cell> trace(const GridMap& map, const SearchSpace& space, uint32_t node,
                               bool root_first) {
  std::vector<Cell> cells;
  for (uint32_t n = node; n != SearchSpace::kNoParent; n = space.parent(n))
    cells.push_back(map.cell_of(n));
  if (root_first) std::reverse(cells.begin(), cells.end());
  return cells;
}

// Relaxes the move n -> m in `space`: opens m, or lowers its g and re-keys it (its f may rise:
// h is evaluated anew against the opposite current node of this moment). Closed nodes are
// skipped by the caller. `g_n` is g of n, read once per expansion by the caller.
template <class Heuristic>
VNSBA_ALWAYS_INLINE inline void relax(SearchSpace& space, uint16_t m_flags, uint32_t n, double g_n,
                                      uint32_t m, const Cell& m_cell, double cost,
                                      const Heuristic& h) {
  const double g = g_n + cost;
  if ((m_flags & space.seen_flag()) == 0) {
    space.push(m, g, g + h(m_cell), n);
  } else if (g < space.g(m)) {
    space.update(m, g, g + h(m_cell), n);
  }
}

// A unidirectional best-first search from start to goal; the neighbourhood's guide is the goal.
template <class Heuristic, class MoveCost>
SearchOutcome search_unidirectional(const GridMap& map, CellStates& states, SearchSpace& space,
                                    const Cell& start, const Cell& goal, const Heuristic& h,
                                    const MoveCost& move_cost, const SearchConfig& cfg,
                                    PlanningBudget& budget, std::vector<Cell>* expanded_cells) {
  SearchOutcome out;
  states.begin_query(map.padded_size());
  space.begin_query(map.padded_size());
  const uint32_t goal_index = map.padded_index(goal);
  const int32_t stride = map.stride();
  const MotionValidator motion(map, cfg.policy);
  space.push(map.padded_index(start), 0.0, h(start), SearchSpace::kNoParent);
  while (!space.empty()) {
    if (StatusCode code = budget.poll(); code != StatusCode::kOk) {
      out.code = code;
      return out;
    }
    const uint32_t n = space.pop();
    ++out.expanded;
    const Cell nc = map.cell_of(n);
    if (cfg.record) expanded_cells->push_back(nc);
    if (n == goal_index) {
      out.code = StatusCode::kOk;
      out.path = trace(map, space, n, /*root_first=*/true);
      return out;
    }
    const double g_n = space.g(n);
    motion.for_each_move(nc, goal, cfg.neighborhood,
                         [&](int dx, int dy, double cost) VNSBA_ALWAYS_INLINE {
                           const uint32_t m = n + dy * stride + dx;
                           const uint16_t flags = states.flags(m);
                           if ((flags & space.closed_flag()) == 0)
                             relax(space, flags, n, g_n, m, Cell{nc.x + dx, nc.y + dy},
                                   move_cost(n, m, dx, dy, cost), h);
                         });
  }
  return out;
}

// How a bidirectional search decides that its two halves have met. Under both rules, a search
// that pops (closes) a node the other search has already closed has met it: with the 8-11-13
// neighbourhood the two move sets differ (a long move y -> x can exist while x -> y does not), so
// this can happen without any generated neighbour having been seen closed by the other side
// (docs/algorithm.md section 3). Checking it keeps every cell closed by at most one search, so the
// two parent chains are disjoint and the joined raw path never visits a cell twice.
enum class MeetingRule {
  // docs/algorithm.md section 3: a search generates a neighbour the other search has closed (or
  // pops
  // one, see above).
  kGenerateClosedByOther,
  // The improved BA* of Li et al.: only a search closing a node the other has closed (which
  // includes the case of both current nodes coinciding).
  kCloseClosedByOther,
};

// Two searches in strict alternation, one expansion each. `current[0]` / `current[1]` are the
// forward / backward current nodes (the last expanded), which the heuristics read through
// pointers, and which guide each search's 8-11-13 neighbourhood (docs/algorithm.md section 2: the
// guide of a bidirectional search is the opposite search's current node, for every planner).
template <class ForwardH, class BackwardH, class MoveCost>
SearchOutcome search_bidirectional(const GridMap& map, CellStates& states, SearchSpace& forward,
                                   SearchSpace& backward, const Cell& start, const Cell& goal,
                                   Cell (&current)[2], const ForwardH& h_forward,
                                   const BackwardH& h_backward, const MoveCost& move_cost,
                                   MeetingRule rule, const SearchConfig& cfg,
                                   PlanningBudget& budget, std::vector<Cell>* expanded_forward,
                                   std::vector<Cell>* expanded_backward) {
  SearchOutcome out;
  const int32_t stride = map.stride();
  const MotionValidator motion(map, cfg.policy);
  current[0] = start;
  current[1] = goal;
  states.begin_query(map.padded_size());
  forward.begin_query(map.padded_size());
  backward.begin_query(map.padded_size());
  forward.push(map.padded_index(start), 0.0, h_forward(start), SearchSpace::kNoParent);
  backward.push(map.padded_index(goal), 0.0, h_backward(goal), SearchSpace::kNoParent);

  // The path through the move a -> b where a was reached by `a_space` and b by the other.
  auto join = [&](bool a_is_forward, uint32_t a, uint32_t b) {
    const uint32_t f = a_is_forward ? a : b;
    const uint32_t r = a_is_forward ? b : a;
    out.path = trace(map, forward, f, /*root_first=*/true);
    const std::vector<Cell> tail = trace(map, backward, r, /*root_first=*/false);
    if (f == r) {
      out.path.insert(out.path.end(), tail.begin() + 1, tail.end());
    } else {
      out.path.insert(out.path.end(), tail.begin(), tail.end());
    }
    out.code = StatusCode::kOk;
  };

  // One expansion of side `s` (0 forward, 1 backward). Returns true when the search is over.
  auto step = [&](int s, SearchSpace& self, const auto& h, std::vector<Cell>* record) -> bool {
    if (self.empty()) {
      out.code = StatusCode::kNoValidPath;
      return true;
    }
    const uint32_t n = self.pop();
    ++out.expanded;
    const Cell nc = map.cell_of(n);
    current[s] = nc;
    if (cfg.record) record->push_back(nc);
    if (self.closed_by_other(n)) {
      out.meeting = nc;
      join(s == 0, n, n);
      return true;
    }
    const Cell& guide = current[1 - s];
    bool met = false;
    const double g_n = self.g(n);
    motion.for_each_move(nc, guide, cfg.neighborhood,
                         [&](int dx, int dy, double cost) VNSBA_ALWAYS_INLINE {
                           const uint32_t m = n + dy * stride + dx;
                           if (met) return;
                           const uint16_t flags = states.flags(m);
                           if ((flags & self.closed_flag()) != 0) return;
                           const Cell mc{nc.x + dx, nc.y + dy};
                           if (rule == MeetingRule::kGenerateClosedByOther &&
                               (flags & self.other_closed_flag()) != 0) {
                             out.meeting = mc;
                             join(s == 0, n, m);
                             met = true;
                             return;
                           }
                           relax(self, flags, n, g_n, m, mc, move_cost(n, m, dx, dy, cost), h);
                         });
    return met;
  };

  for (;;) {
    if (StatusCode code = budget.poll(); code != StatusCode::kOk) {
      out.code = code;
      return out;
    }
    if (step(0, forward, h_forward, expanded_forward)) return out;
    if (step(1, backward, h_backward, expanded_backward)) return out;
  }
}

// What a planner's search is given: the map, the reused search state of both directions, a
// query whose endpoints are in the map, free and distinct, the options (validated), the budget,
// and where to record expansions (when options.record_expansions).
struct SearchRequest {
  const GridMap& map;
  CellStates& states;
  SearchSpace& forward;
  SearchSpace& backward;
  // Per touched cell, for searches that touch cells far apart (jump point search).
  SparseSearchSpace& sparse;
  // The forward / backward current nodes (the last expanded) of a bidirectional search, which
  // its heuristics read through pointers; owned by the planner, so that they outlive the search.
  Cell (&current)[2];
  Cell start;
  Cell goal;
  const PlannerOptions& options;
  PlanningBudget& budget;
  std::vector<Cell>* expanded_forward;
  std::vector<Cell>* expanded_backward;

  SearchConfig config() const {
    return {options.neighborhood, options.corner_policy, options.record_expansions};
  }
};

// Two searches in alternation on the density-weighted heuristic, each towards the other's current
// node and pulled towards the other's root by `eta` (the paper's improved BA* with omega 1, eta 0;
// VNS-BA* with its own weights).
template <class MoveCost>
SearchOutcome search_density_weighted_bidirectional(const SearchRequest& r,
                                                    const MoveCost& move_cost, double omega,
                                                    double eta, MeetingRule rule) {
  const CornerPolicy policy = r.options.corner_policy;
  const DensityWeightedHeuristic forward{&r.map, &r.current[1], r.goal, omega, eta, policy};
  const DensityWeightedHeuristic backward{&r.map, &r.current[0], r.start, omega, eta, policy};
  return search_bidirectional(r.map, r.states, r.forward, r.backward, r.start, r.goal, r.current,
                              forward, backward, move_cost, rule, r.config(), r.budget,
                              r.expanded_forward, r.expanded_backward);
}

// Calls `search(request, move_cost)` with the move cost the options ask for: costs weigh only
// where there are costs to weigh (section 8), else every move costs its length. The two
// instantiations keep the binary grid's search free of cost lookups.
template <class Search>
SearchOutcome with_move_cost(const SearchRequest& request, const Search& search) {
  const MotionValidator motion(request.map, request.options.corner_policy,
                               request.options.cost_weight);
  if (motion.weighs_costs()) return search(request, CellMoveCost{motion});
  return search(request, UniformMoveCost{});
}

}  // namespace vnsba::core::detail
