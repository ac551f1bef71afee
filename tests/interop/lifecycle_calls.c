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
/* rmw_cyclonedds numbers every request of the process with one counter. */
static int64_t last_sequence = 0;

void make_service(Service* s, int which) {
  memset(s, 0, sizeof *s);
  snprintf(s->request_name, sizeof s->request_name, "%s/%sRequest", lifecycle_node_name,
           kServiceNames[which]);
  snprintf(s->reply_name, sizeof s->reply_name, "%s/%sReply", lifecycle_node_name,
           kServiceNames[which]);
  snprintf(s->request_type, sizeof s->request_type, "lifecycle_msgs::srv::dds_::%s_Request_",
           kSrvNames[which]);
  snprintf(s->reply_type, sizeof s->reply_type, "lifecycle_msgs::srv::dds_::%s_Response_",
           kSrvNames[which]);
  memcpy(&s->request_desc, kWrapped[which][0], sizeof s->request_desc);
  s->request_desc.m_typename = s->request_type;
  memcpy(&s->reply_desc, kWrapped[which][1], sizeof s->reply_desc);
  s->reply_desc.m_typename = s->reply_type;
  s->request_spec = (TopicSpec){s->request_name, &s->request_desc, s->request_type, "rq/"};
  s->reply_spec = (TopicSpec){s->reply_name, &s->reply_desc, s->reply_type, "rr/"};
  s->request = writer(&s->request_spec, qos_of(false, 10)); /* services_default */
  s->reply = reader(&s->reply_spec, qos_of(false, 10));
  dds_instance_handle_t handle = 0;
  if (dds_get_instance_handle(s->request, &handle) != DDS_RETCODE_OK) die("instance handle", -1);
  s->guid = handle;
}

/* Writes `sample` (a wrapped request) with its header; returns the sequence number. */
int64_t write_request(Service* s, void* sample) {
  vnsba_interop_lifecycle_RequestHeader* h = sample;
  h->guid = s->guid;
  h->seq = ++last_sequence;
  const dds_return_t rc = dds_write(s->request, sample);
  CHECK(rc == DDS_RETCODE_OK, "writing rq/.../%s: %s", s->request_name, dds_strretcode(-rc));
  return h->seq;
}

/* Takes the reply carrying (s->guid, seq) within `timeout` s; `copy` copies what is needed out
 * of it into `out`. Any other reply is the server's mistake (only this client asks here). */
bool wait_reply(Service* s, int64_t seq, CopyReply copy, void* out, double timeout) {
  const double end = now_s() + timeout;
  for (;;) {
    void* samples[8] = {NULL};
    dds_sample_info_t infos[8];
    const int n = dds_take(s->reply, samples, infos, 8, 8);
    bool found = false;
    for (int i = 0; i < n; ++i) {
      if (!infos[i].valid_data) continue;
      const vnsba_interop_lifecycle_RequestHeader* h = samples[i];
      if (h->guid == s->guid && h->seq == seq && !found) {
        copy(samples[i], out);
        found = true;
      } else {
        CHECK(false,
              "rr/.../%s: a reply with header (0x%016" PRIx64 ", %" PRId64
              "), expected (0x%016" PRIx64 ", %" PRId64 ")",
              s->reply_name, h->guid, h->seq, s->guid, seq);
      }
    }
    if (n > 0) dds_return_loan(s->reply, samples, n);
    if (found) return true;
    if (now_s() >= end) {
      CHECK(false, "rr/.../%s: no reply to request %" PRId64 " within %.0f s", s->reply_name, seq,
            timeout);
      return false;
    }
    if (n <= 0) wait_data(s->reply, end);
  }
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
