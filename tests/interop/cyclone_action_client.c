/* A Nav2 client of vnsba_node's action servers on Eclipse Cyclone DDS 0.10, calling
 * nav2_msgs/action/ComputePathToPose and ComputePathThroughPoses exactly as a ROS 2 node on
 * rmw_cyclonedds (rclcpp_action over rcl_action) does on the wire, and checking what comes back
 * against the client's own map with its own line walk (grid_oracle.c). run_interop.sh starts the
 * node and runs this client (issue 32, item 6).
 *
 *   vnsba_cyclone_action_client --domain N [--namespace NS]
 *                               [--wire | --cancel | --bench N |
 *                                --fresh N [--fresh-parallel P] [--fresh-resident]]
 *
 * The wire, as rcl_action and rmw_cyclonedds (jazzy) put it: an action <name> is three services,
 * <name>/_action/send_goal, get_result and cancel_goal, each the DDS topics
 * rq/<ns>/<name>/_action/<service>Request (the client writes) and .../<service>Reply (it reads),
 * reliable, volatile, keep last 10 (rmw_qos_profile_services_default); and two topics,
 * rt/<ns>/<name>/_action/status (action_msgs/GoalStatusArray; reliable, transient local, keep
 * last 1) and .../feedback (reliable, volatile, keep last 10). Each request payload starts with
 * rmw_cyclonedds's request header {uint64 guid; int64 seq;}: guid the request writer's instance
 * handle, seq one counter of the process for every request; a reply carries the same 16 bytes and
 * is matched to its request by them (rmw_cyclonedds_requests.idl). The request writer and reply
 * reader of each service carry "clientid=<id>;" in their USER_DATA, as rmw_cyclonedds's do.
 *
 * Default run (exit 1 with FAILED lines on stderr when a check fails, 2 on bad usage), on the
 * client's map (client_common.h), the node configured with planner.goal_tolerance 0:
 *   - the node's endpoints of both actions announce the ROS 2 type names and match the client's;
 *   - ComputePathToPose from cell (5, 3) to (34, 3) with use_start: accepted, get_result sent
 *     right after acceptance; status SUCCEEDED (4), error_code 0, the path from the start to the
 *     goal within 1e-4 m, every segment free by the oracle's exact line walk, poses at most one
 *     cell apart; the reply's bytes carry the request's header back in XCDR1; the status topic
 *     shows the goal SUCCEEDED, also to a reader created after it ended (transient local);
 *   - use_start false: the start is the pose last written on robot_pose; the last pose faces the
 *     goal's yaw;
 *   - a goal inside the wall: ABORTED (6) with GOAL_OCCUPIED (206);
 *   - planner_id "no_such_planner": ABORTED with INVALID_PLANNER (201), error_msg naming "astar";
 *   - ComputePathThroughPoses through (34, 3) to (5, 26), crossing the wall twice: SUCCEEDED,
 *     a pose within 1e-4 m of each goal in order, the path checked as above; with an empty list:
 *     ABORTED with NO_VIAPOINTS_GIVEN (309);
 *   - get_result of a goal id the server never saw: status UNKNOWN (0); cancel_goal of it:
 *     ERROR_UNKNOWN_GOAL_ID (2); cancel_goal of a goal that ended: ERROR_GOAL_TERMINATED (3) with
 *     no goal listed (rcl_action_process_cancel_request's codes).
 * --cancel: a 2000 x 2000 map of 0.1 m cells, three walls across it leaving a serpentine of four
 *   lanes (make_maze), so exact A* (planner_id astar) expands most of its 4 million cells:
 *   - a goal whose get_result is sent right after acceptance and acknowledged by the node while
 *     the status topic still shows the goal running gets the final result when the plan ends
 *     (SUCCEEDED, the path checked against the maze);
 *   - a goal cancelled once the status topic shows it EXECUTING (2): cancel_goal answers
 *     ERROR_NONE (0) listing the goal, get_result then says CANCELED (5), and the status topic
 *     (also to a late reader) shows CANCELED.
 * --bench N: measurements, nothing asserted beyond every plan succeeding: N ComputePathToPose
 *   round trips one at a time (send_goal -> accepted -> get_result -> result, as rclcpp_action
 *   calls them), each next to a plan_request -> plan_status round trip for the same plan;
 *   p50/p90 of both and of their difference.
 * --fresh N: fresh clients' first goals (issue 44): the map latched on the node, then N fresh
 *   client processes (this executable with --fresh-client), P at a time (--fresh-parallel P,
 *   default 1), each a new participant with one ComputePathToPose client that sends its goal on
 *   the client's map the moment every entity rcl_action_server_is_available() checks is matched
 *   (as `ros2 action send_goal` and a freshly loaded BT node do: no settle time) and get_result
 *   right after the acceptance. Every one must get the send_goal reply and the get_result reply
 *   within 10 s each, the result SUCCEEDED (or, several at a time, ABORTED: preempted by another
 *   client's goal); a lost reply fails the run, naming the client's participant.
 *   --fresh-resident: this process keeps an idle ComputePathToPose client of its own matched
 *   throughout, as a navigator does.
 * --wire: no node; the serialisation alone: each wrapped type serialises as the 16-byte header
 *   followed by the ROS message's own serialisation, byte for byte; the service writers put
 *   their instance handle and increasing sequence numbers in the first 16 bytes after the
 *   encapsulation, and "clientid=" in their USER_DATA.
 */
#include <inttypes.h>
#include <math.h>
#include <spawn.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <sys/wait.h>
#include <unistd.h>

#include "action_msgs/msg/GoalStatusArray.h"
#include "check.h"
#include "client_common.h"
#include "dds/dds.h"
#include "dds/ddsi/ddsi_serdata.h"
#include "rmw_cyclonedds_requests.h"

extern char** environ;

/* action_msgs/msg/GoalStatus's states. */
enum {
  kStateUnknown = 0,
  kStateAccepted = 1,
  kStateExecuting = 2,
  kStateCanceling = 3,
  kStateSucceeded = 4,
  kStateCanceled = 5,
  kStateAborted = 6
};
/* action_msgs/srv/CancelGoal's return codes. */
enum { kCancelNone = 0, kCancelRejected = 1, kCancelUnknownGoal = 2, kCancelTerminated = 3 };
/* nav2_msgs/action/ComputePathToPose's error codes (ROS 2 Jazzy); ComputePathThroughPoses's are
 * the same plus 100, and 309 NO_VIAPOINTS_GIVEN. */
enum { kNavNone = 0, kInvalidPlanner = 201, kGoalOccupied = 206, kNoViapointsGiven = 309 };

static bool is_terminal(int state) {
  return state == kStateSucceeded || state == kStateCanceled || state == kStateAborted;
}

/* ---------------------------------------------------------------------------------------------
 * The two actions' types. */

enum { kSendGoal, kGetResult, kCancelGoal, kServices };
static const char* const kServiceNames[kServices] = {"send_goal", "get_result", "cancel_goal"};

typedef struct {
  const char* action;   /* the node's default action name (topics.compute_path_*) */
  const char* ros_type; /* "ComputePathToPose" */
  bool through_poses;
  int error_offset; /* added to ComputePathToPose's error codes: 0 or 100 */
  /* Per service: the wrapped request and reply (header + message) and the messages alone. */
  const dds_topic_descriptor_t* wrapped[kServices][2];
  const dds_topic_descriptor_t* plain[kServices][2];
  const dds_topic_descriptor_t* feedback;
} ActionType;

static const ActionType kToPose = {
    "compute_path_to_pose",
    "ComputePathToPose",
    false,
    0,
    {{&vnsba_interop_ToPoseSendGoalRequest_desc, &vnsba_interop_ToPoseSendGoalReply_desc},
     {&vnsba_interop_ToPoseGetResultRequest_desc, &vnsba_interop_ToPoseGetResultReply_desc},
     {&vnsba_interop_CancelGoalRequest_desc, &vnsba_interop_CancelGoalReply_desc}},
    {{&nav2_msgs_action_dds__ComputePathToPose_SendGoal_Request__desc,
      &nav2_msgs_action_dds__ComputePathToPose_SendGoal_Response__desc},
     {&nav2_msgs_action_dds__ComputePathToPose_GetResult_Request__desc,
      &nav2_msgs_action_dds__ComputePathToPose_GetResult_Response__desc},
     {&action_msgs_srv_dds__CancelGoal_Request__desc,
      &action_msgs_srv_dds__CancelGoal_Response__desc}},
    &nav2_msgs_action_dds__ComputePathToPose_FeedbackMessage__desc};

static const ActionType kThroughPoses = {
    "compute_path_through_poses",
    "ComputePathThroughPoses",
    true,
    100,
    {{&vnsba_interop_ThroughPosesSendGoalRequest_desc,
      &vnsba_interop_ThroughPosesSendGoalReply_desc},
     {&vnsba_interop_ThroughPosesGetResultRequest_desc,
      &vnsba_interop_ThroughPosesGetResultReply_desc},
     {&vnsba_interop_CancelGoalRequest_desc, &vnsba_interop_CancelGoalReply_desc}},
    {{&nav2_msgs_action_dds__ComputePathThroughPoses_SendGoal_Request__desc,
      &nav2_msgs_action_dds__ComputePathThroughPoses_SendGoal_Response__desc},
     {&nav2_msgs_action_dds__ComputePathThroughPoses_GetResult_Request__desc,
      &nav2_msgs_action_dds__ComputePathThroughPoses_GetResult_Response__desc},
     {&action_msgs_srv_dds__CancelGoal_Request__desc,
      &action_msgs_srv_dds__CancelGoal_Response__desc}},
    &nav2_msgs_action_dds__ComputePathThroughPoses_FeedbackMessage__desc};

/* The ROS 2 type name of a service's request (reply false) or reply (true) message, as
 * rosidl's DDS names go: "nav2_msgs::action::dds_::ComputePathToPose_SendGoal_Request_",
 * "action_msgs::srv::dds_::CancelGoal_Response_". */
static void service_type_name(const ActionType* t, int service, bool reply, char* out, size_t n) {
  const char* kind = reply ? "Response" : "Request";
  if (service == kCancelGoal)
    snprintf(out, n, "action_msgs::srv::dds_::CancelGoal_%s_", kind);
  else
    snprintf(out, n, "nav2_msgs::action::dds_::%s_%s_%s_", t->ros_type,
             service == kSendGoal ? "SendGoal" : "GetResult", kind);
}

