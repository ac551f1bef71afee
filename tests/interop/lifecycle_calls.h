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
#include "service_calls.h"

enum { kChangeState, kGetState, kGetStates, kGetTransitions, kServices };

/* The managed node's name, relative to the namespace; set before make_lifecycle_service. */
extern const char* lifecycle_node_name;
/* The four services' clients (make_lifecycle_service fills one). */
extern Service lifecycle_services[kServices];
/* The client of lifecycle service `which` of lifecycle_node_name (make_service). */
void make_lifecycle_service(Service* s, int which);

/* change_state to transition `id` (or `label` when not NULL); 1 success, 0 not, -1 no reply. */
int change_state(uint8_t id, const char* label);
/* get_state: the state's id, -1 without a reply. */
int get_state(void);

#endif /* VNSBA_INTEROP_LIFECYCLE_CALLS_H */
