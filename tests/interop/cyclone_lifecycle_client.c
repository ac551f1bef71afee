/* A lifecycle manager of vnsba_node on Eclipse Cyclone DDS 0.10: it calls the node's
 * lifecycle_msgs services exactly as nav2_lifecycle_manager on rmw_cyclonedds does on the wire,
 * reads its transition_event, and checks the node's work at each step (issue 48).
 * run_interop.sh starts the node (lifecycle: managed, --name) and runs this client.
 *
 *   vnsba_cyclone_lifecycle_client --domain N --node-name NAME [--namespace NS] [--self-activating]
 *
 * The wire (rcl_lifecycle/src/com_interface.c, rmw_cyclonedds): services
 * <ns>/<name>/change_state, get_state, get_available_states, get_available_transitions, each
 * rq/<ns>/<name>/<service>Request and rr/.../<service>Reply, reliable, volatile, keep last 10,
 * every payload starting with rmw_cyclonedds's request header {uint64 guid; int64 seq;}
 * (lifecycle_requests.idl); the topic rt/<ns>/<name>/transition_event
 * (lifecycle_msgs/msg/TransitionEvent; reliable, volatile, keep last 10).
 *
 * Default run (managed node; exit 1 with FAILED lines when a check fails, 2 on bad usage):
 *   unconfigured (1), available transitions configure (1) and shutdown (5), 11 states listed;
 *   configure -> success, events 1 (1 -> 10) and 10 (10 -> 2), inactive (2), transitions 2, 3, 6;
 *   a plan_request on the client's map: NODE_INACTIVE; activate by label -> active (3), events
 *   3 and 30; the plan_request planned (OK); configure from active: success false, still active;
 *   deactivate -> inactive, events 4 and 40, a plan_request NODE_INACTIVE again; cleanup ->
 *   unconfigured, events 2 and 20; shutdown by label -> finalized (4), events 5 and 50, no
 *   transition available, get_state still answered.
 * --self-activating: the node configures and activates itself: get_state says active (3) once
 *   that is done (configuring, inactive or activating before), and a plan_request is planned.
 */
#include <inttypes.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "client_common.h"
#include "dds/dds.h"
#include "lifecycle_calls.h"
#include "lifecycle_msgs/msg/TransitionEvent.h"
#include "lifecycle_requests.h"

typedef struct {
  int n;
  int ids[32];
} IdList;
static void copy_transitions(const void* sample, void* out) {
  const vnsba_interop_lifecycle_GetAvailableTransitionsReply* r = sample;
  IdList* l = out;
  l->n = 0;
  for (uint32_t i = 0; i < r->message.available_transitions._length && l->n < 32; ++i)
    l->ids[l->n++] = r->message.available_transitions._buffer[i].transition.id;
}
static void copy_states(const void* sample, void* out) {
  const vnsba_interop_lifecycle_GetAvailableStatesReply* r = sample;
  IdList* l = out;
  l->n = 0;
  for (uint32_t i = 0; i < r->message.available_states._length && l->n < 32; ++i)
    l->ids[l->n++] = r->message.available_states._buffer[i].id;
}

static void check_ids(const char* what, const IdList* got, const int* want, int n) {
  bool same = got->n == n;
  for (int i = 0; same && i < n; ++i) same = got->ids[i] == want[i];
  char text[256] = "";
  for (int i = 0; i < got->n; ++i)
    snprintf(text + strlen(text), sizeof text - strlen(text), "%s%d", i ? ", " : "", got->ids[i]);
  CHECK(same, "%s: got [%s]", what, text);
}

static void check_transitions(const char* what, const int* want, int n) {
  vnsba_interop_lifecycle_GetAvailableTransitionsRequest request;
  memset(&request, 0, sizeof request);
  IdList got = {-1, {0}};
  wait_reply(&lifecycle_services[kGetTransitions],
             write_request(&lifecycle_services[kGetTransitions], &request), copy_transitions, &got,
             10.0);
  check_ids(what, &got, want, n);
}

