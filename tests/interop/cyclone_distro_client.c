/* A client of vnsba_node on Eclipse Cyclone DDS 0.10 for what ros.distro changes, calling the
 * node the way a ROS 2 node on rmw_cyclonedds does (rmw_cyclonedds's 16-byte request header before
 * each request and reply, matched by it; see rmw_cyclonedds_distro_requests.idl), with the types
 * of one distribution under their ROS 2 type names. run_interop.sh starts the node with
 * ros.distro set and runs this client.
 *
 *   vnsba_cyclone_distro_client --domain N --distro humble|jazzy|kilted [--namespace NS]
 *
 * Checks (exit 1 with FAILED lines on stderr when one fails, 2 on bad usage), on the client's map
 * (client_common.h; the node with robot_radius 0, so a cell is blocked exactly where the map is
 * occupied), each answer against the client's own map (grid_oracle.c):
 *   - is_path_valid (rq/<ns>/is_path_validRequest, nav2_msgs::srv::dds_::IsPathValid_Request_,
 *     Kilted's with max_cost and consider_unknown_as_obstacle): the node's endpoints announce the
 *     ROS 2 type names; a path through the gap is valid with no index; a path with poses in the
 *     wall and one off the map lists exactly the poses the oracle finds blocked; with the robot's
 *     pose (robot_pose) beside a later pose, the poses before it are not checked (nav2_planner's
 *     isPathValid: from the pose closest to the robot); a path in frame "odom" is invalid with no
 *     index; an empty path is invalid; Kilted only: max_cost 0 makes every checked pose invalid
 *     (a free cell's cost 0 is not below it), max_cost 1 none;
 *   - Kilted: ComputePathThroughPoses with its goal a nav_msgs/Goals, two goals on either side of
 *     the wall: SUCCEEDED, the path from the start through both goals, free by the oracle;
 *   - Humble: ComputePathToPose across the wall SUCCEEDED (the path checked as above), and a goal
 *     in the wall ABORTED (Humble's result has no error_code: the status alone says it).
 */
#include <inttypes.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>

#include "check.h"
#include "client_common.h"
#include "dds/dds.h"
#include "rmw_cyclonedds_distro_requests.h"
#include "service_calls.h"

enum { kStateSucceeded = 4, kStateAborted = 6 };
typedef enum { kHumble, kJazzy, kKilted } Distro;
static Distro distro = kJazzy;

/* ---------------------------------------------------------------------------------------------
 * is_path_valid. */

static Service is_path_valid;

enum { kMaxPoses = 16, kMaxIndices = 32 };
typedef struct {
  int n;
  double x[kMaxPoses], y[kMaxPoses];
  const char* frame;
  uint8_t max_cost;                  /* Kilted */
  bool consider_unknown_as_obstacle; /* Kilted */
} PathQuery;

typedef struct {
  bool is_valid;
  int n;
  int32_t indices[kMaxIndices];
} Validity;

static void copy_indices(bool is_valid, const dds_sequence_int32* indices, Validity* v) {
  v->is_valid = is_valid;
  v->n = 0;
  for (uint32_t i = 0; i < indices->_length && v->n < kMaxIndices; ++i)
    v->indices[v->n++] = indices->_buffer[i];
}
static void copy_jazzy_validity(const void* sample, void* out) {
  const vnsba_interop_distro_JazzyIsPathValidReply* r = sample;
  copy_indices(r->message.is_valid, &r->message.invalid_pose_indices, out);
}
static void copy_kilted_validity(const void* sample, void* out) {
  const vnsba_interop_distro_KiltedIsPathValidReply* r = sample;
  copy_indices(r->message.is_valid, &r->message.invalid_pose_indices, out);
}

static Validity ask_is_path_valid(const PathQuery* q) {
  geometry_msgs_msg_dds__PoseStamped_ poses[kMaxPoses];
  for (int i = 0; i < q->n; ++i) {
    set_pose(&poses[i], q->x[i], q->y[i], 0.0);
    poses[i].header.frame_id = (char*)q->frame;
  }
  nav_msgs_msg_dds__Path_ path;
  memset(&path, 0, sizeof path);
  path.header.frame_id = (char*)q->frame;
  path.poses._length = path.poses._maximum = (uint32_t)q->n;
  path.poses._buffer = q->n > 0 ? poses : NULL;
  path.poses._release = false;
  int64_t seq;
  if (distro == kKilted) {
    vnsba_interop_distro_KiltedIsPathValidRequest r;
    memset(&r, 0, sizeof r);
    r.message.path = path;
    r.message.max_cost = q->max_cost;
    r.message.consider_unknown_as_obstacle = q->consider_unknown_as_obstacle;
    seq = write_request(&is_path_valid, &r);
  } else {
    vnsba_interop_distro_JazzyIsPathValidRequest r;
    memset(&r, 0, sizeof r);
    r.message.path = path;
    seq = write_request(&is_path_valid, &r);
  }
  Validity v = {false, -1, {0}};
  wait_reply(&is_path_valid, seq, distro == kKilted ? copy_kilted_validity : copy_jazzy_validity,
             &v, 10.0);
  return v;
}

