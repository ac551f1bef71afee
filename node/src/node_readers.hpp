// The node's readers: each made on the participant with its listener (take_listener.hpp), every
// listener kept here until the participant is gone (a listener may be called until its reader
// is deleted). The roles add their own readers through it, in the order start() calls them.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "action_server.hpp"
#include "take_listener.hpp"
#include "vnsba/node/dds.hpp"

namespace vnsba::node {

// A robot's readers the intake thread takes from (its requests, goals and action goals), each
// with its listener.
using IntakeInputs = std::vector<std::pair<TakingListener*, dds::DataReader*>>;

class NodeReaders {
 public:
  // Readers are made on `participant` from here on.
  void use(Participant& participant) { participant_ = &participant; }

  // A reader of PubSubType on `topic` (the DDS name). `intake`, when given, is the robot's list
  // of readers the intake thread takes from.
  template <class PubSubType>
  core::Status add(const std::string& topic, const dds::DataReaderQos& qos,
                   std::unique_ptr<TakingListener> listener, IntakeInputs* intake = nullptr) {
    listeners_.push_back(std::move(listener));
    auto reader = participant_->reader_on<PubSubType>(topic, qos, listeners_.back().get());
    if (!reader) return reader.error();
    if (intake != nullptr) intake->emplace_back(listeners_.back().get(), *reader);
    return core::Status::ok();
  }

  // An action server's writers and readers (ActionServer::create); its send_goal reader goes to
  // `intake`.
  core::Status add_action_server(ActionServer& server, IntakeInputs& intake) {
    return server.create(*participant_, listeners_, intake);
  }

  // A plain service's reply writer and request reader (ServiceServer::create).
  template <class Server>
  core::Status add_service(Server& server) {
    return server.create(*participant_, listeners_);
  }

  // Once the participant is gone: the listeners go.
  void clear() {
    listeners_.clear();
    participant_ = nullptr;
  }

 private:
  Participant* participant_ = nullptr;
  std::vector<std::unique_ptr<TakingListener>> listeners_;
};

}  // namespace vnsba::node