/* The transition_event reader's next `n` events must be `want` ({transition, start, goal}). */
static dds_entity_t events;
static TopicSpec kEvents;
static char events_name[200];
static void check_events(const char* what, const int (*want)[3], int n) {
  const double end = now_s() + 10.0;
  int got = 0;
  while (got < n && now_s() < end) {
    void* samples[8] = {NULL};
    dds_sample_info_t infos[8];
    const int k = dds_take(events, samples, infos, 8, 8);
    for (int i = 0; i < k; ++i) {
      if (!infos[i].valid_data) continue;
      const lifecycle_msgs_msg_dds__TransitionEvent_* e = samples[i];
      if (got < n)
        CHECK(e->transition.id == want[got][0] && e->start_state.id == want[got][1] &&
                  e->goal_state.id == want[got][2],
              "%s: event %d is transition %d (%d -> %d), expected %d (%d -> %d)", what, got,
              e->transition.id, e->start_state.id, e->goal_state.id, want[got][0], want[got][1],
              want[got][2]);
      else
        CHECK(false, "%s: an event more than the %d expected", what, n);
      ++got;
    }
    if (k > 0) dds_return_loan(events, samples, k);
    if (k <= 0 && got < n) wait_data(events, end);
  }
  CHECK(got == n, "%s: %d transition_event(s), expected %d", what, got, n);
}

/* A plan_request on the client's map; its status's code must be `code`. */
static void check_request(Bus* bus, const char* id, int code, const char* code_name) {
  double sx, sy, gx, gy;
  request_ends(&sx, &sy, &gx, &gy);
  const Awaited w = send_request(bus, id, sx, sy, gx, gy);
  Answer a = wait_status(bus->status, &w, 10.0);
  CHECK(a.found, "plan_request %s: no status within 10 s", id);
  if (a.found) {
    CHECK(a.code == code, "plan_request %s: %s (%s), expected %s", id, a.code_name, a.message,
          code_name);
    printf("plan_request %s: %s%s%s\n", id, a.code_name, a.message[0] ? ": " : "", a.message);
  }
  free_answer(&a);
}

