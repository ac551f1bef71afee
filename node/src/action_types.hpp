// The DDS types of Nav2's planner actions, shared by the action server and the action client:
// each action's nav2_msgs types, and RawOf, a type whose samples stay serialized bytes.
#pragma once

#include <fastdds/dds/topic/TopicDataType.hpp>
#include <vector>

#include "action_msgs/msg/GoalStatusArrayPubSubTypes.h"
#include "action_msgs/srv/CancelGoalPubSubTypes.h"
#include "nav2_msgs/action/ComputePathThroughPosesPubSubTypes.h"
#include "nav2_msgs/action/ComputePathToPosePubSubTypes.h"
#include "vnsba/node/convert.hpp"
#include "vnsba/node/service_wire.hpp"

namespace vnsba::node {

namespace dds = eprosima::fastdds::dds;
using eprosima::fastrtps::rtps::InstanceHandle_t;
using eprosima::fastrtps::rtps::SerializedPayload_t;

// The nav2_msgs types of each action.
struct ToPoseTypes {
  using SendGoalRequest = nav2_msgs::action::dds_::ComputePathToPose_SendGoal_Request_;
  using SendGoalRequestType =
      nav2_msgs::action::dds_::ComputePathToPose_SendGoal_Request_PubSubType;
  using SendGoalResponse = nav2_msgs::action::dds_::ComputePathToPose_SendGoal_Response_;
  using SendGoalResponseType =
      nav2_msgs::action::dds_::ComputePathToPose_SendGoal_Response_PubSubType;
  using GetResultRequest = nav2_msgs::action::dds_::ComputePathToPose_GetResult_Request_;
  using GetResultRequestType =
      nav2_msgs::action::dds_::ComputePathToPose_GetResult_Request_PubSubType;
  using GetResultResponse = nav2_msgs::action::dds_::ComputePathToPose_GetResult_Response_;
  using GetResultResponseType =
      nav2_msgs::action::dds_::ComputePathToPose_GetResult_Response_PubSubType;
  using FeedbackMessageType = nav2_msgs::action::dds_::ComputePathToPose_FeedbackMessage_PubSubType;
  static std::vector<PoseStampedMsg> goals(const SendGoalRequest& r) { return {r.goal().goal()}; }
  static void set_goals(SendGoalRequest& r, const std::vector<PoseStampedMsg>& goals) {
    if (!goals.empty()) r.goal().goal(goals.front());
  }
};
struct ThroughPosesTypes {
  using SendGoalRequest = nav2_msgs::action::dds_::ComputePathThroughPoses_SendGoal_Request_;
  using SendGoalRequestType =
      nav2_msgs::action::dds_::ComputePathThroughPoses_SendGoal_Request_PubSubType;
  using SendGoalResponse = nav2_msgs::action::dds_::ComputePathThroughPoses_SendGoal_Response_;
  using SendGoalResponseType =
      nav2_msgs::action::dds_::ComputePathThroughPoses_SendGoal_Response_PubSubType;
  using GetResultRequest = nav2_msgs::action::dds_::ComputePathThroughPoses_GetResult_Request_;
  using GetResultRequestType =
      nav2_msgs::action::dds_::ComputePathThroughPoses_GetResult_Request_PubSubType;
  using GetResultResponse = nav2_msgs::action::dds_::ComputePathThroughPoses_GetResult_Response_;
  using GetResultResponseType =
      nav2_msgs::action::dds_::ComputePathThroughPoses_GetResult_Response_PubSubType;
  using FeedbackMessageType =
      nav2_msgs::action::dds_::ComputePathThroughPoses_FeedbackMessage_PubSubType;
  static std::vector<PoseStampedMsg> goals(const SendGoalRequest& r) { return r.goal().goals(); }
  static void set_goals(SendGoalRequest& r, const std::vector<PoseStampedMsg>& goals) {
    r.goal().goals(goals);
  }
};
using CancelRequest = action_msgs::srv::dds_::CancelGoal_Request_;
using CancelResponse = action_msgs::srv::dds_::CancelGoal_Response_;
using GoalInfoMsg = action_msgs::msg::dds_::GoalInfo_;

// A type whose samples are their serialized bytes (RawSample), under the DDS type name of
// `Generated` (a fastddsgen PubSubType): the server decodes a request only once it knows its
// client's mapping, and writes a reply with or without rmw_cyclonedds's header.
template <class Generated>
class RawOf : public dds::TopicDataType {
 public:
  RawOf() {
    Generated generated;
    setName(generated.getName());
    m_typeSize = 1024;  // a first allocation; PREALLOCATED_WITH_REALLOC grows it per sample
    m_isGetKeyDefined = false;
  }
  bool serialize(void* data, SerializedPayload_t* payload) override {
    const RawSample& sample = *static_cast<RawSample*>(data);
    const auto& bytes = sample.bytes;
    if (bytes.size() < 4 || sample.size() > payload->max_size) return false;
    uint8_t* end = std::copy(bytes.begin(), bytes.end(), payload->data);
    if (sample.shared_tail) std::copy(sample.shared_tail->begin(), sample.shared_tail->end(), end);
    payload->length = static_cast<uint32_t>(sample.size());
    payload->encapsulation = bytes[1] == 0 ? CDR_BE : CDR_LE;
    return true;
  }
  bool deserialize(SerializedPayload_t* payload, void* data) override {
    RawSample& sample = *static_cast<RawSample*>(data);
    sample.bytes.assign(payload->data, payload->data + payload->length);
    sample.shared_tail.reset();
    return true;
  }
  std::function<uint32_t()> getSerializedSizeProvider(void* data) override {
    return [data] { return static_cast<uint32_t>(static_cast<RawSample*>(data)->size()); };
  }
  void* createData() override { return new RawSample(); }
  void deleteData(void* data) override { delete static_cast<RawSample*>(data); }
  bool getKey(void*, InstanceHandle_t*, bool) override { return false; }
};

}  // namespace vnsba::node