/* The oracle: every pose from `first` on whose cell the client's map blocks (or off the map). */
static int oracle_invalid(const PathQuery* q, int first, int32_t* out) {
  int n = 0;
  for (int i = first; i < q->n; ++i)
    if (!grid_point_free(&client_map, q->x[i], q->y[i])) out[n++] = i;
  return n;
}

static void expect_indices(const char* what, const Validity* got, const int32_t* want, int n) {
  bool same = got->n == n;
  for (int i = 0; same && i < n; ++i) same = got->indices[i] == want[i];
  CHECK(same, "%s: %d invalid pose indices, the oracle %d", what, got->n, n);
  CHECK(got->is_valid == (n == 0), "%s: is_valid %d with %d invalid poses", what, got->is_valid, n);
  printf("is_path_valid %s: is_valid %d, %d invalid pose(s)\n", what, got->is_valid, got->n);
}

static void path_checks(dds_entity_t robot_pose) {
  PathQuery q = {0};
  q.frame = "map";
  q.max_cost = 254;
  /* Along row 14 through the gap (column 20 free there): valid. */
  for (int i = 0; i < 8; ++i) centre(14 + i, 14, &q.x[i], &q.y[i]);
  q.n = 8;
  Validity v = ask_is_path_valid(&q);
  int32_t want[kMaxPoses];
  expect_indices("through the gap", &v, want, oracle_invalid(&q, 0, want));
  CHECK(v.is_valid, "a path through the gap must be valid");

  /* Along row 3: poses 2 and 3 in the wall's column, pose 6 off the map. */
  centre(17, 3, &q.x[0], &q.y[0]);
  centre(19, 3, &q.x[1], &q.y[1]);
  centre(20, 3, &q.x[2], &q.y[2]);
  centre(20, 4, &q.x[3], &q.y[3]);
  centre(21, 3, &q.x[4], &q.y[4]);
  centre(25, 3, &q.x[5], &q.y[5]);
  q.x[6] = 5.0, q.y[6] = 0.0; /* the map ends at x = 3 m */
  q.n = 7;
  v = ask_is_path_valid(&q);
  const int blocked = oracle_invalid(&q, 0, want);
  CHECK(blocked == 3, "the oracle finds %d blocked poses, 3 expected", blocked);
  expect_indices("across the wall", &v, want, blocked);

  /* The robot beside pose 4: poses 0..3 are behind it and not checked. */
  geometry_msgs_msg_dds__PoseStamped_ pose;
  set_pose(&pose, q.x[4] + 0.01, q.y[4], 0.0);
  dds_write(robot_pose, &pose);
  dds_sleepfor(DDS_MSECS(300)); /* the node keeps the newest pose */
  v = ask_is_path_valid(&q);
  expect_indices("from the robot's pose", &v, want, oracle_invalid(&q, 4, want));
  if (distro == kKilted) {
    /* max_cost 0: a free cell's cost, 0, is not below it: every checked pose is invalid. */
    q.max_cost = 0;
    v = ask_is_path_valid(&q);
    int n = 0;
    for (int i = 4; i < q.n; ++i) want[n++] = i;
    expect_indices("max_cost 0", &v, want, n);
    q.max_cost = 1;
    v = ask_is_path_valid(&q);
    expect_indices("max_cost 1", &v, want, oracle_invalid(&q, 4, want));
    q.max_cost = 254;
  }
  /* Another frame: the path cannot be placed on the map; invalid, no index. */
  q.frame = "odom";
  v = ask_is_path_valid(&q);
  CHECK(!v.is_valid && v.n == 0, "a path in 'odom': is_valid %d, %d indices", v.is_valid, v.n);
  q.frame = "map";
  q.n = 0;
  v = ask_is_path_valid(&q);
  CHECK(!v.is_valid && v.n == 0, "an empty path: is_valid %d, %d indices", v.is_valid, v.n);
}