/* ---------------------------------------------------------------------------------------------
 * rmw_cyclonedds's service clients. */

/* rmw_cyclonedds numbers the requests of every client of a process with one counter
 * (rmw_send_request: static next_request_id), so each client's are increasing. */
static int64_t last_sequence = 0;
/* rmw_cyclonedds's per-participant counter of client and service ids (get_unique_csid). */
static uint32_t last_client_id = 0;

typedef struct {
  char request_name[200], reply_name[200]; /* ROS names relative to the namespace */
  char request_type[128], reply_type[128];
  dds_topic_descriptor_t request_desc, reply_desc; /* the wrapped types under the ROS names */
  TopicSpec request_spec, reply_spec;
  dds_entity_t request, reply; /* writer on rq/..., reader on rr/... */
  uint64_t guid;               /* the request writer's instance handle */
} Service;

/* rmw_cyclonedds's id of a client (get_unique_csid): the participant's GUID prefix and a
 * big-endian counter, in USER_DATA as "clientid=" + csid_to_string (first byte two hex digits,
 * then '.' and each further byte in hex) + ";". */
static void client_user_data(char* out, size_t n) {
  const dds_guid_t p = guid_of(participant);
  uint8_t id[16];
  memcpy(id, p.v, 12);
  const uint32_t x = ++last_client_id;
  for (int i = 0; i < 4; ++i) id[12 + i] = (uint8_t)(x >> (24 - 8 * i));
  int k = snprintf(out, n, "clientid=%02x", id[0]);
  for (int i = 1; i < 16 && k > 0 && (size_t)k < n; ++i)
    k += snprintf(out + k, n - (size_t)k, ".%x", id[i]);
  if (k > 0 && (size_t)k < n) snprintf(out + k, n - (size_t)k, ";");
}

static dds_qos_t* service_qos(const char* user_data) {
  dds_qos_t* qos = qos_of(false, 10); /* rmw_qos_profile_services_default */
  dds_qset_userdata(qos, user_data, strlen(user_data));
  return qos;
}

/* A copy of a generated descriptor under another type name (the descriptor's other members are
 * const, so the copy is made byte for byte). */
static void rename_descriptor(dds_topic_descriptor_t* out, const dds_topic_descriptor_t* from,
                              const char* type_name) {
  memcpy(out, from, sizeof *out);
  out->m_typename = type_name;
}

static void make_service(Service* s, const ActionType* t, const char* action, int service) {
  memset(s, 0, sizeof *s);
  snprintf(s->request_name, sizeof s->request_name, "%s/_action/%sRequest", action,
           kServiceNames[service]);
  snprintf(s->reply_name, sizeof s->reply_name, "%s/_action/%sReply", action,
           kServiceNames[service]);
  service_type_name(t, service, false, s->request_type, sizeof s->request_type);
  service_type_name(t, service, true, s->reply_type, sizeof s->reply_type);
  rename_descriptor(&s->request_desc, t->wrapped[service][0], s->request_type);
  rename_descriptor(&s->reply_desc, t->wrapped[service][1], s->reply_type);
  s->request_spec = (TopicSpec){s->request_name, &s->request_desc, s->request_type, "rq/"};
  s->reply_spec = (TopicSpec){s->reply_name, &s->reply_desc, s->reply_type, "rr/"};
  char user_data[96];
  client_user_data(user_data, sizeof user_data);
  s->request = writer(&s->request_spec, service_qos(user_data));
  s->reply = reader(&s->reply_spec, service_qos(user_data));
  dds_instance_handle_t handle = 0;
  if (dds_get_instance_handle(s->request, &handle) != DDS_RETCODE_OK) die("instance handle", -1);
  s->guid = handle;
}

/* Writes a request: `sample` is a wrapped type (its header first), the header is filled in here.
 * Returns its sequence number. */
static int64_t write_request(Service* s, void* sample) {
  vnsba_interop_RequestHeader* h = sample;
  h->guid = s->guid;
  h->seq = ++last_sequence;
  const dds_return_t rc = dds_write(s->request, sample);
  CHECK(rc == DDS_RETCODE_OK, "writing rq/.../%s: %s", s->request_name, dds_strretcode(-rc));
  return h->seq;
}

typedef struct Action Action;
/* Copies what a caller needs out of a reply sample (a wrapped type) into `out`. */
typedef void (*CopyReply)(const Action* a, const void* sample, void* out);

/* Whether replies to other clients are skipped, as rmw_take_response skips them (a --fresh
 * client: other fresh clients may ask in the same namespace at the same time). */
static bool skip_foreign_replies = false;

/* Waits for the reply to request `seq` of `s`: the one whose header is (s->guid, seq), as
 * rmw_cyclonedds takes a reply (rmw_take_response filters on the guid, rcl on the sequence
 * number). Only this client asks in this run's namespace (except with skip_foreign_replies), so
 * any other reply is the server's mistake and fails the run. Returns the time it came
 * (monotonic s), or a negative number. */
static double wait_reply(const Action* a, Service* s, int64_t seq, CopyReply copy, void* out,
                         double timeout) {
  const double end = now_s() + timeout;
  for (;;) {
    void* samples[8] = {NULL};
    dds_sample_info_t infos[8];
    const int n = dds_take(s->reply, samples, infos, 8, 8);
    double found = -1;
    for (int i = 0; i < n; ++i) {
      if (!infos[i].valid_data) continue;
      const vnsba_interop_RequestHeader* h = samples[i];
      if (h->guid == s->guid && h->seq == seq && found < 0) {
        copy(a, samples[i], out);
        found = now_s();
      } else if (!(skip_foreign_replies && h->guid != s->guid)) {
        CHECK(false,
              "rr/.../%s: a reply with header (guid 0x%016" PRIx64 ", seq %" PRId64
              "), not that of the request in flight (guid 0x%016" PRIx64 ", seq %" PRId64 ")",
              s->reply_name, h->guid, h->seq, s->guid, seq);
      }
    }
    if (n > 0) dds_return_loan(s->reply, samples, n);
    if (found >= 0) return found;
    if (now_s() >= end) {
      CHECK(false,
            "rr/.../%s: no reply carrying the request's header (guid 0x%016" PRIx64 ", seq %" PRId64
            ") within %.0f s",
            s->reply_name, s->guid, seq, timeout);
      return -1;
    }
    if (n <= 0) wait_data(s->reply, end);
  }
}

/* ---------------------------------------------------------------------------------------------
 * An action client: three services and two topic readers. */

struct Action {
  const ActionType* type;
  Service service[kServices];
  char status_name[200], feedback_name[200], feedback_type[128];
  TopicSpec status_spec, feedback_spec;
  dds_entity_t status, feedback;
};

/* rcl_action_qos_profile_status_default: reliable, transient local, keep last 1. */
static dds_qos_t* status_qos(void) {
  return qos_of(true, 1);
}

static void make_action(Action* a, const ActionType* t) {
  memset(a, 0, sizeof *a);
  a->type = t;
  for (int s = 0; s < kServices; ++s) make_service(&a->service[s], t, t->action, s);
  snprintf(a->status_name, sizeof a->status_name, "%s/_action/status", t->action);
  snprintf(a->feedback_name, sizeof a->feedback_name, "%s/_action/feedback", t->action);
  snprintf(a->feedback_type, sizeof a->feedback_type,
           "nav2_msgs::action::dds_::%s_FeedbackMessage_", t->ros_type);
  a->status_spec = (TopicSpec){a->status_name, &action_msgs_msg_dds__GoalStatusArray__desc,
                               "action_msgs::msg::dds_::GoalStatusArray_", NULL};
  a->feedback_spec = (TopicSpec){a->feedback_name, t->feedback, a->feedback_type, NULL};
  a->status = reader(&a->status_spec, status_qos());
  a->feedback = reader(&a->feedback_spec, ros_default_qos()); /* rmw_qos_profile_default */
}

/* The entities rclcpp_action waits for before it calls (rcl_action_server_is_available: every
 * service's request writer and reply reader matched, and the status and feedback readers). */
static int action_entities(const Action* a, dds_entity_t* out) {
  int n = 0;
  for (int s = 0; s < kServices; ++s) {
    out[n++] = a->service[s].request;
    out[n++] = a->service[s].reply;
  }
  out[n++] = a->status;
  out[n++] = a->feedback;
  return n;
}

/* The node's endpoints of the action as announced in discovery carry the ROS 2 type names. */
static void check_action_types(const Action* a, dds_entity_t publications,
                               dds_entity_t subscriptions) {
  int announced = 0;
  for (int s = 0; s < kServices; ++s) {
    const int readers = check_remote_type_names(subscriptions, &a->service[s].request_spec);
    const int writers = check_remote_type_names(publications, &a->service[s].reply_spec);
    CHECK(readers > 0 && writers > 0,
          "%s: the node announces %d request reader(s) and %d reply writer(s) of %s",
          a->type->action, readers, writers, kServiceNames[s]);
    announced += readers + writers;
  }
  const int status = check_remote_type_names(publications, &a->status_spec);
  const int feedback = check_remote_type_names(publications, &a->feedback_spec);
  CHECK(status > 0 && feedback > 0, "%s: the node announces %d status and %d feedback writer(s)",
        a->type->action, status, feedback);
  printf("types: %s: %d endpoints of the node announce the ROS 2 type names\n", a->type->action,
         announced + status + feedback);
}

/* ---------------------------------------------------------------------------------------------
 * Goals, results, cancels. */

typedef struct {
  uint8_t uuid[16];
} GoalId;

/* 16 random bytes, as rclcpp_action's generate_goal_id. */
static GoalId new_goal_id(void) {
  GoalId id;
  if (getrandom(id.uuid, sizeof id.uuid, 0) != (ssize_t)sizeof id.uuid) die("getrandom", -1);
  return id;
}

typedef struct {
  double sx, sy; /* the start, metres (used with use_start) */
  int n;         /* goals: 1 for ComputePathToPose, 0..kMaxGoals for ComputePathThroughPoses */
  double gx[4], gy[4], yaw[4]; /* metres, radians */
  const char* planner_id;      /* "" for the node's default */
  bool use_start;
} GoalSpec;
enum { kMaxGoals = 4 };

