// A client of the node's Nav2 actions, as a ROS 2 action client (rclcpp_action on rcl_action)
// puts them on the wire, in either middleware's mapping (service_wire.hpp): vnsba_send_goal
// --action, the tests and the benchmark use it. It creates its endpoints on a Participant the
// caller owns, and is thread-safe. Its code is the same for every action: what is an action's
// own (its DDS types, how a goal is written and a result read) comes from its traits type
// (node/src/action_traits.hpp), chosen by the ActionKind it is created with.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "vnsba/core/status.hpp"
#include "vnsba/node/action_catalog.hpp"
#include "vnsba/node/action_goals.hpp"
#include "vnsba/node/config.hpp"
#include "vnsba/node/convert.hpp"
#include "vnsba/node/dds.hpp"
#include "vnsba/node/service_wire.hpp"

namespace vnsba::node {

// A cancel_goal reply.
struct CancelReply {
  CancelCode code = CancelCode::kNone;
  std::vector<GoalUuid> canceling;
};

class ActionClient {
 public:
  using Duration = std::chrono::milliseconds;
  // `kind`: the action called (nav2_actions()); `ros_name`: its full name, e.g.
  // "/compute_path_to_pose"; `distro`: the ROS 2 distribution whose wire types it speaks (a
  // Humble result carries no error_code: the reply's stays 0).
  static core::Expected<std::unique_ptr<ActionClient>> create(Participant& participant,
                                                              const std::string& ros_name,
                                                              ActionKind kind, WireMapping mapping,
                                                              RosDistro distro = RosDistro::kJazzy);
  ~ActionClient();

  // Until the three services' request readers and reply writers and the status and feedback
  // writers of a server are matched (what rclcpp_action's wait_for_action_server checks).
  bool wait_for_server(Duration timeout, int servers = 1);

  // A fresh random goal id.
  static GoalUuid random_id();

  // Each request returns its sequence number; the matching wait_* returns its reply (nullopt on
  // timeout).
  int64_t send_goal(const GoalUuid& id, const ActionGoalSpec& goal);
  std::optional<bool> wait_accepted(int64_t request, Duration timeout);
  int64_t request_result(const GoalUuid& id);
  std::optional<ActionResultReply> wait_result(int64_t request, Duration timeout);
  int64_t request_cancel(const GoalUuid& id, const GoalStamp& stamp = {});
  std::optional<CancelReply> wait_cancel(int64_t request, Duration timeout);

  // send_goal, then get_result once accepted: the whole round trip. nullopt: no reply in time;
  // a rejected goal gives status UNKNOWN and error_msg "rejected".
  std::optional<ActionResultReply> plan(const GoalUuid& id, const ActionGoalSpec& goal,
                                        Duration timeout);

  // The state of `id` in the newest status list received (UNKNOWN when absent), and a wait for
  // a state.
  GoalState status_of(const GoalUuid& id) const;
  // How many goals the newest status list received lists.
  size_t status_list_size() const;
  bool wait_status(const GoalUuid& id, GoalState state, Duration timeout) const;

  // Sends `payload` as it is (the encapsulation and what follows) as a request of `service`:
  // for tests of malformed requests.
  void send_raw(ActionService service, const RawSample& payload);

  // Replies the client received that answer none of its requests: every reply reaches every
  // client's reply reader, and each client keeps its own (by identity or header), as the rmw do.
  size_t unmatched_replies() const;
  // Replies to a request that had been answered already (never, from a correct server).
  size_t duplicate_replies() const;
  // How many servers this client has met: the send_goal reply writers matched now, or the DDS
  // participants that replied, whichever is more. More than one when two nodes serve the action
  // on one domain, each answering every goal it hears (one that did not accept a goal answers
  // its get_result UNKNOWN, as rcl_action does).
  size_t servers_seen() const;

 private:
  // What every action's client does (replies, statuses, cancel_goal), and the part that is one
  // action's own (ImplOf<Traits>: its endpoints' types, send_goal and get_result).
  class Impl;
  template <class Traits, class Wire>
  class ImplOf;
  explicit ActionClient(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace vnsba::node