/* ---------------------------------------------------------------------------------------------
 * One goal of an action, send_goal then get_result. */

typedef struct {
  int status;
  int n;
  double* xy;
} GoalResult;

static void copy_kilted_accepted(const void* sample, void* out) {
  *(bool*)out =
      ((const vnsba_interop_distro_KiltedThroughPosesSendGoalReply*)sample)->message.accepted;
}
static void copy_humble_accepted(const void* sample, void* out) {
  *(bool*)out = ((const vnsba_interop_distro_HumbleToPoseSendGoalReply*)sample)->message.accepted;
}

static void copy_path_result(int8_t status, const nav_msgs_msg_dds__Path_* path, GoalResult* r) {
  r->status = status;
  r->n = (int)path->poses._length;
  r->xy = malloc(sizeof(double) * 2 * (size_t)(r->n > 0 ? r->n : 1));
  for (int i = 0; i < r->n; ++i) {
    r->xy[2 * i] = path->poses._buffer[i].pose.position.x;
    r->xy[2 * i + 1] = path->poses._buffer[i].pose.position.y;
  }
}
static void copy_kilted_result(const void* sample, void* out) {
  const vnsba_interop_distro_KiltedThroughPosesGetResultReply* r = sample;
  copy_path_result(r->message.status, &r->message.result.path, out);
  CHECK(r->message.result.error_code == 0, "kilted result: error_code %u, error_msg '%s'",
        r->message.result.error_code, r->message.result.error_msg);
}
static void copy_humble_result(const void* sample, void* out) {
  const vnsba_interop_distro_HumbleToPoseGetResultReply* r = sample;
  copy_path_result(r->message.status, &r->message.result.path, out);
}

typedef struct {
  Service send_goal, get_result;
} Action;

static void make_action(Action* a, const char* name, const char* ros_type,
                        const dds_topic_descriptor_t* const wrapped[4]) {
  char service[256], request_type[128], reply_type[128];
  snprintf(service, sizeof service, "%s/_action/send_goal", name);
  snprintf(request_type, sizeof request_type, "nav2_msgs::action::dds_::%s_SendGoal_Request_",
           ros_type);
  snprintf(reply_type, sizeof reply_type, "nav2_msgs::action::dds_::%s_SendGoal_Response_",
           ros_type);
  make_service(&a->send_goal, service, request_type, reply_type, wrapped[0], wrapped[1]);
  snprintf(service, sizeof service, "%s/_action/get_result", name);
  snprintf(request_type, sizeof request_type, "nav2_msgs::action::dds_::%s_GetResult_Request_",
           ros_type);
  snprintf(reply_type, sizeof reply_type, "nav2_msgs::action::dds_::%s_GetResult_Response_",
           ros_type);
  make_service(&a->get_result, service, request_type, reply_type, wrapped[2], wrapped[3]);
}

static void goal_id(uint8_t uuid[16]) {
  if (getrandom(uuid, 16, 0) != 16) die("getrandom", -1);
}

/* Sends the goal request `send`; true once the node accepted it. */
static bool goal_accepted(Action* a, void* send, CopyReply copy) {
  bool accepted = false;
  const int64_t seq = write_request(&a->send_goal, send);
  if (!wait_reply(&a->send_goal, seq, copy, &accepted, 15.0)) return false;
  CHECK(accepted, "the goal was not accepted");
  return accepted;
}

/* Sends the get_result request `get`; its reply copied into `result`. */
static bool goal_result(Action* a, void* get, CopyReply copy, GoalResult* result) {
  const int64_t seq = write_request(&a->get_result, get);
  return wait_reply(&a->get_result, seq, copy, result, 30.0);
}

