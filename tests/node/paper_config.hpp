// The configuration most node tests plan with: config/paper.yaml's, compiled in (the paper's
// binary grid: a point robot, no inflation or costs, exact start and goal, vns_bastar), with
// requests.map_wait 0 so that a request sent before any map is answered NO_MAP at once. A test
// that needs more of the real robot starts from node::default_config() instead.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>

#include "vnsba/node/config.hpp"

namespace vnsba::test {

inline node::NodeConfig paper_test_config() {
  const node::ConfigResult paper = node::paper_config();
  if (!paper.config) {
    ADD_FAILURE() << "the built-in paper.yaml does not load: "
                  << (paper.errors.empty() ? std::string() : paper.errors.front());
    std::abort();  // nothing else can make a NodeConfig; a build defect, not a test outcome
  }
  node::NodeConfig config = *paper.config;
  config.map_wait = std::chrono::milliseconds{0};
  return config;
}

}  // namespace vnsba::test
