/* The helpers both Cyclone DDS clients share; see client_common.h. */
#include "client_common.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "check.h"
#include "dds/ddsi/ddsi_serdata.h"

int failures = 0;

/* The client's map (client_common.h). */
static int8_t cells[kWidth * kHeight];
const Grid client_map = {kWidth, kHeight, 0.1, -1.0, -0.5, 65, cells};

void make_map(void) {
  memset(cells, 0, sizeof cells);
  for (int y = 0; y < kHeight; ++y)
    if (y < kGapFirstRow || y > kGapLastRow) cells[y * kWidth + kWallColumn] = 100;
}

void centre(int cx, int cy, double* x, double* y) {
  grid_cell_centre(&client_map, cx, cy, x, y);
}

void request_ends(double* sx, double* sy, double* gx, double* gy) {
  centre(5, 3, sx, sy);
  centre(34, 3, gx, gy);
}

const double kAtTolerance = 1e-4;

/* --------------------------------------------------------------------------------------------- */

double now_s(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

void die(const char* what, dds_return_t rc) {
  fprintf(stderr, "%s: %s\n", what, dds_strretcode(rc < 0 ? -rc : rc));
  exit(2);
}

dds_entity_t participant;
const char* ros_namespace = "";

const TopicSpec kMap = {"projected_map", &nav_msgs_msg_dds__OccupancyGrid__desc,
                        "nav_msgs::msg::dds_::OccupancyGrid_", NULL};
const TopicSpec kRequest = {"plan_request", &vnsba_msgs_msg_dds__PlanRequest__desc,
                            "vnsba_msgs::msg::dds_::PlanRequest_", NULL};
const TopicSpec kRobotPose = {"robot_pose", &geometry_msgs_msg_dds__PoseStamped__desc,
                              "geometry_msgs::msg::dds_::PoseStamped_", NULL};
const TopicSpec kStatus = {"plan_status", &vnsba_msgs_msg_dds__PlanStatus__desc,
                           "vnsba_msgs::msg::dds_::PlanStatus_", NULL};

void dds_topic_name(const TopicSpec* spec, char* out, size_t size) {
  snprintf(out, size, "%s%s%s%s", spec->prefix ? spec->prefix : "rt/", ros_namespace,
           *ros_namespace ? "/" : "", spec->name);
}

dds_entity_t topic(const TopicSpec* spec) {
  char name[256];
  dds_topic_name(spec, name, sizeof name);
  const dds_entity_t t = dds_create_topic(participant, spec->desc, name, NULL, NULL);
  if (t < 0) die(name, t);
  /* idlc's name for the type is the one Fast DDS registers: topics and types both match. */
  char type_name[256];
  CHECK(dds_get_type_name(t, type_name, sizeof type_name) >= 0 &&
            strcmp(type_name, spec->type_name) == 0,
        "%s: Cyclone's type name is \"%s\", Fast DDS registers \"%s\"", name, type_name,
        spec->type_name);
  return t;
}

dds_qos_t* qos_of(bool transient_local, int32_t depth) {
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(qos,
                      transient_local ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, depth);
  return qos;
}

dds_qos_t* ros_default_qos(void) {
  return qos_of(false, 10);
}

dds_entity_t writer(const TopicSpec* spec, dds_qos_t* qos) {
  const dds_entity_t w = dds_create_writer(participant, topic(spec), qos, NULL);
  dds_delete_qos(qos);
  if (w < 0) die(spec->name, w);
  dds_set_status_mask(w, DDS_PUBLICATION_MATCHED_STATUS);
  return w;
}

dds_entity_t reader(const TopicSpec* spec, dds_qos_t* qos) {
  const dds_entity_t r = dds_create_reader(participant, topic(spec), qos, NULL);
  dds_delete_qos(qos);
  if (r < 0) die(spec->name, r);
  dds_set_status_mask(r, DDS_SUBSCRIPTION_MATCHED_STATUS | DDS_DATA_AVAILABLE_STATUS);
  return r;
}

bool is_matched(dds_entity_t e) {
  dds_publication_matched_status_t p;
  if (dds_get_publication_matched_status(e, &p) == DDS_RETCODE_OK) return p.current_count > 0;
  dds_subscription_matched_status_t s;
  return dds_get_subscription_matched_status(e, &s) == DDS_RETCODE_OK && s.current_count > 0;
}

double wait_matched(const dds_entity_t* entities, int n, double timeout) {
  const dds_entity_t ws = dds_create_waitset(participant);
  for (int i = 0; i < n; ++i) dds_waitset_attach(ws, entities[i], entities[i]);
  const double end = now_s() + timeout;
  double done = -1;
  for (;;) {
    bool all = true;
    for (int i = 0; i < n && all; ++i) all = is_matched(entities[i]);
    if (all) {
      done = now_s();
      break;
    }
    const double left = end - now_s();
    if (left <= 0) break;
    dds_waitset_wait(ws, NULL, 0, (dds_duration_t)(fmin(left, 0.05) * 1e9));
  }
  dds_delete(ws);
  return done;
}

void wait_data(dds_entity_t r, double until) {
  const double left = until - now_s();
  if (left <= 0) return;
  const dds_entity_t ws = dds_create_waitset(participant);
  const dds_entity_t cond = dds_create_readcondition(r, DDS_ANY_STATE);
  dds_waitset_attach(ws, cond, r);
  dds_waitset_wait(ws, NULL, 0, (dds_duration_t)(left * 1e9));
  dds_delete(cond);
  dds_delete(ws);
}

/* ------------------------------------------------------------------------------------------ */
/* Copies of received messages. */

void free_path(Path* p) {
  free(p->xy);
  memset(p, 0, sizeof *p);
}

static double yaw_of(const geometry_msgs_msg_dds__Quaternion_* q) {
  return atan2(2.0 * (q->w * q->z + q->x * q->y), 1.0 - 2.0 * (q->y * q->y + q->z * q->z));
}

void copy_path(const nav_msgs_msg_dds__Path_* msg, Path* p) {
  free_path(p);
  p->n = (int)msg->poses._length;
  p->xy = malloc(sizeof(double) * 2 * (size_t)(p->n > 0 ? p->n : 1));
  for (int i = 0; i < p->n; ++i) {
    p->xy[2 * i] = msg->poses._buffer[i].pose.position.x;
    p->xy[2 * i + 1] = msg->poses._buffer[i].pose.position.y;
  }
  if (p->n > 0) p->last_yaw = yaw_of(&msg->poses._buffer[p->n - 1].pose.orientation);
  p->sec = msg->header.stamp.sec;
  p->nanosec = msg->header.stamp.nanosec;
  snprintf(p->frame, sizeof p->frame, "%s", msg->header.frame_id ? msg->header.frame_id : "");
}

bool same_path(const Path* a, const Path* b) {
  if (a->n != b->n || a->sec != b->sec || a->nanosec != b->nanosec) return false;
  return a->n == 0 || memcmp(a->xy, b->xy, sizeof(double) * 2 * (size_t)a->n) == 0;
}

void free_answer(Answer* a) {
  free_path(&a->path);
  memset(a, 0, sizeof *a);
}

static bool answers(const vnsba_msgs_msg_dds__PlanStatus_* s, const Awaited* w) {
  if (s->subject != w->subject) return false;
  const bool identity = memcmp(s->request_writer_guid, w->writer_guid.v, 16) == 0 &&
                        s->request_sequence_number == w->sequence_number;
  return identity || (w->request_id != NULL && strcmp(s->request_id, w->request_id) == 0);
}

Answer wait_status(dds_entity_t statuses, const Awaited* w, double timeout) {
  Answer a;
  memset(&a, 0, sizeof a);
  const double end = now_s() + timeout;
  while (!a.found) {
    void* samples[16] = {NULL};
    dds_sample_info_t infos[16];
    const int n = dds_take(statuses, samples, infos, 16, 16);
    for (int i = 0; i < n; ++i) {
      const vnsba_msgs_msg_dds__PlanStatus_* s = samples[i];
      if (!infos[i].valid_data || a.found || !answers(s, w)) continue;
      a.found = true;
      a.code = s->code;
      a.subject = s->subject;
      snprintf(a.request_id, sizeof a.request_id, "%s", s->request_id);
      snprintf(a.code_name, sizeof a.code_name, "%s", s->code_name);
      snprintf(a.message, sizeof a.message, "%s", s->message);
      memcpy(a.writer_guid, s->request_writer_guid, 16);
      a.sequence_number = (long long)s->request_sequence_number;
      a.planning_time_us = (long long)s->planning_time_us;
      a.expanded = (long long)s->expanded;
      copy_path(&s->path, &a.path);
    }
    if (n > 0) dds_return_loan(statuses, samples, n);
    if (a.found || now_s() >= end) break;
    if (n <= 0) wait_data(statuses, end);
  }
  return a;
}

bool take_until(dds_entity_t r, Accept accept, void* ctx, double until) {
  for (;;) {
    void* samples[8] = {NULL};
    dds_sample_info_t infos[8];
    const int n = dds_take(r, samples, infos, 8, 8);
    bool done = false;
    for (int i = 0; i < n && !done; ++i) done = infos[i].valid_data && accept(samples[i], ctx);
    if (n > 0) dds_return_loan(r, samples, n);
    if (done) return true;
    if (now_s() >= until) return false;
    if (n <= 0) wait_data(r, until);
  }
}

/* ------------------------------------------------------------------------------------------ */
/* Wire format and discovery. */

void check_xcdr1(dds_entity_t cdr_reader, const char* what, double timeout) {
  struct ddsi_serdata* data[8] = {NULL};
  dds_sample_info_t infos[8];
  const double end = now_s() + timeout;
  int seen = 0;
  while (seen == 0 && now_s() < end) {
    const int n = dds_takecdr(cdr_reader, data, 8, infos, DDS_ANY_STATE);
    for (int i = 0; i < n; ++i) {
      if (infos[i].valid_data) {
        unsigned char header[4];
        ddsi_serdata_to_ser(data[i], 0, sizeof header, header);
        const unsigned id = (unsigned)header[0] << 8 | header[1];
        CHECK(id <= 3, "%s: encapsulation 0x%04x on the wire, expected XCDR1 (0x0000..0x0003)",
              what, id);
        if (seen++ == 0) printf("wire: %s in encapsulation 0x%04x (XCDR1)\n", what, id);
      }
      ddsi_serdata_unref(data[i]);
    }
    if (n <= 0) wait_data(cdr_reader, end);
  }
  CHECK(seen > 0, "%s: no sample to check the encapsulation of", what);
}

int check_remote_type_names(dds_entity_t builtin, const TopicSpec* spec) {
  char name[256];
  dds_topic_name(spec, name, sizeof name);
  dds_guid_t own;
  dds_get_guid(participant, &own);
  /* Every endpoint of the domain is in the builtin reader: the node's (about 40 with its action
   * servers), the client's own and any other run's on the same domain id. */
  enum { kMaxEndpoints = 512 };
  static void* samples[kMaxEndpoints];
  static dds_sample_info_t infos[kMaxEndpoints];
  memset(samples, 0, sizeof samples);
  const int n = dds_read(builtin, samples, infos, kMaxEndpoints, kMaxEndpoints);
  int found = 0;
  for (int i = 0; i < n; ++i) {
    const dds_builtintopic_endpoint_t* e = samples[i];
    if (!infos[i].valid_data || strcmp(e->topic_name, name) != 0 ||
        memcmp(e->participant_key.v, own.v, 12) == 0)
      continue;
    ++found;
    CHECK(strcmp(e->type_name, spec->type_name) == 0,
          "%s: the node announces type \"%s\", Cyclone uses \"%s\"", name, e->type_name,
          spec->type_name);
  }
  if (n > 0) dds_return_loan(builtin, samples, n);
  return found;
}

nav_msgs_msg_dds__OccupancyGrid_ map_message(const Grid* g) {
  nav_msgs_msg_dds__OccupancyGrid_ m;
  memset(&m, 0, sizeof m);
  m.header.frame_id = "map";
  m.info.resolution = (float)g->resolution;
  m.info.width = (uint32_t)g->width;
  m.info.height = (uint32_t)g->height;
  m.info.origin.position.x = g->origin_x;
  m.info.origin.position.y = g->origin_y;
  m.info.origin.orientation.w = 1.0;
  m.data._length = m.data._maximum = (uint32_t)g->width * (uint32_t)g->height;
  m.data._buffer = (int8_t*)g->data; /* only read: _release is false */
  m.data._release = false;
  return m;
}

void set_pose(geometry_msgs_msg_dds__PoseStamped_* p, double x, double y, double yaw) {
  memset(p, 0, sizeof *p);
  p->header.frame_id = "map";
  p->pose.position.x = x;
  p->pose.position.y = y;
  p->pose.orientation.z = sin(yaw / 2);
  p->pose.orientation.w = cos(yaw / 2);
}

dds_guid_t guid_of(dds_entity_t e) {
  dds_guid_t g;
  memset(&g, 0, sizeof g);
  dds_get_guid(e, &g);
  return g;
}

Awaited send_request(Bus* bus, const char* id, double sx, double sy, double gx, double gy) {
  vnsba_msgs_msg_dds__PlanRequest_ request;
  memset(&request, 0, sizeof request);
  request.id = (char*)id;
  set_pose(&request.start, sx, sy, 0.0);
  set_pose(&request.goal, gx, gy, 0.0);
  request.planner = "";
  const dds_return_t rc = dds_write(bus->request, &request);
  CHECK(rc == DDS_RETCODE_OK, "writing request %s: %s", id, dds_strretcode(-rc));
  /* Cyclone numbers a writer's samples 1, 2, ...: the sample identity the node echoes. */
  const Awaited w = {id, STATUS(SUBJECT_REQUEST), guid_of(bus->request), ++bus->request_writes};
  return w;
}

void check_path(const Grid* g, const char* what, const Path* p, double sx, double sy, double gx,
                double gy) {
  CHECK(strcmp(p->frame, "map") == 0, "%s: frame_id \"%s\", expected \"map\"", what, p->frame);
  /* The node's default path_spacing is the map's resolution. */
  failures += grid_check_polyline(g, what, p->xy, p->n, sx, sy, gx, gy, kAtTolerance,
                                  g->resolution * (1 + 1e-6), stderr);
}

/* ------------------------------------------------------------------------------------------ */
/* Measurements and command lines. */

static int compare_doubles(const void* a, const void* b) {
  const double x = *(const double*)a, y = *(const double*)b;
  return (x > y) - (x < y);
}

double percentile(double* v, int n, double p) {
  qsort(v, (size_t)n, sizeof *v, compare_doubles);
  int i = (int)ceil(p * n) - 1;
  return v[i < 0 ? 0 : i];
}

void print_stats(const char* what, double* v, int n) {
  printf("  %-34s p50 %7.3f  p90 %7.3f  p99 %7.3f  max %7.3f ms\n", what, percentile(v, n, 0.5),
         percentile(v, n, 0.9), percentile(v, n, 0.99), percentile(v, n, 1.0));
}

bool parse_int(const char* text, int lo, int hi, int* out) {
  char* end = NULL;
  errno = 0;
  const long v = strtol(text, &end, 10);
  if (errno != 0 || end == text || *end != '\0' || v < lo || v > hi) return false;
  *out = (int)v;
  return true;
}

int report_run(dds_entity_t participant, const char* what) {
  dds_delete(participant);
  if (failures > 0) {
    fprintf(stderr, "%d check(s) failed\n", failures);
    return 1;
  }
  printf("%s: all checks passed\n", what);
  return 0;
}