static void kilted_goal(Action* a) {
  double sx, sy, g1x, g1y, g2x, g2y;
  centre(5, 3, &sx, &sy);
  centre(34, 3, &g1x, &g1y);
  centre(5, 26, &g2x, &g2y);
  geometry_msgs_msg_dds__PoseStamped_ goals[2];
  set_pose(&goals[0], g1x, g1y, 0.0);
  set_pose(&goals[1], g2x, g2y, 0.0);
  vnsba_interop_distro_KiltedThroughPosesSendGoalRequest r;
  memset(&r, 0, sizeof r);
  goal_id(r.message.goal_id.uuid);
  r.message.goal.goals.header.frame_id = "map";
  r.message.goal.goals.goals._length = r.message.goal.goals.goals._maximum = 2;
  r.message.goal.goals.goals._buffer = goals;
  set_pose(&r.message.goal.start, sx, sy, 0.0);
  r.message.goal.planner_id = "";
  r.message.goal.use_start = true;
  vnsba_interop_distro_KiltedThroughPosesGetResultRequest get;
  memset(&get, 0, sizeof get);
  memcpy(get.message.goal_id.uuid, r.message.goal_id.uuid, 16);
  GoalResult result = {0};
  if (!goal_accepted(a, &r, copy_kilted_accepted) ||
      !goal_result(a, &get, copy_kilted_result, &result))
    return;
  CHECK(result.status == kStateSucceeded, "kilted ComputePathThroughPoses: status %d",
        result.status);
  /* Start to the first goal, then on to the second: each part against the oracle. */
  int at = -1;
  for (int i = 0; i < result.n && at < 0; ++i)
    if (fabs(result.xy[2 * i] - g1x) < kAtTolerance &&
        fabs(result.xy[2 * i + 1] - g1y) < kAtTolerance)
      at = i;
  CHECK(at > 0, "kilted ComputePathThroughPoses: the first goal is not on the path");
  if (at > 0) {
    failures += grid_check_polyline(&client_map, "kilted leg 1", result.xy, at + 1, sx, sy, g1x,
                                    g1y, kAtTolerance, 0.1 + 1e-6, stderr);
    failures += grid_check_polyline(&client_map, "kilted leg 2", result.xy + 2 * at, result.n - at,
                                    g1x, g1y, g2x, g2y, kAtTolerance, 0.1 + 1e-6, stderr);
  }
  printf("kilted ComputePathThroughPoses (nav_msgs/Goals): status %d, %d poses\n", result.status,
         result.n);
  free(result.xy);
}

static void humble_goal(Action* a, double gx, double gy, int want_status) {
  double sx, sy;
  centre(5, 3, &sx, &sy);
  vnsba_interop_distro_HumbleToPoseSendGoalRequest r;
  memset(&r, 0, sizeof r);
  goal_id(r.message.goal_id.uuid);
  set_pose(&r.message.goal.goal, gx, gy, 0.0);
  set_pose(&r.message.goal.start, sx, sy, 0.0);
  r.message.goal.planner_id = "";
  r.message.goal.use_start = true;
  vnsba_interop_distro_HumbleToPoseGetResultRequest get;
  memset(&get, 0, sizeof get);
  memcpy(get.message.goal_id.uuid, r.message.goal_id.uuid, 16);
  GoalResult result = {0};
  if (!goal_accepted(a, &r, copy_humble_accepted) ||
      !goal_result(a, &get, copy_humble_result, &result))
    return;
  CHECK(result.status == want_status,
        "humble ComputePathToPose to (%.2f, %.2f): status %d, %d expected", gx, gy, result.status,
        want_status);
  if (want_status == kStateSucceeded)
    failures += grid_check_polyline(&client_map, "humble path", result.xy, result.n, sx, sy, gx, gy,
                                    kAtTolerance, 0.1 + 1e-6, stderr);
  else
    CHECK(result.n == 0, "humble: an aborted goal's path has %d poses", result.n);
  printf("humble ComputePathToPose: status %d, %d poses\n", result.status, result.n);
  free(result.xy);
}