static int64_t send_goal(Action* a, const GoalId* id, const GoalSpec* g) {
  geometry_msgs_msg_dds__PoseStamped_ start, goals[kMaxGoals];
  set_pose(&start, g->sx, g->sy, 0.0);
  for (int i = 0; i < g->n && i < kMaxGoals; ++i)
    set_pose(&goals[i], g->gx[i], g->gy[i], g->yaw[i]);
  Service* s = &a->service[kSendGoal];
  if (!a->type->through_poses) {
    vnsba_interop_ToPoseSendGoalRequest r;
    memset(&r, 0, sizeof r);
    memcpy(r.message.goal_id.uuid, id->uuid, 16);
    r.message.goal.goal = goals[0];
    r.message.goal.start = start;
    r.message.goal.planner_id = (char*)g->planner_id;
    r.message.goal.use_start = g->use_start;
    return write_request(s, &r);
  }
  vnsba_interop_ThroughPosesSendGoalRequest r;
  memset(&r, 0, sizeof r);
  memcpy(r.message.goal_id.uuid, id->uuid, 16);
  r.message.goal.goals._length = r.message.goal.goals._maximum = (uint32_t)g->n;
  r.message.goal.goals._buffer = g->n > 0 ? goals : NULL;
  r.message.goal.goals._release = false;
  r.message.goal.start = start;
  r.message.goal.planner_id = (char*)g->planner_id;
  r.message.goal.use_start = g->use_start;
  return write_request(s, &r);
}

typedef struct {
  bool accepted;
  int32_t sec; /* the reply's stamp */
  uint32_t nanosec;
} Acceptance;

static void copy_acceptance(const Action* a, const void* sample, void* out) {
  Acceptance* acc = out;
  if (a->type->through_poses) {
    const vnsba_interop_ThroughPosesSendGoalReply* r = sample;
    *acc = (Acceptance){r->message.accepted, r->message.stamp.sec, r->message.stamp.nanosec};
  } else {
    const vnsba_interop_ToPoseSendGoalReply* r = sample;
    *acc = (Acceptance){r->message.accepted, r->message.stamp.sec, r->message.stamp.nanosec};
  }
}

static int64_t send_get_result(Action* a, const GoalId* id) {
  if (a->type->through_poses) {
    vnsba_interop_ThroughPosesGetResultRequest r;
    memset(&r, 0, sizeof r);
    memcpy(r.message.goal_id.uuid, id->uuid, 16);
    return write_request(&a->service[kGetResult], &r);
  }
  vnsba_interop_ToPoseGetResultRequest r;
  memset(&r, 0, sizeof r);
  memcpy(r.message.goal_id.uuid, id->uuid, 16);
  return write_request(&a->service[kGetResult], &r);
}

typedef struct {
  int status; /* action_msgs/GoalStatus */
  int error_code;
  char error_msg[512];
  double planning_time; /* s */
  Path path;
} Result;

static void fill_result(Result* r, int8_t status, const nav_msgs_msg_dds__Path_* path,
                        const builtin_interfaces_msg_dds__Duration_* t, uint16_t code,
                        const char* msg) {
  r->status = status;
  r->error_code = code;
  snprintf(r->error_msg, sizeof r->error_msg, "%s", msg ? msg : "");
  r->planning_time = t->sec + 1e-9 * t->nanosec;
  copy_path(path, &r->path);
}

static void copy_result(const Action* a, const void* sample, void* out) {
  if (a->type->through_poses) {
    const vnsba_interop_ThroughPosesGetResultReply* r = sample;
    fill_result(out, r->message.status, &r->message.result.path, &r->message.result.planning_time,
                r->message.result.error_code, r->message.result.error_msg);
  } else {
    const vnsba_interop_ToPoseGetResultReply* r = sample;
    fill_result(out, r->message.status, &r->message.result.path, &r->message.result.planning_time,
                r->message.result.error_code, r->message.result.error_msg);
  }
}

/* A zero-stamped GoalInfo with the goal's id: cancel exactly that goal (rclcpp_action's
 * async_cancel_goal). */
static int64_t send_cancel(Action* a, const GoalId* id) {
  vnsba_interop_CancelGoalRequest r;
  memset(&r, 0, sizeof r);
  memcpy(r.message.goal_info.goal_id.uuid, id->uuid, 16);
  return write_request(&a->service[kCancelGoal], &r);
}

typedef struct {
  int return_code;
  int n; /* goals_canceling */
  GoalId goals[8];
} CancelReply;

static void copy_cancel(const Action* a, const void* sample, void* out) {
  (void)a;
  const vnsba_interop_CancelGoalReply* r = sample;
  CancelReply* c = out;
  c->return_code = r->message.return_code;
  c->n = (int)r->message.goals_canceling._length;
  for (int i = 0; i < c->n && i < 8; ++i)
    memcpy(c->goals[i].uuid, r->message.goals_canceling._buffer[i].goal_id.uuid, 16);
}

static bool lists_goal(const CancelReply* c, const GoalId* id) {
  for (int i = 0; i < c->n && i < 8; ++i)
    if (memcmp(c->goals[i].uuid, id->uuid, 16) == 0) return true;
  return false;
}

/* One goal as rclcpp_action calls it: send_goal, and once accepted, get_result. Returns false
 * (checked failures) when there is no acceptance or no result within `timeout` seconds. */
typedef struct {
  GoalId id;
  int64_t goal_seq; /* the send_goal request's sequence number */
  Acceptance acceptance;
  Result result;
  double sent, accepted_at, result_at; /* monotonic s */
} Call;

static bool call_goal(Action* a, const GoalSpec* g, Call* c, double timeout) {
  memset(c, 0, sizeof *c);
  c->id = new_goal_id();
  c->sent = now_s();
  c->goal_seq = send_goal(a, &c->id, g);
  c->accepted_at =
      wait_reply(a, &a->service[kSendGoal], c->goal_seq, copy_acceptance, &c->acceptance, 5.0);
  if (c->accepted_at < 0) return false;
  CHECK(c->acceptance.accepted, "%s: goal not accepted", a->type->action);
  if (!c->acceptance.accepted) return false;
  const int64_t result_seq = send_get_result(a, &c->id);
  c->result_at =
      wait_reply(a, &a->service[kGetResult], result_seq, copy_result, &c->result, timeout);
  return c->result_at >= 0;
}

/* ---------------------------------------------------------------------------------------------
 * The status topic. */

/* What the status topic said of one goal. */
typedef struct {
  GoalId id;
  int latest;    /* last state seen, -1 before any */
  unsigned seen; /* bit s: state s seen */
} Track;

static Track track(const GoalId* id) {
  Track t = {*id, -1, 0};
  return t;
}

/* Takes every GoalStatusArray `r` holds, noting the goal's state in each that lists it. */
static void poll_status(dds_entity_t r, Track* t) {
  void* samples[8] = {NULL};
  dds_sample_info_t infos[8];
  int n;
  while ((n = dds_take(r, samples, infos, 8, 8)) > 0) {
    for (int i = 0; i < n; ++i) {
      if (!infos[i].valid_data) continue;
      const action_msgs_msg_dds__GoalStatusArray_* array = samples[i];
      for (uint32_t k = 0; k < array->status_list._length; ++k) {
        const action_msgs_msg_dds__GoalStatus_* s = &array->status_list._buffer[k];
        if (memcmp(s->goal_info.goal_id.uuid, t->id.uuid, 16) != 0) continue;
        t->latest = s->status;
        if (s->status >= 0 && s->status < 32) t->seen |= 1u << s->status;
      }
    }
    dds_return_loan(r, samples, n);
  }
}

/* Until the status topic shows the goal in a state `want` accepts, or `until` passes. */
static bool wait_state(dds_entity_t r, Track* t, bool (*want)(int), double until) {
  for (;;) {
    poll_status(r, t);
    if (t->latest >= 0 && want(t->latest)) return true;
    if (now_s() >= until) return false;
    wait_data(r, until);
  }
}

static bool is_executing(int state) {
  return state == kStateExecuting;
}

/* A status reader created now, after the goal ended, still gets the array listing it in its
 * terminal state: the status writer is transient local. */
static void check_latched_state(const Action* a, const GoalId* id, int want, const char* what) {
  const dds_entity_t late = reader(&a->status_spec, status_qos());
  Track t = track(id);
  wait_state(late, &t, is_terminal, now_s() + 5.0);
  CHECK(t.latest == want,
        "%s: a status reader created after the goal ended sees it in state %d, expected %d "
        "(transient local status)",
        what, t.latest, want);
  dds_delete(late);
}

/* ---------------------------------------------------------------------------------------------
 * Checks of a result. */

/* A result with `status` and the action's error `code` (ComputePathToPose's numbering). */
static bool check_outcome(const Action* a, const char* what, const Call* c, int status, int code) {
  const int want = code == kNavNone ? 0 : code + (code < 300 ? a->type->error_offset : 0);
  CHECK(c->result.status == status && c->result.error_code == want,
        "%s: status %d, error_code %d (\"%s\"), expected status %d, error_code %d", what,
        c->result.status, c->result.error_code, c->result.error_msg, status, want);
  return c->result.status == status && c->result.error_code == want;
}

/* A pose of the path within kAtTolerance of (x, y), from index `from` on; its index or -1. */
static int pose_at(const Path* p, int from, double x, double y) {
  for (int i = from; i < p->n; ++i)
    if (hypot(p->xy[2 * i] - x, p->xy[2 * i + 1] - y) <= kAtTolerance) return i;
  return -1;
}

/* ---------------------------------------------------------------------------------------------
 * Serialized bytes. */

/* The serialized bytes (encapsulation included) of the first sample `cdr_reader` gets within
 * `timeout` seconds from the writer with instance handle `from` (0: any writer); NULL if none. */
