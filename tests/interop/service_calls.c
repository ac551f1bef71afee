/* rmw_cyclonedds's service clients (service_calls.h). */
#include "service_calls.h"

#include <inttypes.h>
#include <stdio.h>
#include <string.h>

#include "check.h"

/* rmw_cyclonedds's request header, at the start of every wrapped request and reply. */
typedef struct {
  uint64_t guid;
  int64_t seq;
} RequestHeader;

/* rmw_cyclonedds numbers every request of the process with one counter. */
static int64_t last_sequence = 0;

void make_service(Service* s, const char* name, const char* request_type, const char* reply_type,
                  const dds_topic_descriptor_t* wrapped_request,
                  const dds_topic_descriptor_t* wrapped_reply) {
  memset(s, 0, sizeof *s);
  snprintf(s->request_name, sizeof s->request_name, "%sRequest", name);
  snprintf(s->reply_name, sizeof s->reply_name, "%sReply", name);
  snprintf(s->request_type, sizeof s->request_type, "%s", request_type);
  snprintf(s->reply_type, sizeof s->reply_type, "%s", reply_type);
  /* A copy of the generated descriptor under the ROS 2 type name (its members are const). */
  memcpy(&s->request_desc, wrapped_request, sizeof s->request_desc);
  s->request_desc.m_typename = s->request_type;
  memcpy(&s->reply_desc, wrapped_reply, sizeof s->reply_desc);
  s->reply_desc.m_typename = s->reply_type;
  s->request_spec = (TopicSpec){s->request_name, &s->request_desc, s->request_type, "rq/"};
  s->reply_spec = (TopicSpec){s->reply_name, &s->reply_desc, s->reply_type, "rr/"};
  s->request = writer(&s->request_spec, qos_of(false, 10)); /* services' default QoS */
  s->reply = reader(&s->reply_spec, qos_of(false, 10));
  dds_instance_handle_t handle = 0;
  if (dds_get_instance_handle(s->request, &handle) != DDS_RETCODE_OK) die("instance handle", -1);
  s->guid = handle;
}

int64_t write_request(Service* s, void* sample) {
  RequestHeader* h = sample;
  h->guid = s->guid;
  h->seq = ++last_sequence;
  const dds_return_t rc = dds_write(s->request, sample);
  CHECK(rc == DDS_RETCODE_OK, "writing rq/.../%s: %s", s->request_name, dds_strretcode(-rc));
  return h->seq;
}

bool wait_reply(Service* s, int64_t seq, CopyReply copy, void* out, double timeout) {
  const double end = now_s() + timeout;
  for (;;) {
    void* samples[8] = {NULL};
    dds_sample_info_t infos[8];
    const int n = dds_take(s->reply, samples, infos, 8, 8);
    bool found = false;
    for (int i = 0; i < n; ++i) {
      if (!infos[i].valid_data) continue;
      const RequestHeader* h = samples[i];
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
