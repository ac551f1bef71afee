/* What the two Cyclone DDS clients of vnsba_node share (cyclone_client.c: topics, the goal tool,
 * debug layers, fresh clients; cyclone_action_client.c: Nav2's actions called the way
 * rmw_cyclonedds calls them): one participant and its topics under the run's namespace, with
 * ROS 2's DDS names and QoS; waiting for matches and data; the client's map and the oracle's
 * checks of a path on it; PlanRequest -> PlanStatus round trips; wire-format checks;
 * percentiles. Plain C on Cyclone DDS 0.10's C API. Every failed check is a CHECK (check.h)
 * counted in `failures`. */
#ifndef VNSBA_INTEROP_CLIENT_COMMON_H
#define VNSBA_INTEROP_CLIENT_COMMON_H

#include <stdbool.h>
#include <stdint.h>

#include "dds/dds.h"
#include "geometry_msgs/msg/PoseStamped.h"
#include "grid_oracle.h"
#include "nav_msgs/msg/OccupancyGrid.h"
#include "nav_msgs/msg/Path.h"
#include "vnsba_msgs/msg/PlanRequest.h"
#include "vnsba_msgs/msg/PlanStatus.h"

#define STATUS(name) vnsba_msgs_msg_PlanStatus_Constants_##name

/* Failed checks so far (check.h's CHECK counts here); a client exits 1 when it is not 0. */
extern int failures;

/* Deletes `participant` and reports the run: 0 when every check passed ("<what>: all checks
 * passed"), 1 with the count of failed checks otherwise. */
int report_run(dds_entity_t participant, const char* what);

/* ---------------------------------------------------------------------------------------------
 * The client's map: 40 x 30 cells of 0.1 m, origin (-1, -0.5), a wall across x in [1.0, 1.1) m
 * (column 20) with a gap of 6 cells (rows 12..17, y in [0.7, 1.3) m). Every start and goal the
 * clients request on it lies on opposite sides of the wall with the straight line between them
 * blocked, so each path must find the gap; on the node's binary grid (run_interop.sh:
 * robot_radius 0) the shortest paths pass the wall's ends within centimetres.
 */
enum { kWidth = 40, kHeight = 30, kWallColumn = 20, kGapFirstRow = 12, kGapLastRow = 17 };
extern const Grid client_map;
/* Fills client_map's cells; call once before using it. */
void make_map(void);
/* The centre of client_map's cell (cx, cy), metres. */
void centre(int cx, int cy, double* x, double* y);
/* The plan_request's start and goal: cell (5, 3) to cell (34, 3), the wall between them. */
void request_ends(double* sx, double* sy, double* gx, double* gy);

/* Poses at a cell centre come back within float rounding of it (the map's resolution is a
 * float32 on the wire), metres. */
extern const double kAtTolerance;

/* --------------------------------------------------------------------------------------------- */

/* Monotonic clock, seconds. */
double now_s(void);
/* Prints what failed with Cyclone's return code and exits 2 (the DDS setup itself failed). */
void die(const char* what, dds_return_t rc);

extern dds_entity_t participant;
/* The run's ROS 2 namespace, without slashes ("" for none). */
extern const char* ros_namespace;

/* A topic, with the type name Fast DDS registers (fastddsgen's names of idl/). */
typedef struct {
  const char* name; /* ROS 2 name relative to the namespace; a service's ends "Request"/"Reply" */
  const dds_topic_descriptor_t* desc;
  const char* type_name;
  const char* prefix; /* the DDS name's prefix: NULL for "rt/" (a topic); "rq/" or "rr/" (the
                         request or reply topic of a service), as rmw_cyclonedds names them */
} TopicSpec;

/* The node's topics both clients use: projected_map, plan_request, robot_pose, plan_status. */
extern const TopicSpec kMap, kRequest, kRobotPose, kStatus;

/* "<prefix><ns>/<name>", as a ROS 2 node in namespace /<ns> names the DDS topic. */
void dds_topic_name(const TopicSpec* spec, char* out, size_t size);
/* Creates the topic and checks that Cyclone's type name for it is spec->type_name. */
dds_entity_t topic(const TopicSpec* spec);
/* ROS 2's QoS profiles as rclcpp sets them: reliable, the durability, keep last depth. */
dds_qos_t* qos_of(bool transient_local, int32_t depth);
/* rclcpp::QoS(10), the default of publishers and subscriptions: reliable, volatile, keep last
 * 10. */