static unsigned char* payload_from(dds_entity_t cdr_reader, dds_instance_handle_t from,
                                   size_t* size, double timeout) {
  unsigned char* bytes = NULL;
  const double end = now_s() + timeout;
  while (bytes == NULL && now_s() < end) {
    struct ddsi_serdata* data[8] = {NULL};
    dds_sample_info_t infos[8];
    const int n = dds_takecdr(cdr_reader, data, 8, infos, DDS_ANY_STATE);
    for (int i = 0; i < n; ++i) {
      if (infos[i].valid_data && (from == 0 || infos[i].publication_handle == from) &&
          bytes == NULL) {
        *size = ddsi_serdata_size(data[i]);
        bytes = malloc(*size);
        ddsi_serdata_to_ser(data[i], 0, *size, bytes);
      }
      ddsi_serdata_unref(data[i]);
    }
    if (n <= 0) wait_data(cdr_reader, end);
  }
  return bytes;
}

/* rmw_cyclonedds's request header at bytes 4..19 of a payload of `size` bytes, in the byte order
 * its encapsulation says (XCDR1: CDR_BE 0x0000, CDR_LE 0x0001). False when the payload is not
 * XCDR1 plain CDR or too short. */
static bool header_at(const unsigned char* b, size_t size, uint64_t* guid, int64_t* seq) {
  if (size < 20 || b[0] != 0 || b[1] > 1) return false;
  uint64_t g = 0, s = 0;
  for (int k = 0; k < 8; ++k) {
    const int shift = b[1] == 1 ? 8 * k : 8 * (7 - k);
    g |= (uint64_t)b[4 + k] << shift;
    s |= (uint64_t)b[12 + k] << shift;
  }
  *guid = g;
  *seq = (int64_t)s;
  return true;
}

/* ---------------------------------------------------------------------------------------------
 * Default run. */

static void goal_to(GoalSpec* g, double sx, double sy, double gx, double gy, const char* planner) {
  memset(g, 0, sizeof *g);
  g->sx = sx;
  g->sy = sy;
  g->n = 1;
  g->gx[0] = gx;
  g->gy[0] = gy;
  g->planner_id = planner;
  g->use_start = true;
}

/* The first ComputePathToPose, with a byte-level look at the node's replies. */
static void first_goal(Action* a, dds_entity_t send_goal_bytes) {
  double sx, sy, gx, gy;
  request_ends(&sx, &sy, &gx, &gy);
  GoalSpec g;
  goal_to(&g, sx, sy, gx, gy, "");
  Call c;
  /* The node waits up to requests.map_wait for its first map: time enough for that. */
  if (!call_goal(a, &g, &c, 10.0)) return;
  /* The node's send_goal reply as it came: XCDR1, and bytes 4..19 the request's header. */
  size_t size = 0;
  unsigned char* bytes = payload_from(send_goal_bytes, 0, &size, 2.0);
  uint64_t guid = 0;
  int64_t got = 0;
  CHECK(bytes != NULL && header_at(bytes, size, &guid, &got), "send_goal reply: %s",
        bytes == NULL ? "not seen by the client's serialized-data reader"
                      : "not XCDR1 CDR with a 16-byte header");
  if (bytes != NULL && header_at(bytes, size, &guid, &got)) {
    CHECK(guid == a->service[kSendGoal].guid && got == c.goal_seq,
          "send_goal reply bytes 4..19: (guid 0x%016" PRIx64 ", seq %" PRId64
          "), the request's were (0x%016" PRIx64 ", %" PRId64 ")",
          guid, got, a->service[kSendGoal].guid, c.goal_seq);
    printf("wire: send_goal reply in encapsulation 0x%02x%02x, header (0x%016" PRIx64 ", %" PRId64
           ") at bytes 4..19\n",
           bytes[0], bytes[1], guid, got);
  }
  free(bytes);
  if (!check_outcome(a, "compute_path_to_pose", &c, kStateSucceeded, kNavNone)) return;
  check_path(&client_map, "compute_path_to_pose result path", &c.result.path, sx, sy, gx, gy);
  Track t = track(&c.id);
  CHECK(wait_state(a->status, &t, is_terminal, now_s() + 3.0) && t.latest == kStateSucceeded,
        "compute_path_to_pose: the status topic shows the goal in state %d, expected %d", t.latest,
        kStateSucceeded);
  check_latched_state(a, &c.id, kStateSucceeded, "compute_path_to_pose");
  printf(
      "compute_path_to_pose: SUCCEEDED, %d poses checked against the client's map, planning "
      "%.3f ms, send_goal -> result %.3f ms; status topic: SUCCEEDED\n",
      c.result.path.n, 1e3 * c.result.planning_time, 1e3 * (c.result_at - c.sent));

  /* The goal has ended: cancelling it is ERROR_GOAL_TERMINATED with nothing listed. */
  CancelReply cr;
  memset(&cr, 0, sizeof cr);
  const int64_t seq = send_cancel(a, &c.id);
  if (wait_reply(a, &a->service[kCancelGoal], seq, copy_cancel, &cr, 5.0) >= 0) {
    CHECK(cr.return_code == kCancelTerminated && cr.n == 0,
          "cancel_goal of an ended goal: return_code %d with %d goal(s), expected %d with none",
          cr.return_code, cr.n, kCancelTerminated);
    printf("cancel_goal of the ended goal: return_code %d (ERROR_GOAL_TERMINATED)\n",
           cr.return_code);
  }
  free_path(&c.result.path);
}

/* use_start false: the start is the node's latest robot_pose. */
static void robot_pose_goal(Action* a, dds_entity_t robot_pose) {
  double rx, ry, gx, gy;
  centre(4, 26, &rx, &ry);
  centre(36, 25, &gx, &gy);
  const double yaw = M_PI / 2;
  geometry_msgs_msg_dds__PoseStamped_ pose;
  set_pose(&pose, rx, ry, 0.0);
  /* Acknowledged by the node's reader before the goal goes out: its reader keeps the newest. */
  dds_write(robot_pose, &pose);
  CHECK(dds_wait_for_acks(robot_pose, DDS_SECS(2)) == DDS_RETCODE_OK,
        "robot_pose: not acknowledged by the node within 2 s");
  GoalSpec g;
  goal_to(&g, 0.0, 0.0, gx, gy, "");
  g.yaw[0] = yaw;
  g.use_start = false; /* the start field (0, 0), inside the map, must be ignored */
  Call c;
  if (!call_goal(a, &g, &c, 5.0)) return;
  if (check_outcome(a, "use_start false", &c, kStateSucceeded, kNavNone)) {
    check_path(&client_map, "use_start false result path", &c.result.path, rx, ry, gx, gy);
    CHECK(fabs(remainder(c.result.path.last_yaw - yaw, 2 * M_PI)) < 1e-6,
          "use_start false: the last pose faces %.4f rad, the goal %.4f rad",
          c.result.path.last_yaw, yaw);
    printf(
        "use_start false: SUCCEEDED from the robot_pose start, %d poses, last facing the "
        "goal\n",
        c.result.path.n);
  }
  free_path(&c.result.path);
}

/* Goals the node must refuse, each with its Nav2 error code. */
static void refused_goals(Action* a) {
  double sx, sy, wx, wy;
  centre(5, 3, &sx, &sy);
  centre(kWallColumn, 5, &wx, &wy); /* a wall cell; planner.goal_tolerance is 0 */
  GoalSpec g;
  goal_to(&g, sx, sy, wx, wy, "");
  Call c;
  if (call_goal(a, &g, &c, 5.0) &&
      check_outcome(a, "goal in the wall", &c, kStateAborted, kGoalOccupied))
    printf("goal in the wall: ABORTED, GOAL_OCCUPIED: %s\n", c.result.error_msg);
  free_path(&c.result.path);

  double gx, gy;
  request_ends(&sx, &sy, &gx, &gy);
  goal_to(&g, sx, sy, gx, gy, "no_such_planner");
  if (call_goal(a, &g, &c, 5.0) &&
      check_outcome(a, "unknown planner_id", &c, kStateAborted, kInvalidPlanner)) {
    CHECK(strstr(c.result.error_msg, "astar") != NULL,
          "unknown planner_id: error_msg \"%s\" does not name the known planner astar",
          c.result.error_msg);
    printf("unknown planner_id: ABORTED, INVALID_PLANNER: %s\n", c.result.error_msg);
  }
  free_path(&c.result.path);
}

/* Requests about a goal id the server never saw. */
static void unknown_goal(Action* a) {
  const GoalId id = new_goal_id();
  Result r;
  memset(&r, 0, sizeof r);
  r.status = -1;
  const int64_t seq = send_get_result(a, &id);
  if (wait_reply(a, &a->service[kGetResult], seq, copy_result, &r, 5.0) >= 0) {
    CHECK(r.status == kStateUnknown, "get_result of an unknown goal: status %d, expected %d",
          r.status, kStateUnknown);
    printf("get_result of an unknown goal: status %d (UNKNOWN)\n", r.status);
  }
  free_path(&r.path);
  CancelReply cr;
  memset(&cr, 0, sizeof cr);
  const int64_t cancel_seq = send_cancel(a, &id);
  if (wait_reply(a, &a->service[kCancelGoal], cancel_seq, copy_cancel, &cr, 5.0) >= 0) {
    CHECK(cr.return_code == kCancelUnknownGoal && cr.n == 0,
          "cancel_goal of an unknown goal: return_code %d with %d goal(s), expected %d with none",
          cr.return_code, cr.n, kCancelUnknownGoal);
    printf("cancel_goal of an unknown goal: return_code %d (ERROR_UNKNOWN_GOAL_ID)\n",
           cr.return_code);
  }
}

static void through_poses(Action* a) {
  double sx, sy;
  GoalSpec g;
  memset(&g, 0, sizeof g);
  centre(5, 3, &sx, &sy);
  g.sx = sx;
  g.sy = sy;
  g.n = 2; /* across the wall and back: the path goes through the gap twice */
  centre(34, 3, &g.gx[0], &g.gy[0]);
  centre(5, 26, &g.gx[1], &g.gy[1]);
  g.planner_id = "";
  g.use_start = true;
  Call c;
  if (call_goal(a, &g, &c, 5.0) &&
      check_outcome(a, "compute_path_through_poses", &c, kStateSucceeded, kNavNone)) {
    const Path* p = &c.result.path;
    check_path(&client_map, "compute_path_through_poses result path", p, sx, sy, g.gx[1], g.gy[1]);
    const int via = pose_at(p, 0, g.gx[0], g.gy[0]);
    CHECK(via > 0 && via < p->n - 1,
          "compute_path_through_poses: no pose within %g m of the first goal (%.4f, %.4f) "
          "between the ends",
          kAtTolerance, g.gx[0], g.gy[0]);
    printf(
        "compute_path_through_poses: SUCCEEDED, %d poses, through the first goal at pose %d "
        "and ending at the second\n",
        p->n, via);
  }
  free_path(&c.result.path);

  g.n = 0;
  if (call_goal(a, &g, &c, 5.0) && check_outcome(a, "compute_path_through_poses, no goals", &c,
                                                 kStateAborted, kNoViapointsGiven))
    printf("compute_path_through_poses with no goals: ABORTED, NO_VIAPOINTS_GIVEN: %s\n",
           c.result.error_msg);
  free_path(&c.result.path);
}

