/* A managed node's lifecycle services called as rmw_cyclonedds calls them (issue 48): each
 * service rq/<ns>/<node>/<service>Request -> rr/.../<service>Reply, reliable, volatile, keep last
 * 10 (rmw_qos_profile_services_default), every payload starting with rmw_cyclonedds's request
 * header {uint64 guid; int64 seq;} (lifecycle_requests.idl), the guid the request writer's
 * instance handle, seq one counter of the process. Shared by cyclone_lifecycle_client.c (the
 * whole lifecycle walk) and cyclone_bond_client.c (nav2_lifecycle_manager's bringup). */
#ifndef VNSBA_INTEROP_LIFECYCLE_CALLS_H
#define VNSBA_INTEROP_LIFECYCLE_CALLS_H

#include <stdbool.h>
#include <stdint.h>

#include "client_common.h"
#include "dds/dds.h"

enum { kChangeState, kGetState, kGetStates, kGetTransitions, kServices };

/* One service client, as rmw_cyclonedds makes it. */
typedef struct {
  char request_name[200], reply_name[200]; /* ROS names relative to the namespace */
  char request_type[128], reply_type[128];
  dds_topic_descriptor_t request_desc, reply_desc;
  TopicSpec request_spec, reply_spec;
  dds_entity_t request, reply;
  uint64_t guid; /* the request writer's instance handle */
} Service;

/* The managed node's name, relative to the namespace; set before make_service. */
extern const char* lifecycle_node_name;
/* The four services' clients (make_service fills one). */
extern Service lifecycle_services[kServices];
void make_service(Service* s, int which);

/* Writes `sample` (a wrapped request) with its header; returns the sequence number. */
int64_t write_request(Service* s, void* sample);
/* Takes the reply carrying (s->guid, seq) within `timeout` s; `copy` copies what is needed out
 * of it into `out`. Any other reply is the server's mistake (only this client asks here). */
typedef void (*CopyReply)(const void* sample, void* out);
bool wait_reply(Service* s, int64_t seq, CopyReply copy, void* out, double timeout);

/* change_state to transition `id` (or `label` when not NULL); 1 success, 0 not, -1 no reply. */
int change_state(uint8_t id, const char* label);
/* get_state: the state's id, -1 without a reply. */
int get_state(void);

#endif /* VNSBA_INTEROP_LIFECYCLE_CALLS_H */