dds_qos_t* ros_default_qos(void);
/* A writer or reader on spec's topic; takes ownership of qos. */
dds_entity_t writer(const TopicSpec* spec, dds_qos_t* qos);
dds_entity_t reader(const TopicSpec* spec, dds_qos_t* qos);
bool is_matched(dds_entity_t e);
/* Waits until every entity has matched a remote endpoint (woken by the match, not polling);
 * returns the time it happened, or a negative number after `timeout` seconds. */
double wait_matched(const dds_entity_t* entities, int n, double timeout);
/* Sleeps until `r` has data or `until` (monotonic seconds) passes. */
void wait_data(dds_entity_t r, double until);
/* Takes samples from `r` until `accept` takes one (returns true) or `until` passes. */
typedef bool (*Accept)(const void* sample, void* ctx);
bool take_until(dds_entity_t r, Accept accept, void* ctx, double until);

/* XCDR1 encapsulations: CDR_BE 0, CDR_LE 1, PL_CDR_BE 2, PL_CDR_LE 3 (XCDR2 uses 6..11). Checks
 * that the samples `cdr_reader` (a reader for dds_takecdr) gets within `timeout` seconds are in
 * XCDR1, and that there is one. */
void check_xcdr1(dds_entity_t cdr_reader, const char* what, double timeout);
/* The node's endpoints on `spec`'s topic, as it announced them in discovery (`builtin`: a reader
 * of DCPSPublication or DCPSSubscription): their type name must be the one Cyclone uses; returns
 * how many there are. */
int check_remote_type_names(dds_entity_t builtin, const TopicSpec* spec);

/* ------------------------------------------------------------------------------------------ */
/* Copies of received messages. */

typedef struct {
  int n;
  double* xy;      /* 2n values, metres */
  double last_yaw; /* radians */
  int32_t sec;
  uint32_t nanosec;
  char frame[64];
} Path;

void free_path(Path* p);
void copy_path(const nav_msgs_msg_dds__Path_* msg, Path* p);
bool same_path(const Path* a, const Path* b);
/* A PoseStamped in frame "map" at (x, y) metres facing yaw radians. */
void set_pose(geometry_msgs_msg_dds__PoseStamped_* p, double x, double y, double yaw);
dds_guid_t guid_of(dds_entity_t e);
/* The OccupancyGrid of `g` in frame "map" (its cells borrowed, not copied). */
nav_msgs_msg_dds__OccupancyGrid_ map_message(const Grid* g);
/* The checks every path of the node passes on the map `g`: frame "map", from (sx, sy) to (gx, gy)
 * within kAtTolerance, every segment free and at most one cell long (see grid_oracle.h). */
void check_path(const Grid* g, const char* what, const Path* p, double sx, double sy, double gx,
                double gy);

/* ------------------------------------------------------------------------------------------ */
/* PlanRequest -> PlanStatus. */

typedef struct {
  bool found;
  int code, subject;
  char request_id[128], code_name[64], message[512];
  uint8_t writer_guid[16];
  long long sequence_number, planning_time_us, expanded;
  Path path;
} Answer;

void free_answer(Answer* a);

/* What the answer to one sample must carry: its writer and sequence number (the DDS sample
 * identity), and for a request its id. A status with either is taken as the answer, and the
 * caller then checks both. */
typedef struct {
  const char* request_id; /* NULL: any (a goal's status, request_id "goal-<n>") */
  int subject;
  dds_guid_t writer_guid;
  long long sequence_number;
} Awaited;

/* The status answering `w` within `timeout` seconds; statuses about anything else are skipped. */
Answer wait_status(dds_entity_t statuses, const Awaited* w, double timeout);

/* The writers and readers of one run. */
typedef struct {
  dds_entity_t map, request, robot_pose, goal;          /* writers */
  dds_entity_t status, plan;                            /* readers, ROS 2 default QoS */
  dds_entity_t raw, pruned, forward, backward, meeting; /* debug readers (--debug-layers) */
  long long request_writes, goal_writes;
} Bus;

/* Writes one PlanRequest from (sx, sy) to (gx, gy) (metres, the node's default planner) on
 * bus->request and returns what its status must carry. */
Awaited send_request(Bus* bus, const char* id, double sx, double sy, double gx, double gy);

/* ------------------------------------------------------------------------------------------ */
/* Measurements and command lines. */

/* Nearest-rank percentile (p in [0, 1]) of n values; sorts v. */
double percentile(double* v, int n, double p);
/* One line: p50, p90, p99 and max of n values in milliseconds. */
void print_stats(const char* what, double* v, int n);
/* A whole decimal integer in [lo, hi]. */
bool parse_int(const char* text, int lo, int hi, int* out);

#endif /* VNSBA_INTEROP_CLIENT_COMMON_H */
