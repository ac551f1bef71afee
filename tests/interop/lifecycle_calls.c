/* rmw_cyclonedds's client side of a managed node's lifecycle services (lifecycle_calls.h), shared
 * by the lifecycle client and the bond client. Moved from cyclone_lifecycle_client.c. */
#include "lifecycle_calls.h"

#include <inttypes.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "lifecycle_requests.h"

static const char* const kServiceNames[kServices] = {
    "change_state", "get_state", "get_available_states", "get_available_transitions"};
static const char* const kSrvNames[kServices] = {"ChangeState", "GetState", "GetAvailableStates",
                                                 "GetAvailableTransitions"};
static const dds_topic_descriptor_t* const kWrapped[kServices][2] = {
    {&vnsba_interop_lifecycle_ChangeStateRequest_desc,
     &vnsba_interop_lifecycle_ChangeStateReply_desc},
    {&vnsba_interop_lifecycle_GetStateRequest_desc, &vnsba_interop_lifecycle_GetStateReply_desc},
    {&vnsba_interop_lifecycle_GetAvailableStatesRequest_desc,
     &vnsba_interop_lifecycle_GetAvailableStatesReply_desc},
    {&vnsba_interop_lifecycle_GetAvailableTransitionsRequest_desc,
     &vnsba_interop_lifecycle_GetAvailableTransitionsReply_desc}};

const char* lifecycle_node_name = NULL;

Service lifecycle_services[kServices];
void make_lifecycle_service(Service* s, int which) {
  char name[200], request_type[128], reply_type[128];
  snprintf(name, sizeof name, "%s/%s", lifecycle_node_name, kServiceNames[which]);
  snprintf(request_type, sizeof request_type, "lifecycle_msgs::srv::dds_::%s_Request_",
           kSrvNames[which]);
  snprintf(reply_type, sizeof reply_type, "lifecycle_msgs::srv::dds_::%s_Response_",
           kSrvNames[which]);
  make_service(s, name, request_type, reply_type, kWrapped[which][0], kWrapped[which][1]);
}

static void copy_success(const void* sample, void* out) {
  *(int*)out = ((const vnsba_interop_lifecycle_ChangeStateReply*)sample)->message.success ? 1 : 0;
}

/* change_state to transition `id` (or `label` when not NULL); 1 success, 0 not, -1 no reply. */
int change_state(uint8_t id, const char* label) {
  vnsba_interop_lifecycle_ChangeStateRequest request;
  memset(&request, 0, sizeof request);
  request.message.transition.id = id;
  request.message.transition.label = (char*)(label ? label : "");
  int success = -1;
  wait_reply(&lifecycle_services[kChangeState],
             write_request(&lifecycle_services[kChangeState], &request), copy_success, &success,
             30.0);
  return success;
}

typedef struct {
  int id;
  char label[32];
} StateReply;
static void copy_state(const void* sample, void* out) {
  const vnsba_interop_lifecycle_GetStateReply* r = sample;
  StateReply* s = out;
  s->id = r->message.current_state.id;
  snprintf(s->label, sizeof s->label, "%s", r->message.current_state.label);
}

int get_state(void) {
  vnsba_interop_lifecycle_GetStateRequest request;
  memset(&request, 0, sizeof request);
  StateReply reply = {-1, ""};
  wait_reply(&lifecycle_services[kGetState],
             write_request(&lifecycle_services[kGetState], &request), copy_state, &reply, 10.0);
  return reply.id;
}