static int run_checks(void) {
  const nav_msgs_msg_dds__OccupancyGrid_ map = map_message(&client_map);
  /* A latched map, written once now, before the node is discovered. */
  const dds_entity_t map_writer = writer(&kMap, qos_of(true, 1));
  dds_write(map_writer, &map);
  const dds_entity_t robot_pose = writer(&kRobotPose, ros_default_qos());
  static Action to_pose, through;
  make_action(&to_pose, &kToPose);
  make_action(&through, &kThroughPoses);
  dds_entity_t entities[2 + 2 * (2 * kServices + 2)];
  int n = 0;
  entities[n++] = map_writer;
  entities[n++] = robot_pose;
  n += action_entities(&to_pose, entities + n);
  n += action_entities(&through, entities + n);
  const double t0 = now_s();
  if (wait_matched(entities, n, 20.0) < 0) {
    fprintf(stderr, "FAILED: the node did not match all %d endpoints within 20 s\n", n);
    return 1;
  }
  printf("discovery: %d endpoints matched in %.3f s\n", n, now_s() - t0);
  const dds_entity_t publications =
      dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, NULL, NULL);
  const dds_entity_t subscriptions =
      dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, NULL, NULL);
  check_action_types(&to_pose, publications, subscriptions);
  check_action_types(&through, publications, subscriptions);
  /* A second reader of send_goal replies, for their serialized bytes (its own USER_DATA: the
   * node must answer the requester's reply reader, not this one). */
  const dds_entity_t send_goal_bytes =
      reader(&to_pose.service[kSendGoal].reply_spec, qos_of(false, 10));
  wait_matched(&send_goal_bytes, 1, 5.0);

  first_goal(&to_pose, send_goal_bytes);
  robot_pose_goal(&to_pose, robot_pose);
  refused_goals(&to_pose);
  unknown_goal(&to_pose);
  through_poses(&through);

  return report_run(participant, "interop actions");
}

/* ---------------------------------------------------------------------------------------------
 * --cancel: plans that run long enough to be caught running. */

/* 2000 x 2000 cells of 0.1 m, origin (0, 0): walls across the whole width at rows 500, 1000 and
 * 1500, each with a gap of 10 cells at alternating ends (east, west, east), so the four lanes
 * form one serpentine from the south-west corner to the north-west one (the path: 871.7 m).
 * The octile distance to the goal guides A* nowhere useful: it expands most of the 4 million
 * cells (about 3 million expanded, 0.3-0.6 s of planning on the machine of the measurements). */
enum { kMazeSize = 2000, kMazeLane = 500, kMazeGap = 10 };
static int8_t* maze_cells;
static Grid maze;

static void make_maze(void) {
  maze_cells = calloc((size_t)kMazeSize * kMazeSize, 1);
  if (maze_cells == NULL) die("maze", -1);
  for (int k = 1; k < kMazeSize / kMazeLane; ++k) {
    const int row = k * kMazeLane;
    const bool gap_east = k % 2 == 1;
    for (int x = 0; x < kMazeSize; ++x) {
      const bool in_gap = gap_east ? x >= kMazeSize - kMazeGap : x < kMazeGap;
      if (!in_gap) maze_cells[(size_t)row * kMazeSize + x] = 100;
    }
  }
  maze = (Grid){kMazeSize, kMazeSize, 0.1, 0.0, 0.0, 65, maze_cells};
}

static void maze_goal(GoalSpec* g) {
  double sx, sy, gx, gy;
  grid_cell_centre(&maze, 20, 20, &sx, &sy);
  grid_cell_centre(&maze, 20, kMazeSize - 20, &gx, &gy);
  goal_to(g, sx, sy, gx, gy, "astar");
}

static bool still_running(int state) {
  return state == kStateAccepted || state == kStateExecuting;
}

/* Sends the maze goal under a fresh id (into `g`, `id`, sent at `sent`) and waits for its
 * acceptance; false (with a failed check naming `what`) when it is not accepted. */
static bool send_maze_goal(Action* a, const char* what, GoalSpec* g, GoalId* id, double* sent) {
  maze_goal(g);
  *id = new_goal_id();
  *sent = now_s();
  const int64_t seq = send_goal(a, id, g);
  Acceptance acc;
  memset(&acc, 0, sizeof acc);
  if (wait_reply(a, &a->service[kSendGoal], seq, copy_acceptance, &acc, 10.0) < 0) return false;
  CHECK(acc.accepted, "%s: not accepted", what);
  return acc.accepted;
}

/* A get_result sent right after acceptance, while the plan runs, is answered when it ends. */
static void result_while_running(Action* a) {
  GoalSpec g;
  GoalId id;
  double sent;
  if (!send_maze_goal(a, "maze goal", &g, &id, &sent)) return;
  const int64_t result_seq = send_get_result(a, &id);
  /* Acknowledged: the node holds the get_result request now. */
  CHECK(dds_wait_for_acks(a->service[kGetResult].request, DDS_SECS(5)) == DDS_RETCODE_OK,
        "get_result: not acknowledged within 5 s");
  const double acked = now_s();
  Track t = track(&id);
  poll_status(a->status, &t);
  const int state_at_ack = t.latest;
  Result r;
  memset(&r, 0, sizeof r);
  /* The plan first waits (up to requests.map_wait, 30 s) for the 4 MB map to arrive and be
   * installed, then plans (0.4 s measured; max_planning_time 30 s). */
  const double at = wait_reply(a, &a->service[kGetResult], result_seq, copy_result, &r, 30.0);
  if (at < 0) return;
  poll_status(a->status, &t);
  printf(
      "maze goal: accepted after %.3f s; get_result acknowledged while the status topic said "
      "state %d; result %.3f s later (planning %.3f s)\n",
      acked - sent, state_at_ack, at - acked, r.planning_time);
  CHECK(state_at_ack < 0 || still_running(state_at_ack),
        "maze goal: the status topic said state %d when get_result was acknowledged: the plan "
        "had already ended, so this run does not show a get_result answered when it ends",
        state_at_ack);
  CHECK(at - acked > 0.1,
        "maze goal: the result came %.3f s after get_result was acknowledged: the plan was not "
        "running any more (make the maze longer)",
        at - acked);
  CHECK(r.status == kStateSucceeded && r.error_code == 0,
        "maze goal: status %d, error_code %d (\"%s\"), expected %d, 0", r.status, r.error_code,
        r.error_msg, kStateSucceeded);
  if (r.status == kStateSucceeded) {
    check_path(&maze, "maze result path", &r.path, g.sx, g.sy, g.gx[0], g.gy[0]);
    printf("maze goal: SUCCEEDED, %d poses checked against the maze\n", r.path.n);
  }
  free_path(&r.path);
}

/* A goal cancelled while it runs. */
static void cancel_running(Action* a) {
  GoalSpec g;
  GoalId id;
  double sent;
  if (!send_maze_goal(a, "goal to cancel", &g, &id, &sent)) return;
  /* rclcpp_action asks for the result as soon as the goal is accepted; it stays pending. */
  const int64_t result_seq = send_get_result(a, &id);
  Track t = track(&id);
  const bool executing = wait_state(a->status, &t, is_executing, now_s() + 10.0);
  CHECK(executing, "goal to cancel: the status topic never showed it EXECUTING (2); last %d",
        t.latest);
  if (!executing) return;
  const double cancel_sent = now_s();
  CancelReply cr;
  memset(&cr, 0, sizeof cr);
  const int64_t cancel_seq = send_cancel(a, &id);
  const double cancel_at =
      wait_reply(a, &a->service[kCancelGoal], cancel_seq, copy_cancel, &cr, 10.0);
  if (cancel_at < 0) return;
  CHECK(cr.return_code == kCancelNone && lists_goal(&cr, &id),
        "cancel_goal of a running goal: return_code %d, %d goal(s) listed%s; expected %d listing "
        "the goal",
        cr.return_code, cr.n, lists_goal(&cr, &id) ? " (the goal among them)" : "", kCancelNone);
  Result r;
  memset(&r, 0, sizeof r);
  const double result_at =
      wait_reply(a, &a->service[kGetResult], result_seq, copy_result, &r, 30.0);
  if (result_at < 0) return;
  CHECK(r.status == kStateCanceled,
        "cancelled goal: result status %d (error_code %d, \"%s\"), "
        "expected %d",
        r.status, r.error_code, r.error_msg, kStateCanceled);
  wait_state(a->status, &t, is_terminal, now_s() + 3.0);
  CHECK(t.latest == kStateCanceled, "cancelled goal: the status topic shows state %d, expected %d",
        t.latest, kStateCanceled);
  check_latched_state(a, &id, kStateCanceled, "cancelled goal");
  printf(
      "cancel: EXECUTING %.3f s after send_goal; cancel_goal answered %d (ERROR_NONE) listing "
      "the goal in %.3f ms; get_result %d (CANCELED) %.3f ms after the cancel was sent; "
      "status topic (and a late reader): CANCELED; states seen 0x%x\n",
      cancel_sent - sent, cr.return_code, 1e3 * (cancel_at - cancel_sent), r.status,
      1e3 * (result_at - cancel_sent), t.seen);
  free_path(&r.path);
}

