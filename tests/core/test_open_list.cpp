// The open list under keys that move both ways (docs/algorithm.md section 3): a randomized
// comparison of SearchSpace with an ordered multiset as oracle, and every planner run over random
// maps with the library's open-list check on (this executable links vnsba_core_checked, built with
// VNSBA_CHECK_OPEN_LIST: a pop that is not the least entry of the open list aborts the test).
#include <gtest/gtest.h>

#include <map>
#include <random>
#include <set>

#include "core/test_support.hpp"
#include "search_space.hpp"
#include "vnsba/core/planner.hpp"

namespace vnsba::test {
namespace {

using core::detail::CellStates;
using core::detail::SearchSpace;

// One search space over `cells` cells with its cell states, at the start of a query.
struct OneSearch {
  explicit OneSearch(size_t cells) {
    states.begin_query(cells);
    space.begin_query(cells);
  }
  CellStates states;
  SearchSpace space{&states, 0};
};

TEST(OpenList, ARisingKeySinksBelowTheOthers) {
  OneSearch search(16);
  SearchSpace& space = search.space;
  space.push(1, 0.0, 1.0, SearchSpace::kNoParent);
  space.push(2, 0.0, 2.0, SearchSpace::kNoParent);
  space.push(3, 0.0, 3.0, SearchSpace::kNoParent);
  space.push(4, 0.0, 4.0, SearchSpace::kNoParent);
  // Node 1 had the least key; its g falls but its f rises past everyone else's.
  space.update(1, -1.0, 10.0, 7);
  EXPECT_EQ(space.pop(), 2u);
  EXPECT_EQ(space.pop(), 3u);
  EXPECT_EQ(space.pop(), 4u);
  EXPECT_EQ(space.pop(), 1u);
  EXPECT_EQ(space.parent(1), 7u);
  EXPECT_TRUE(space.empty());
}

TEST(OpenList, EqualKeysPopTheLargerGFirst) {
  OneSearch search(8);
  SearchSpace& space = search.space;
  space.push(1, 1.0, 5.0, SearchSpace::kNoParent);
  space.push(2, 3.0, 5.0, SearchSpace::kNoParent);
  space.push(3, 2.0, 5.0, SearchSpace::kNoParent);
  EXPECT_EQ(space.pop(), 2u);
  EXPECT_EQ(space.pop(), 3u);
  EXPECT_EQ(space.pop(), 1u);
}

// Random pushes, key changes in both directions and pops, against std::set ordered by
// (f, -g, node) as the oracle: every pop must return an entry with the oracle's least key.
TEST(OpenList, MatchesAnOrderedSetUnderRandomKeyChanges) {
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> key(0.0, 100.0);
  constexpr uint32_t kCells = 2000;
  int pops = 0, rises = 0, falls = 0;
  for (int round = 0; round < 50; ++round) {
    OneSearch search(kCells);
    SearchSpace& space = search.space;
    std::map<uint32_t, std::pair<double, double>> open;    // node -> (f, g)
    std::set<std::tuple<double, double, uint32_t>> order;  // (f, -g, node)
    std::set<uint32_t> closed;
    std::uniform_int_distribution<uint32_t> cell(0, kCells - 1);
    for (int op = 0; op < 4000; ++op) {
      const int what = static_cast<int>(rng() % 3);
      const uint32_t n = cell(rng);
      if (what == 0 && !space.seen(n)) {
        const double g = key(rng), f = g + key(rng);
        space.push(n, g, f, SearchSpace::kNoParent);
        open[n] = {f, g};
        // g is kept as float for ties in the heap, so the oracle uses the same value.
        order.insert({f, -double(static_cast<float>(g)), n});
      } else if (what == 1 && !open.empty()) {
        auto it = open.begin();
        std::advance(it, static_cast<long>(rng() % open.size()));
        const uint32_t changed = it->first;
        const auto [old_f, old_g] = it->second;
        const double g = old_g - 1.0, f = key(rng) + key(rng);
        (f > old_f ? rises : falls)++;
        space.update(changed, g, f, SearchSpace::kNoParent);
        order.erase({old_f, -double(static_cast<float>(old_g)), changed});
        open[changed] = {f, g};
        order.insert({f, -double(static_cast<float>(g)), changed});
      } else if (what == 2 && !order.empty()) {
        ASSERT_FALSE(space.empty());
        const uint32_t popped = space.pop();
        const auto least = *order.begin();
        ASSERT_EQ(open.at(popped).first, std::get<0>(least)) << "round " << round << " op " << op;
        ASSERT_EQ(double(static_cast<float>(open.at(popped).second)), -std::get<1>(least));
        order.erase({open[popped].first, -double(static_cast<float>(open[popped].second)), popped});
        open.erase(popped);
        EXPECT_TRUE(space.closed(popped));
        ++pops;
      }
    }
    EXPECT_EQ(space.empty(), order.empty());
  }
  EXPECT_GT(pops, 10000);
  EXPECT_GT(rises, 1000);
  EXPECT_GT(falls, 1000);
}

// Every planner, every corner policy, both neighbourhoods, on random maps: with the check on,
// any pop that is not the least entry of its open list aborts here.
TEST(OpenList, EveryPopIsTheLeastOnRandomMapsForEveryPlanner) {
  std::mt19937 rng(20241029);
  std::uniform_int_distribution<int> size(8, 120);
  std::uniform_real_distribution<double> density(0.0, 0.45);
  int plans = 0, found = 0;
  for (int m = 0; m < 300; ++m) {
    auto map = random_shared_map(rng, size(rng), size(rng), density(rng));
    ASSERT_TRUE(map);
    const auto cells = free_cells(*map);
    if (cells.size() < 2) continue;
    std::uniform_int_distribution<size_t> pick(0, cells.size() - 1);
    const core::PlanQuery q{cells[pick(rng)], cells[pick(rng)]};
    core::Planner planner(map);
    for (core::PlannerKind kind : core::all_planner_kinds()) {
      for (core::Neighborhood hood :
           {core::Neighborhood::kEight, core::Neighborhood::kEightElevenThirteen}) {
        core::PlannerOptions o = core::default_options(kind);
        o.corner_policy = kAllCornerPolicies[m % 3];
        o.neighborhood = hood;
        o.prune = o.smooth = false;
        if (!core::supports(kind, o.corner_policy) || !core::supports(kind, hood)) continue;
        const core::PlanResult r = planner.plan(q, o);
        ++plans;
        found += r.status.is_ok() ? 1 : 0;
      }
    }
  }
  EXPECT_GT(plans, 2500);
  EXPECT_GT(found, plans / 3);
}

}  // namespace
}  // namespace vnsba::test