static int run(void) {
  const nav_msgs_msg_dds__OccupancyGrid_ map = map_message(&client_map);
  const dds_entity_t map_writer = writer(&kMap, qos_of(true, 1));
  dds_write(map_writer, &map);
  const dds_entity_t robot_pose = writer(&kRobotPose, ros_default_qos());
  if (distro == kKilted)
    make_service(&is_path_valid, "is_path_valid", "nav2_msgs::srv::dds_::IsPathValid_Request_",
                 "nav2_msgs::srv::dds_::IsPathValid_Response_",
                 &vnsba_interop_distro_KiltedIsPathValidRequest_desc,
                 &vnsba_interop_distro_KiltedIsPathValidReply_desc);
  else
    make_service(&is_path_valid, "is_path_valid", "nav2_msgs::srv::dds_::IsPathValid_Request_",
                 "nav2_msgs::srv::dds_::IsPathValid_Response_",
                 &vnsba_interop_distro_JazzyIsPathValidRequest_desc,
                 &vnsba_interop_distro_JazzyIsPathValidReply_desc);
  static Action action;
  static const dds_topic_descriptor_t* const kilted[4] = {
      &vnsba_interop_distro_KiltedThroughPosesSendGoalRequest_desc,
      &vnsba_interop_distro_KiltedThroughPosesSendGoalReply_desc,
      &vnsba_interop_distro_KiltedThroughPosesGetResultRequest_desc,
      &vnsba_interop_distro_KiltedThroughPosesGetResultReply_desc};
  static const dds_topic_descriptor_t* const humble[4] = {
      &vnsba_interop_distro_HumbleToPoseSendGoalRequest_desc,
      &vnsba_interop_distro_HumbleToPoseSendGoalReply_desc,
      &vnsba_interop_distro_HumbleToPoseGetResultRequest_desc,
      &vnsba_interop_distro_HumbleToPoseGetResultReply_desc};
  dds_entity_t entities[8] = {map_writer, robot_pose, is_path_valid.request, is_path_valid.reply};
  int n = 4;
  if (distro == kKilted)
    make_action(&action, "compute_path_through_poses", "ComputePathThroughPoses", kilted);
  if (distro == kHumble) make_action(&action, "compute_path_to_pose", "ComputePathToPose", humble);
  if (distro != kJazzy) {
    entities[n++] = action.send_goal.request;
    entities[n++] = action.send_goal.reply;
    entities[n++] = action.get_result.request;
    entities[n++] = action.get_result.reply;
  }
  if (wait_matched(entities, n, 20.0) < 0) {
    fprintf(stderr, "FAILED: the node did not match all %d endpoints within 20 s\n", n);
    return 1;
  }
  /* The node's endpoints announce the ROS 2 type names. */
  const dds_entity_t publications =
      dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, NULL, NULL);
  const dds_entity_t subscriptions =
      dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, NULL, NULL);
  CHECK(check_remote_type_names(subscriptions, &is_path_valid.request_spec) > 0 &&
            check_remote_type_names(publications, &is_path_valid.reply_spec) > 0,
        "is_path_valid: the node's endpoints do not announce the ROS 2 type names");
  if (distro != kJazzy)
    CHECK(check_remote_type_names(subscriptions, &action.send_goal.request_spec) > 0 &&
              check_remote_type_names(publications, &action.get_result.reply_spec) > 0,
          "the action's endpoints do not announce the ROS 2 type names");
  dds_sleepfor(DDS_MSECS(500)); /* the latched map reaches the node and is installed */
  path_checks(robot_pose);
  if (distro == kKilted) kilted_goal(&action);
  if (distro == kHumble) {
    double gx, gy, wx, wy;
    centre(34, 3, &gx, &gy);
    centre(20, 5, &wx, &wy);
    humble_goal(&action, gx, gy, kStateSucceeded);
    humble_goal(&action, wx, wy, kStateAborted);
  }
  return report_run(participant, "interop distro");
}

int main(int argc, char** argv) {
  int domain = -1;
  for (int i = 1; i < argc; ++i) {
    const char* value = i + 1 < argc ? argv[i + 1] : NULL;
    if (strcmp(argv[i], "--domain") == 0 && value) {
      domain = atoi(argv[++i]);
    } else if (strcmp(argv[i], "--namespace") == 0 && value) {
      ros_namespace = argv[++i];
    } else if (strcmp(argv[i], "--distro") == 0 && value) {
      ++i;
      distro = strcmp(value, "humble") == 0   ? kHumble
               : strcmp(value, "kilted") == 0 ? kKilted
               : strcmp(value, "jazzy") == 0  ? kJazzy
                                              : (Distro)-1;
      if ((int)distro < 0) {
        fprintf(stderr, "%s: --distro: found '%s', expected humble, jazzy or kilted\n", argv[0],
                value);
        return 2;
      }
    } else {
      fprintf(stderr, "usage: %s --domain 0..232 --distro humble|jazzy|kilted [--namespace NS]\n",
              argv[0]);
      return 2;
    }
  }
  if (domain < 0 || domain > 232) {
    fprintf(stderr, "%s: --domain 0..232 is required\n", argv[0]);
    return 2;
  }
  make_map();
  participant = dds_create_participant((dds_domainid_t)domain, NULL, NULL);
  if (participant < 0) die("cannot create the participant", participant);
  return run();
}