static int run_cancel(void) {
  make_maze();
  const nav_msgs_msg_dds__OccupancyGrid_ map = map_message(&maze);
  const dds_entity_t map_writer = writer(&kMap, qos_of(true, 1));
  dds_write(map_writer, &map);
  static Action to_pose;
  make_action(&to_pose, &kToPose);
  dds_entity_t entities[1 + 2 * kServices + 2];
  entities[0] = map_writer;
  const int n = 1 + action_entities(&to_pose, entities + 1);
  if (wait_matched(entities, n, 20.0) < 0) {
    fprintf(stderr, "FAILED: the node did not match all %d endpoints within 20 s\n", n);
    return 1;
  }
  result_while_running(&to_pose);
  cancel_running(&to_pose);
  dds_delete(participant);
  free(maze_cells);
  if (failures > 0) {
    fprintf(stderr, "%d check(s) failed\n", failures);
    return 1;
  }
  printf("interop action cancel: all checks passed\n");
  return 0;
}

/* ---------------------------------------------------------------------------------------------
 * --bench N. */

static int bench(int count) {
  const nav_msgs_msg_dds__OccupancyGrid_ map = map_message(&client_map);
  Bus bus;
  memset(&bus, 0, sizeof bus);
  bus.map = writer(&kMap, qos_of(true, 1));
  dds_write(bus.map, &map);
  bus.request = writer(&kRequest, ros_default_qos());
  bus.status = reader(&kStatus, ros_default_qos());
  static Action a;
  make_action(&a, &kToPose);
  dds_entity_t entities[3 + 2 * kServices + 2];
  entities[0] = bus.map;
  entities[1] = bus.request;
  entities[2] = bus.status;
  const int n = 3 + action_entities(&a, entities + 3);
  if (wait_matched(entities, n, 20.0) < 0) {
    fprintf(stderr, "FAILED: the node did not match the bench's endpoints within 20 s\n");
    return 1;
  }
  double sx, sy, gx, gy;
  request_ends(&sx, &sy, &gx, &gy);
  GoalSpec g;
  goal_to(&g, sx, sy, gx, gy, "");
  const size_t size = (size_t)(count > 0 ? count : 1);
  double* action_ms = malloc(sizeof(double) * size);
  double* accept_ms = malloc(sizeof(double) * size);
  double* request_ms = malloc(sizeof(double) * size);
  double* difference_ms = malloc(sizeof(double) * size);
  double* action_planning_ms = malloc(sizeof(double) * size);
  double* request_planning_ms = malloc(sizeof(double) * size);
  int done = 0;
  for (int i = -20; i < count; ++i) { /* 20 unmeasured rounds first */
    Call c;
    const bool called = call_goal(&a, &g, &c, 5.0);
    const bool action_ok = called && c.result.status == kStateSucceeded;
    free_path(&c.result.path);
    char id[64];
    snprintf(id, sizeof id, "bench-%d", i);
    const double sent = now_s();
    const Awaited w = send_request(&bus, id, sx, sy, gx, gy);
    Answer answer = wait_status(bus.status, &w, 5.0);
    const double took = now_s() - sent;
    const bool request_ok = answer.found && answer.code == STATUS(OK);
    if (i >= 0 && action_ok && request_ok) {
      action_ms[done] = 1e3 * (c.result_at - c.sent);
      accept_ms[done] = 1e3 * (c.accepted_at - c.sent);
      request_ms[done] = 1e3 * took;
      difference_ms[done] = action_ms[done] - request_ms[done];
      action_planning_ms[done] = 1e3 * c.result.planning_time;
      request_planning_ms[done] = 1e-3 * (double)answer.planning_time_us;
      ++done;
    }
    free_answer(&answer);
  }
  CHECK(done == count, "bench: %d of %d rounds had both a SUCCEEDED goal and an OK status", done,
        count);
  if (done > 0) {
    printf(
        "bench: %d rounds one at a time, %dx%d map, Cyclone client -> vnsba_node: "
        "ComputePathToPose (rmw_cyclonedds's wire) and plan_request for the same plan\n",
        done, kWidth, kHeight);
    print_stats("action send_goal -> result", action_ms, done);
    print_stats("action send_goal -> accepted", accept_ms, done);
    print_stats("plan_request -> plan_status", request_ms, done);
    print_stats("action - plan_request (paired)", difference_ms, done);
    print_stats("planning_time (action result)", action_planning_ms, done);
    print_stats("planning_time_us (plan_status)", request_planning_ms, done);
  }
  free(action_ms);
  free(accept_ms);
  free(request_ms);
  free(difference_ms);
  free(action_planning_ms);
  free(request_planning_ms);
  dds_delete(participant);
  return failures > 0 ? 1 : 0;
}

/* ---------------------------------------------------------------------------------------------
 * --fresh N: fresh clients' first goals (issue 44). */

/* How long a fresh client waits for each reply (s): the node holds a reply at most
 * requests.reply_wait (2 s by default) and plans the client's goal in milliseconds. */
static const double kFreshReplyBound = 10.0;

/* --fresh-client (run by --fresh): one fresh process as `ros2 action send_goal` or a freshly
 * loaded BT node is: a participant with one ComputePathToPose client that sends its goal the
 * moment rcl_action_server_is_available() holds (every entity of action_entities matched), and
 * get_result right after the acceptance, as rclcpp_action does. Prints one line,
 * "fresh-action <start -> discovered ms> <goal -> accepted ms> <accepted -> result ms>
 * <result status> <status topic state>", -1 for a reply that never came (or a state never seen;
 * result status -2: the goal was rejected), and on stderr which reply it lost, with its
 * participant's GUID prefix (to find it in a Cyclone trace). Exits 0 when both replies came. */
static int fresh_action_client(double started) {
  skip_foreign_replies = true;
  static Action a;
  make_action(&a, &kToPose);
  dds_entity_t entities[2 * kServices + 2];
  const int n = action_entities(&a, entities);
  const double discovered = wait_matched(entities, n, 20.0);
  if (discovered < 0) {
    fprintf(stderr, "fresh client %d: the node did not match its action client within 20 s\n",
            (int)getpid());
    printf("fresh-action -1 -1 -1 -1 -1\n");
    return 1;
  }
  double sx, sy, gx, gy;
  request_ends(&sx, &sy, &gx, &gy);
  GoalSpec g;
  goal_to(&g, sx, sy, gx, gy, "");
  Call c;
  memset(&c, 0, sizeof c);
  c.id = new_goal_id();
  c.sent = now_s();
  c.goal_seq = send_goal(&a, &c.id, &g);
  c.accepted_at = wait_reply(&a, &a.service[kSendGoal], c.goal_seq, copy_acceptance, &c.acceptance,
                             kFreshReplyBound);
  c.result_at = -1;
  c.result.status = c.accepted_at >= 0 && !c.acceptance.accepted ? -2 : -1; /* -2: rejected */
  int64_t result_seq = -1;
  if (c.accepted_at >= 0 && c.acceptance.accepted) {
    result_seq = send_get_result(&a, &c.id);
    c.result_at = wait_reply(&a, &a.service[kGetResult], result_seq, copy_result, &c.result,
                             kFreshReplyBound);
  }
  /* What the status topic says of the goal (transient local: its latest list is here by now,
   * or comes within a second). */
  Track t = track(&c.id);
  wait_state(a.status, &t, is_terminal, now_s() + 1.0);
  printf("fresh-action %.3f %.3f %.3f %d %d\n", 1e3 * (discovered - started),
         c.accepted_at >= 0 ? 1e3 * (c.accepted_at - c.sent) : -1.0,
         c.result_at >= 0 ? 1e3 * (c.result_at - c.accepted_at) : -1.0, c.result.status, t.latest);
  fflush(stdout);
  if (c.accepted_at < 0 || (c.acceptance.accepted && c.result_at < 0)) {
    const dds_guid_t p = guid_of(participant);
    char prefix[40];
    int k = 0;
    for (int i = 0; i < 12; ++i)
      k += snprintf(prefix + k, sizeof prefix - (size_t)k, "%02x", p.v[i]);
    const Service* lost = &a.service[c.accepted_at < 0 ? kSendGoal : kGetResult];
    fprintf(stderr,
            "fresh client %d (participant %s): lost the %s reply to request (guid 0x%016" PRIx64
            ", seq %" PRId64 "); the status topic shows the goal in state %d\n",
            (int)getpid(), prefix, c.accepted_at < 0 ? "send_goal" : "get_result", lost->guid,
            c.accepted_at < 0 ? c.goal_seq : result_seq, t.latest);
  }
  /* The parent judges the result's status (fresh clients may preempt each other's goals). */
  const bool ok = c.accepted_at >= 0 && c.acceptance.accepted && c.result_at >= 0;
  free_path(&c.result.path);
  dds_delete(participant);
  return ok ? 0 : 1;
}

typedef enum {
  kFreshAnswered,   /* both replies, SUCCEEDED */
  kFreshPreempted,  /* both replies, ABORTED: another fresh client's goal preempted it */
  kFreshLostAccept, /* no send_goal reply */
  kFreshLostResult, /* no get_result reply */
  kFreshFailed      /* anything else */
} FreshOutcome;

typedef struct {
  pid_t pid;
  FILE* out;
} FreshChild;

/* Starts this executable as a fresh client (`args`), its stdout a pipe to us. */
static bool start_fresh_client(char* const* args, FreshChild* child) {
  int fd[2];
  if (pipe(fd) != 0) return false;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fd[1], STDOUT_FILENO);
  posix_spawn_file_actions_addclose(&actions, fd[0]);
  const int rc = posix_spawn(&child->pid, "/proc/self/exe", &actions, NULL, args, environ);
  posix_spawn_file_actions_destroy(&actions);
  close(fd[1]);
  if (rc != 0) {
    close(fd[0]);
    fprintf(stderr, "cannot start a fresh client: %s\n", strerror(rc));
    return false;
  }
  child->out = fdopen(fd[0], "r");
  return true;
}