int main(int argc, char** argv) {
  int domain = -1;
  bool self_activating = false;
  for (int i = 1; i < argc; ++i) {
    const char* arg = argv[i];
    const char* value = i + 1 < argc ? argv[i + 1] : NULL;
    if (strcmp(arg, "--domain") == 0 && value && parse_int(value, 0, 232, &domain)) {
      ++i;
    } else if (strcmp(arg, "--namespace") == 0 && value) {
      ros_namespace = argv[++i];
    } else if (strcmp(arg, "--node-name") == 0 && value) {
      lifecycle_node_name = argv[++i];
    } else if (strcmp(arg, "--self-activating") == 0) {
      self_activating = true;
    } else {
      fprintf(stderr,
              "%s: bad argument '%s'\nusage: %s --domain 0..232 --node-name NAME [--namespace NS]"
              " [--self-activating]\n",
              argv[0], arg, argv[0]);
      return 2;
    }
  }
  if (domain < 0 || lifecycle_node_name == NULL) {
    fprintf(stderr, "%s: --domain 0..232 and --node-name are required\n", argv[0]);
    return 2;
  }
  make_map();
  participant = dds_create_participant((dds_domainid_t)domain, NULL, NULL);
  if (participant < 0) die("cannot create the participant", participant);

  for (int s = 0; s < kServices; ++s) make_lifecycle_service(&lifecycle_services[s], s);
  snprintf(events_name, sizeof events_name, "%s/transition_event", lifecycle_node_name);
  kEvents = (TopicSpec){events_name, &lifecycle_msgs_msg_dds__TransitionEvent__desc,
                        "lifecycle_msgs::msg::dds_::TransitionEvent_", NULL};
  events = reader(&kEvents, ros_default_qos());
  /* The map (latched) and the plan_request / plan_status of the client's bus. */
  const nav_msgs_msg_dds__OccupancyGrid_ map = map_message(&client_map);
  const dds_entity_t map_writer = writer(&kMap, qos_of(true, 1));
  dds_write(map_writer, &map);
  Bus bus;
  memset(&bus, 0, sizeof bus);
  bus.request = writer(&kRequest, ros_default_qos());
  bus.status = reader(&kStatus, ros_default_qos());

  dds_entity_t lifecycle_entities[2 * kServices + 1];
  int n = 0;
  for (int s = 0; s < kServices; ++s) {
    lifecycle_entities[n++] = lifecycle_services[s].request;
    lifecycle_entities[n++] = lifecycle_services[s].reply;
  }
  lifecycle_entities[n++] = events;
  if (wait_matched(lifecycle_entities, n, 20.0) < 0) {
    fprintf(stderr, "FAILED: the node's lifecycle endpoints did not match within 20 s\n");
    return 1;
  }
  printf("lifecycle endpoints of %s matched\n", lifecycle_node_name);
  /* Discovery is not symmetric: the node's transition_event writer may match this reader a
   * little after this reader matched it, and the topic is volatile (as rcl's), so an event
   * published in between would never arrive. The node matches within milliseconds here; 1 s is
   * far beyond it. */
  dds_sleepfor(DDS_SECS(1));
  const dds_entity_t work[] = {map_writer, bus.request, bus.status};

  if (self_activating) {
    /* Its services exist from its start, before its own configure and activate end: it may
     * answer configuring (10), inactive (2) or activating (13) first, then active for good. */
    int state = get_state();
    for (const double end = now_s() + 10.0; state != 3 && now_s() < end; state = get_state())
      CHECK(state == 10 || state == 2 || state == 13,
            "a self-activating node's state is %d on its way to active", state);
    CHECK(state == 3, "a self-activating node's state is %d, expected active (3)", state);
    if (wait_matched(work, 3, 20.0) < 0) CHECK(false, "the node's work did not match within 20 s");
    check_request(&bus, "self", STATUS(OK), "OK");
    return report_run(participant, "interop lifecycle (self-activating)");
  }

  CHECK(get_state() == 1, "the managed node does not start unconfigured (1)");
  check_transitions("unconfigured's transitions", (const int[]){1, 5}, 2);
  {
    vnsba_interop_lifecycle_GetAvailableStatesRequest request;
    memset(&request, 0, sizeof request);
    IdList got = {-1, {0}};
    wait_reply(&lifecycle_services[kGetStates],
               write_request(&lifecycle_services[kGetStates], &request), copy_states, &got, 10.0);
    check_ids("get_available_states", &got, (const int[]){0, 1, 2, 3, 4, 10, 11, 12, 13, 14, 15},
              11);
  }

  CHECK(change_state(1, NULL) == 1, "configure did not succeed");
  check_events("configure", (const int[][3]){{1, 1, 10}, {10, 10, 2}}, 2);
  CHECK(get_state() == 2, "not inactive after configure");
  check_transitions("inactive's transitions", (const int[]){2, 3, 6}, 3);
  if (wait_matched(work, 3, 20.0) < 0) CHECK(false, "the node's work did not match within 20 s");
  /* The map reaches the node while it is inactive: requests wait for it at most map_wait. */
  check_request(&bus, "inactive", STATUS(NODE_INACTIVE), "NODE_INACTIVE");

  CHECK(change_state(0, "activate") == 1, "activate (by label) did not succeed");
  check_events("activate", (const int[][3]){{3, 2, 13}, {30, 13, 3}}, 2);
  CHECK(get_state() == 3, "not active after activate");
  check_request(&bus, "active", STATUS(OK), "OK");
  CHECK(change_state(1, NULL) == 0, "configure from active did not fail");
  CHECK(get_state() == 3, "not active after a refused configure");

  CHECK(change_state(4, NULL) == 1, "deactivate did not succeed");
  check_events("deactivate", (const int[][3]){{4, 3, 14}, {40, 14, 2}}, 2);
  CHECK(get_state() == 2, "not inactive after deactivate");
  check_request(&bus, "deactivated", STATUS(NODE_INACTIVE), "NODE_INACTIVE");

  CHECK(change_state(2, NULL) == 1, "cleanup did not succeed");
  check_events("cleanup", (const int[][3]){{2, 2, 11}, {20, 11, 1}}, 2);
  CHECK(get_state() == 1, "not unconfigured after cleanup");

  CHECK(change_state(0, "shutdown") == 1, "shutdown (by label) did not succeed");
  check_events("shutdown", (const int[][3]){{5, 1, 12}, {50, 12, 4}}, 2);
  CHECK(get_state() == 4, "not finalized after shutdown");
  check_transitions("finalized's transitions", NULL, 0);
  return report_run(participant, "interop lifecycle");
}
