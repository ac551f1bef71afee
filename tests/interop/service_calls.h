/* A ROS 2 service client as rmw_cyclonedds makes it, for the interop clients of plain services
 * (lifecycle_calls.c, cyclone_distro_client.c): a request writer on rq/<ns>/<name>Request and a
 * reply reader on rr/<ns>/<name>Reply, reliable, volatile, keep last 10
 * (rmw_qos_profile_services_default), every payload starting with rmw_cyclonedds's request header
 * {uint64 guid; int64 seq;}: the guid the request writer's instance handle, seq one counter of
 * the process. The request and reply types are this folder's wrapped types (the header, then the
 * ROS 2 message), their descriptors copied under the ROS 2 type names. */
#ifndef VNSBA_INTEROP_SERVICE_CALLS_H
#define VNSBA_INTEROP_SERVICE_CALLS_H

#include <stdbool.h>
#include <stdint.h>

#include "client_common.h"
#include "dds/dds.h"

/* One service client. */
typedef struct {
  char request_name[200], reply_name[200]; /* ROS names relative to the namespace */
  char request_type[128], reply_type[128];
  dds_topic_descriptor_t request_desc, reply_desc;
  TopicSpec request_spec, reply_spec;
  dds_entity_t request, reply;
  uint64_t guid; /* the request writer's instance handle */
} Service;

/* The client of service `name` (relative to the namespace, e.g. "is_path_valid" or
 * "planner_server/get_state"), the wrapped descriptors renamed to `request_type`/`reply_type`. */
void make_service(Service* s, const char* name, const char* request_type, const char* reply_type,
                  const dds_topic_descriptor_t* wrapped_request,
                  const dds_topic_descriptor_t* wrapped_reply);

/* Writes `sample` (a wrapped request, its header first) with its header; its sequence number. */
int64_t write_request(Service* s, void* sample);

/* Takes the reply carrying (s->guid, seq) within `timeout` s; `copy` copies what is needed out
 * of it into `out`. Any other reply is the server's mistake (only this client asks here). */
typedef void (*CopyReply)(const void* sample, void* out);
bool wait_reply(Service* s, int64_t seq, CopyReply copy, void* out, double timeout);

#endif /* VNSBA_INTEROP_SERVICE_CALLS_H */