/* Reads a fresh client's line and waits for it to exit. */
static FreshOutcome finish_fresh_client(FreshChild* child, double* discovery_ms, double* accept_ms,
                                        double* result_ms) {
  char line[256] = "";
  if (child->out == NULL || fgets(line, sizeof line, child->out) == NULL) line[0] = '\0';
  if (child->out) fclose(child->out);
  int status = 0;
  waitpid(child->pid, &status, 0);
  int result_status = -1, topic_state = -1;
  if (sscanf(line, "fresh-action %lf %lf %lf %d %d", discovery_ms, accept_ms, result_ms,
             &result_status, &topic_state) != 5 ||
      *discovery_ms < 0)
    return kFreshFailed;
  if (*accept_ms < 0) return kFreshLostAccept;
  if (result_status == -2) return kFreshFailed; /* the goal was rejected */
  if (*result_ms < 0) return kFreshLostResult;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return kFreshFailed;
  if (result_status == kStateSucceeded) return kFreshAnswered;
  /* The node preempts a robot's running goal with a newer one (ABORTED). */
  return result_status == kStateAborted ? kFreshPreempted : kFreshFailed;
}

/* --fresh N [--fresh-parallel P] [--fresh-resident]: the map latched on the node, then N fresh
 * client processes, P at a time (default 1): every one must get both replies. With
 * --fresh-resident this process keeps a ComputePathToPose client of its own matched throughout,
 * idle, as a navigator's (bt_navigator) is: the node's reply writers then always have two or
 * more Cyclone readers, which share Cyclone's multicast locator. */
static int run_fresh(int domain, int count, int parallel, bool resident) {
  const nav_msgs_msg_dds__OccupancyGrid_ map = map_message(&client_map);
  const dds_entity_t map_writer = writer(&kMap, qos_of(true, 1));
  dds_write(map_writer, &map);
  static Action navigator;
  dds_entity_t entities[1 + 2 * kServices + 2] = {map_writer};
  int n = 1;
  if (resident) {
    make_action(&navigator, &kToPose);
    n += action_entities(&navigator, entities + n);
  }
  if (wait_matched(entities, n, 20.0) < 0 ||
      dds_wait_for_acks(map_writer, DDS_SECS(10)) != DDS_RETCODE_OK) {
    fprintf(stderr, "FAILED: the node did not match (and acknowledge the map) within 30 s\n");
    return 1;
  }
  char domain_text[16];
  snprintf(domain_text, sizeof domain_text, "%d", domain);
  char* args[] = {"vnsba_cyclone_action_client",
                  "--fresh-client",
                  "--domain",
                  domain_text,
                  "--namespace",
                  (char*)ros_namespace,
                  NULL};
  const size_t size = (size_t)count;
  double* discovery = malloc(sizeof(double) * size);
  double* accept = malloc(sizeof(double) * size);
  double* result = malloc(sizeof(double) * size);
  FreshChild* children = malloc(sizeof(FreshChild) * (size_t)parallel);
  int answered = 0, preempted = 0, lost_accept = 0, lost_result = 0, failed = 0;
  for (int first = 0; first < count; first += parallel) {
    const int batch = count - first < parallel ? count - first : parallel;
    bool started[batch];
    for (int i = 0; i < batch; ++i) started[i] = start_fresh_client(args, &children[i]);
    for (int i = 0; i < batch; ++i) {
      if (!started[i]) {
        ++failed;
        continue;
      }
      double d = -1, acc = -1, res = -1;
      switch (finish_fresh_client(&children[i], &d, &acc, &res)) {
        case kFreshAnswered:
          discovery[answered] = d;
          accept[answered] = acc;
          result[answered++] = res;
          break;
        case kFreshPreempted:
          ++preempted;
          break;
        case kFreshLostAccept:
          ++lost_accept;
          break;
        case kFreshLostResult:
          ++lost_result;
          break;
        case kFreshFailed:
          ++failed;
          break;
      }
    }
  }
  printf(
      "fresh action clients: %d (each a new process: participant, one ComputePathToPose client, "
      "its goal sent once the action server is available, %d at a time%s): %d answered, %d lost "
      "the send_goal reply, %d lost the get_result reply, %d failed otherwise",
      count, parallel, resident ? ", beside a resident client" : "", answered + preempted,
      lost_accept, lost_result, failed);
  if (preempted > 0) printf(" (%d answered ABORTED: preempted by another's goal)", preempted);
  printf("\n");
  if (answered > 0) {
    print_stats("start -> action server available", discovery, answered);
    print_stats("send_goal -> accepted", accept, answered);
    print_stats("accepted -> result", result, answered);
  }
  CHECK(lost_accept + lost_result == 0,
        "%d of %d fresh clients lost a reply (%d the send_goal reply, %d the get_result reply)",
        lost_accept + lost_result, count, lost_accept, lost_result);
  CHECK(failed == 0, "%d of %d fresh clients failed (not a lost reply)", failed, count);
  /* One at a time, no goal is preempted: every result is SUCCEEDED. */
  CHECK(parallel > 1 || preempted == 0, "%d of %d results ABORTED, none expected", preempted,
        count);
  free(discovery);
  free(accept);
  free(result);
  free(children);
  return report_run(participant, "interop action fresh clients");
}

/* ---------------------------------------------------------------------------------------------
 * --wire: the serialisation, no node. */

/* One sample of `desc`'s type written on a topic of its own and read back serialized. */
static unsigned char* serialise(const char* topic_name, const dds_topic_descriptor_t* desc,
                                const char* type_name, const void* sample, size_t* size) {
  const TopicSpec spec = {topic_name, desc, type_name, NULL};
  const dds_entity_t w = writer(&spec, qos_of(false, 10));
  const dds_entity_t r = reader(&spec, qos_of(false, 10));
  CHECK(dds_write(w, sample) == DDS_RETCODE_OK, "%s: write failed", topic_name);
  dds_instance_handle_t handle = 0;
  dds_get_instance_handle(w, &handle);
  unsigned char* bytes = payload_from(r, handle, size, 1.0);
  CHECK(bytes != NULL, "%s: the client's own sample did not come back", topic_name);
  dds_delete(r);
  dds_delete(w);
  return bytes;
}

/* `wrapped` (a wrapped type's sample, its header set) serialises as `plain` (the ROS message
 * alone) with the header's 16 bytes between the encapsulation and the message; and, when
 * `expect` is not NULL, the message's bytes are those `expect_n` (written out by hand from the
 * XCDR1 rules, independently of Cyclone). */
static void check_wrapped_bytes(const char* what, const dds_topic_descriptor_t* wrapped_desc,
                                const char* ros_type, const void* wrapped,
                                const dds_topic_descriptor_t* plain_desc, const void* plain,
                                const unsigned char* expect, size_t expect_n) {
  char wrapped_topic[128], plain_topic[128], plain_type[160];
  snprintf(wrapped_topic, sizeof wrapped_topic, "wire_check/%s_wrapped", what);
  snprintf(plain_topic, sizeof plain_topic, "wire_check/%s_plain", what);
  /* The message alone under a name of its own: one type name, one layout in this participant. */
  snprintf(plain_type, sizeof plain_type, "vnsba_interop::plain::%s", what);
  dds_topic_descriptor_t w_desc, p_desc;
  rename_descriptor(&w_desc, wrapped_desc, ros_type);
  rename_descriptor(&p_desc, plain_desc, plain_type);
  size_t nw = 0, np = 0;
  unsigned char* w = serialise(wrapped_topic, &w_desc, ros_type, wrapped, &nw);
  unsigned char* p = serialise(plain_topic, &p_desc, plain_type, plain, &np);
  if (w != NULL && p != NULL) {
    const vnsba_interop_RequestHeader* h = wrapped;
    uint64_t guid = 0;
    int64_t seq = 0;
    header_at(w, nw, &guid, &seq);
    const bool same = nw == np + 16 && w[0] == p[0] && w[1] == p[1] && w[0] == 0 && w[1] == 1 &&
                      memcmp(w + 20, p + 4, np - 4) == 0;
    CHECK(same && guid == h->guid && seq == h->seq,
          "%s: %zu bytes wrapped, %zu plain, encapsulations 0x%02x%02x and 0x%02x%02x, header "
          "(0x%016" PRIx64 ", %" PRId64 ") read back as (0x%016" PRIx64 ", %" PRId64
          "): not CDR_LE header + message",
          what, nw, np, w[0], w[1], p[0], p[1], h->guid, h->seq, guid, seq);
    if (expect != NULL)
      CHECK(nw == 20 + expect_n && memcmp(w + 20, expect, expect_n) == 0,
            "%s: the message's %zu bytes after the header are not the %zu written by hand", what,
            nw - 20, expect_n);
    if (same)
      printf("wire: %s = CDR_LE + 16-byte header + the message's %zu bytes\n", what, np - 4);
  }
  free(w);
  free(p);
}

/* The service writers as they write: the instance handle and the sequence number first. */
static void check_request_writer(Service* s, void* sample, const char* what) {
  const dds_entity_t own = reader(&s->request_spec, qos_of(false, 10));
  const int64_t seq = write_request(s, sample);
  size_t n = 0;
  unsigned char* b = payload_from(own, s->guid, &n, 1.0);
  CHECK(b != NULL && n >= 20, "%s: the request did not come back", what);
  if (b != NULL && n >= 20) {
    uint64_t guid = 0;
    int64_t got = 0;
    CHECK(header_at(b, n, &guid, &got) && b[1] == 1 && guid == s->guid && got == seq,
          "%s: encapsulation 0x%02x%02x, header (0x%016" PRIx64 ", %" PRId64
          "), expected CDR_LE with (0x%016" PRIx64 ", %" PRId64 ")",
          what, b[0], b[1], guid, got, s->guid, seq);
    printf("wire: %s on %s: header (instance handle 0x%016" PRIx64 ", seq %" PRId64 ")\n", what,
           s->request_name, guid, got);
  }
  free(b);
  dds_delete(own);
  /* rmw_cyclonedds's client id in the writer's and the reader's USER_DATA. */
  const dds_entity_t ends[2] = {s->request, s->reply};
  for (int k = 0; k < 2; ++k) {
    dds_qos_t* qos = dds_create_qos();
    void* data = NULL;
    size_t size = 0;
    const bool got = dds_get_qos(ends[k], qos) == DDS_RETCODE_OK &&
                     dds_qget_userdata(qos, &data, &size) && data != NULL;
    CHECK(got && size > 10 && strncmp(data, "clientid=", 9) == 0 &&
              ((const char*)data)[size - 1] == ';',
          "%s: USER_DATA of the %s is not \"clientid=...;\"", what, k == 0 ? "writer" : "reader");
    dds_free(data);
    dds_delete_qos(qos);
  }
}

_Static_assert(offsetof(vnsba_interop_ThroughPosesSendGoalRequest, message) ==
                       sizeof(vnsba_interop_RequestHeader) &&
                   offsetof(vnsba_interop_CancelGoalReply, message) ==
                       sizeof(vnsba_interop_RequestHeader),
               "a wrapped message follows its 16-byte header");

static int run_wire(void) {
  static Action to_pose, through;
  make_action(&to_pose, &kToPose);
  make_action(&through, &kThroughPoses);
  geometry_msgs_msg_dds__PoseStamped_ poses[2];
  set_pose(&poses[0], 1.25, -0.5, 0.3);
  set_pose(&poses[1], 3.5, 2.0, -1.0);
  const GoalId id = new_goal_id();
  const vnsba_interop_RequestHeader header = {0x0123456789abcdefull, 42};
  nav_msgs_msg_dds__Path_ path;
  memset(&path, 0, sizeof path);
  path.header.frame_id = "map";
  path.poses._length = path.poses._maximum = 2;
  path.poses._buffer = poses;

  /* ComputePathToPose's four messages. */
  vnsba_interop_ToPoseSendGoalRequest tp_goal;
  memset(&tp_goal, 0, sizeof tp_goal);
  tp_goal.header = header;
  memcpy(tp_goal.message.goal_id.uuid, id.uuid, 16);
  tp_goal.message.goal.goal = poses[0];
  tp_goal.message.goal.start = poses[1];
  tp_goal.message.goal.planner_id = "astar";
  tp_goal.message.goal.use_start = true;
  /* Zeroed first: Cyclone serialises a fixed-size type by copying its memory, C padding too. */
  vnsba_interop_ToPoseSendGoalReply tp_accept;
  memset(&tp_accept, 0, sizeof tp_accept);
  tp_accept.header = header;
  tp_accept.message.accepted = true;
  tp_accept.message.stamp = (builtin_interfaces_msg_dds__Time_){1700000000, 123456789};
  vnsba_interop_ToPoseGetResultRequest tp_get;
  memset(&tp_get, 0, sizeof tp_get);
  tp_get.header = header;
  memcpy(tp_get.message.goal_id.uuid, id.uuid, 16);
  vnsba_interop_ToPoseGetResultReply tp_result;
  memset(&tp_result, 0, sizeof tp_result);
  tp_result.header = header;
  tp_result.message.status = kStateSucceeded;
  tp_result.message.result.path = path;
  tp_result.message.result.planning_time = (builtin_interfaces_msg_dds__Duration_){0, 1500};
  tp_result.message.result.error_code = 0;
  tp_result.message.result.error_msg = "";
  const void* tp[kServices][2] = {{&tp_goal, &tp_accept}, {&tp_get, &tp_result}, {NULL, NULL}};
  /* ComputePathThroughPoses's, the goals a sequence (its length before the start's doubles). */
  vnsba_interop_ThroughPosesSendGoalRequest th_goal;
  memset(&th_goal, 0, sizeof th_goal);
  th_goal.header = header;
  memcpy(th_goal.message.goal_id.uuid, id.uuid, 16);
  th_goal.message.goal.goals._length = th_goal.message.goal.goals._maximum = 2;
  th_goal.message.goal.goals._buffer = poses;
  th_goal.message.goal.start = poses[1];
  th_goal.message.goal.planner_id = "jps";
  vnsba_interop_ThroughPosesSendGoalReply th_accept;
  memset(&th_accept, 0, sizeof th_accept);
  th_accept.header = header;
  th_accept.message.stamp = (builtin_interfaces_msg_dds__Time_){7, 8};
  vnsba_interop_ThroughPosesGetResultRequest th_get;
  memset(&th_get, 0, sizeof th_get);
  th_get.header = header;
  memcpy(th_get.message.goal_id.uuid, id.uuid, 16);
  vnsba_interop_ThroughPosesGetResultReply th_result;
  memset(&th_result, 0, sizeof th_result);
  th_result.header = header;
  th_result.message.status = kStateAborted;
  th_result.message.result.path = path;
  th_result.message.result.error_code = kNoViapointsGiven;
  th_result.message.result.error_msg = "no goals";
  const void* th[kServices][2] = {{&th_goal, &th_accept}, {&th_get, &th_result}, {NULL, NULL}};
  /* CancelGoal. */
  action_msgs_msg_dds__GoalInfo_ infos[2];
  memset(infos, 0, sizeof infos);
  memcpy(infos[0].goal_id.uuid, id.uuid, 16);
  infos[1].stamp.sec = 5;
  vnsba_interop_CancelGoalRequest cancel;
  memset(&cancel, 0, sizeof cancel);
  cancel.header = header;
  cancel.message.goal_info = infos[0];
  vnsba_interop_CancelGoalReply canceling;
  memset(&canceling, 0, sizeof canceling);
  canceling.header = header;
  canceling.message.goals_canceling._length = canceling.message.goals_canceling._maximum = 2;
  canceling.message.goals_canceling._buffer = infos;

  /* Two messages by hand, XCDR1 little-endian: GetResult_Request_ is the 16 bytes of the goal
   * id; SendGoal_Response_ is accepted (1 byte), 3 bytes of padding to align the stamp's int32
   * sec, then sec and nanosec (1700000000 = 0x6553f100, 123456789 = 0x075bcd15). */
  unsigned char get_bytes[16];
  memcpy(get_bytes, id.uuid, 16);
  const unsigned char accept_bytes[12] = {1,    0,    0,    0,    0x00, 0xf1,
                                          0x53, 0x65, 0x15, 0xcd, 0x5b, 0x07};
  const ActionType* types[2] = {&kToPose, &kThroughPoses};
  const void* const(*samples[2])[2] = {tp, th}; /* [action][service][request, reply] */
  for (int t = 0; t < 2; ++t) {
    for (int s = 0; s < kServices; ++s) {
      if (s == kCancelGoal && t == 1) continue; /* one type for both actions */
      for (int k = 0; k < 2; ++k) {
        const void* wrapped =
            s == kCancelGoal ? (k == 0 ? (const void*)&cancel : &canceling) : samples[t][s][k];
        /* The message itself is the wrapped sample's member right after the header (at 16: the
         * header's size, a multiple of every member's alignment). */
        const void* plain = (const char*)wrapped + sizeof(vnsba_interop_RequestHeader);
        char ros_type[128], what[96];
        service_type_name(types[t], s, k == 1, ros_type, sizeof ros_type);
        snprintf(what, sizeof what, "%s_%s_%s", types[t]->action, kServiceNames[s],
                 k == 0 ? "request" : "reply");
        const bool by_hand = t == 0 && ((s == kGetResult && k == 0) || (s == kSendGoal && k == 1));
        const unsigned char* expect = !by_hand ? NULL : s == kGetResult ? get_bytes : accept_bytes;
        check_wrapped_bytes(what, types[t]->wrapped[s][k], ros_type, wrapped, types[t]->plain[s][k],
                            plain, expect,
                            s == kGetResult ? sizeof get_bytes : sizeof accept_bytes);
      }
    }
  }

  /* The real request writers: handle, sequence, USER_DATA. */
  check_request_writer(&to_pose.service[kSendGoal], &tp_goal, "compute_path_to_pose send_goal");
  check_request_writer(&to_pose.service[kGetResult], &tp_get, "compute_path_to_pose get_result");
  check_request_writer(&to_pose.service[kCancelGoal], &cancel, "compute_path_to_pose cancel_goal");
  check_request_writer(&through.service[kSendGoal], &th_goal,
                       "compute_path_through_poses send_goal");
  CHECK(last_sequence == 4, "sequence numbers: %" PRId64 " after 4 requests", last_sequence);
  return report_run(participant, "interop action wire");
}

/* --------------------------------------------------------------------------------------------- */

int main(int argc, char** argv) {
  const double started = now_s();
  int domain = -1, bench_count = -1, fresh_count = -1, fresh_parallel = 1;
  bool wire = false, cancel = false, fresh_child = false, fresh_resident = false;
  for (int i = 1; i < argc; ++i) {
    const char* arg = argv[i];
    const char* value = i + 1 < argc ? argv[i + 1] : NULL;
    if (strcmp(arg, "--domain") == 0 && value && parse_int(value, 0, 232, &domain)) {
      ++i;
    } else if (strcmp(arg, "--namespace") == 0 && value) {
      ros_namespace = argv[++i];
    } else if (strcmp(arg, "--bench") == 0 && value && parse_int(value, 1, 1000000, &bench_count)) {
      ++i;
    } else if (strcmp(arg, "--fresh") == 0 && value && parse_int(value, 1, 100000, &fresh_count)) {
      ++i;
    } else if (strcmp(arg, "--fresh-parallel") == 0 && value &&
               parse_int(value, 1, 64, &fresh_parallel)) {
      ++i;
    } else if (strcmp(arg, "--fresh-resident") == 0) {
      fresh_resident = true;
    } else if (strcmp(arg, "--fresh-client") == 0) {
      fresh_child = true;
    } else if (strcmp(arg, "--wire") == 0) {
      wire = true;
    } else if (strcmp(arg, "--cancel") == 0) {
      cancel = true;
    } else {
      fprintf(
          stderr,
          "%s: bad argument '%s'\nusage: %s --domain 0..232 [--namespace NS]"
          " [--wire | --cancel | --bench N | --fresh N [--fresh-parallel P] [--fresh-resident]]\n",
          argv[0], arg, argv[0]);
      return 2;
    }
  }
  if (domain < 0 || wire + cancel + (bench_count > 0) + (fresh_count > 0) + fresh_child > 1) {
    fprintf(stderr,
            "%s: --domain 0..232 is required, and at most one of --wire, --cancel, --bench, "
            "--fresh\n",
            argv[0]);
    return 2;
  }
  make_map();
  participant = dds_create_participant((dds_domainid_t)domain, NULL, NULL);
  if (participant < 0) die("cannot create the participant", participant);
  if (fresh_child) return fresh_action_client(started);
  if (wire) return run_wire();
  if (cancel) return run_cancel();
  if (bench_count > 0) return bench(bench_count);
  if (fresh_count > 0) return run_fresh(domain, fresh_count, fresh_parallel, fresh_resident);
  return run_checks();
}
