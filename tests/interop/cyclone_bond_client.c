/* nav2_lifecycle_manager's side of a bond with vnsba_node, on Eclipse Cyclone DDS 0.10, as a ROS 2
 * node on rmw_cyclonedds puts it on the wire: bond/msg/Status on rt/<ns>/bond (bondcpp, branch
 * ros2: a publisher with rclcpp::QoS(KeepLast(5)) and a subscription with rclcpp::QoS(100), both
 * reliable and volatile), a heartbeat every 0.1 s with the bond's id (the node's name) and a
 * random instance_id of its own; the manager's bond breaks after bond_timeout seconds without a
 * heartbeat of the node (nav2_lifecycle_manager's createBondConnection: setHeartbeatTimeout(
 * bond_timeout), setHeartbeatPeriod(0.10); checkBondConnections). run_interop.sh starts the node
 * and runs this client.
 *
 *   vnsba_cyclone_bond_client --domain N [--namespace NS] --id NAME --node-pid PID
 *                             [--bond-timeout S] [--period S] [--lifecycle]
 *
 * Without --lifecycle the node runs with bond.mode always (a self-activating node that bonds from
 * start to stop) and bond.heartbeat_period --period. With --lifecycle it is a managed node named
 * NAME (lifecycle: managed, --name NAME, bond.mode managed) and the client first makes the
 * manager's calls (lifecycle_calls.h, rmw_cyclonedds's mapping): get_state unconfigured (1),
 * configure, get_state inactive (2), activate, get_state active (3), and only then bonds (Nav2's
 * changeStateForNode); after the checks below for a first bond, deactivate: the node breaks its
 * bond at once (active=false), get_state inactive; activate again: a new bond with a new instance
 * of the node; the watchdog on that one; then deactivate, cleanup and shutdown (ids 4, 2, 5) to
 * finalized (4), as the manager's reset and shutdown.
 * Checks (exit 1 with FAILED lines when one fails, 2 on bad usage):
 *   - the bond forms within bond_timeout / 2 (the manager's waitUntilFormed);
 *   - every heartbeat of the node carries id NAME, one instance_id other than ours, active true,
 *     heartbeat_period --period; the median gap between them is --period within 40 %;
 *   - the watchdog: the node stopped (SIGSTOP to --node-pid), the manager's bond breaks after
 *     bond_timeout of silence: not before bond_timeout - one period, and within bond_timeout +
 *     0.5 s; then the node is continued (SIGCONT);
 *   - a bond of another id never forms.
 */
#include <inttypes.h>
#include <math.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <unistd.h>

#include "bond/msg/Status.h"
#include "check.h"
#include "client_common.h"
#include "dds/dds.h"
#include "lifecycle_calls.h"

static const TopicSpec kBond = {"bond", &bond_msg_dds__Status__desc, "bond::msg::dds_::Status_",
                                NULL};

/* BondSM's states, as far as the manager's watchdog needs them. */
typedef enum { kWaiting, kAlive, kDead } BondState;

typedef struct {
  const char* id;
  char instance_id[37];
  double heartbeat_timeout; /* s */
  double period;            /* s */
  dds_entity_t writer, reader;
  BondState state;
  double last_heard; /* monotonic s of the sister's last heartbeat */
  double next_publish;
  /* What was heard of the sister. */
  char sister[64];
  char former_sister[64]; /* the previous bond's sister: its leftover active=false heartbeats
                             are not this bond's */
  int heard;
  int wrong;         /* heartbeats of our id whose fields are not what the node must send */
  bool sister_broke; /* ended by the sister's active=false */
  double expected_period;
  double gaps[4096];
  int n_gaps;
} Bond;

static void new_uuid(char out[37]) {
  unsigned char b[16];
  if (getrandom(b, sizeof b, 0) != (ssize_t)sizeof b)
    for (int i = 0; i < 16; ++i) b[i] = (unsigned char)rand();
  b[6] = (unsigned char)((b[6] & 0x0F) | 0x40);
  b[8] = (unsigned char)((b[8] & 0x3F) | 0x80);
  snprintf(out, 37, "%02x%02x%02x%02x-%02x%02x-%02x%02x-%02x%02x-%02x%02x%02x%02x%02x%02x", b[0],
           b[1], b[2], b[3], b[4], b[5], b[6], b[7], b[8], b[9], b[10], b[11], b[12], b[13], b[14],
           b[15]);
}

static void bond_start(Bond* bond, const char* id, double heartbeat_timeout) {
  bond->id = id;
  new_uuid(bond->instance_id);
  bond->heartbeat_timeout = heartbeat_timeout;
  bond->period = 0.10;
  bond->state = kWaiting;
  bond->next_publish = now_s() + bond->period;
  /* The node goes on sending the broken bond's active=false heartbeats for a while (bondcpp's
     wait for an answer): the new bond must not take one of them for its sister's death (a
     second bond that reused the first instance_id still shows, in its active heartbeats). */
  snprintf(bond->former_sister, sizeof bond->former_sister, "%s", bond->sister);
  bond->sister[0] = '\0';
  bond->heard = bond->wrong = bond->n_gaps = 0;
  bond->sister_broke = false;
}

static void publish(Bond* bond, bool active) {
  bond_msg_dds__Status_ msg;
  memset(&msg, 0, sizeof msg);
  msg.header.frame_id = "";
  msg.id = (char*)bond->id;
  msg.instance_id = bond->instance_id;
  msg.active = active;
  msg.heartbeat_timeout = (float)bond->heartbeat_timeout;
  msg.heartbeat_period = (float)bond->period;
  const dds_return_t rc = dds_write(bond->writer, &msg);
  if (rc < 0) die("bond write", rc);
}

/* Runs the bond until `until` (monotonic s) or until it leaves `leave` (when not negative). */
static void bond_spin(Bond* bond, double until, int leave) {
  while (now_s() < until && (leave < 0 || (int)bond->state == leave)) {
    const double now = now_s();
    if (bond->state != kDead && now >= bond->next_publish) {
      publish(bond, true);
      bond->next_publish += bond->period;
      if (bond->next_publish < now) bond->next_publish = now + bond->period;
    }
    void* samples[16] = {NULL};
    dds_sample_info_t infos[16];
    const int n = dds_take(bond->reader, samples, infos, 16, 16);
    for (int i = 0; i < n; ++i) {
      if (!infos[i].valid_data) continue;
      const bond_msg_dds__Status_* s = samples[i];
      /* bondcpp's filter: our id, not our instance. */
      if (strcmp(s->id, bond->id) != 0 || strcmp(s->instance_id, bond->instance_id) == 0) continue;
      if (!s->active && bond->former_sister[0] != '\0' &&
          strcmp(s->instance_id, bond->former_sister) == 0)
        continue;
      const double at = now_s();
      if (bond->sister[0] == '\0')
        snprintf(bond->sister, sizeof bond->sister, "%s", s->instance_id);
      if (strcmp(bond->sister, s->instance_id) != 0 ||
          fabs(s->heartbeat_period - bond->expected_period) > 1e-6)
        ++bond->wrong;
      if (!s->active) {
        if (bond->state != kDead) {
          bond->state = kDead; /* SisterDead */
          bond->sister_broke = true;
        }
        continue;
      }
      if (bond->state == kDead) continue;
      if (bond->heard > 0 && bond->state == kAlive && bond->n_gaps < 4096)
        bond->gaps[bond->n_gaps++] = at - bond->last_heard;
      ++bond->heard;
      bond->last_heard = at;
      if (bond->state == kWaiting) bond->state = kAlive; /* SisterAlive: Connected */
    }
    if (n > 0) dds_return_loan(bond->reader, samples, n);
    /* After what arrived meanwhile: a heartbeat waiting in the reader is not silence. */
    if (bond->state == kAlive && now_s() - bond->last_heard >= bond->heartbeat_timeout) {
      bond->state = kDead; /* HeartbeatTimeout */
      return;
    }
    double next = bond->next_publish;
    if (bond->state == kAlive && bond->last_heard + bond->heartbeat_timeout < next)
      next = bond->last_heard + bond->heartbeat_timeout;
    if (until < next) next = until;
    if (n <= 0) wait_data(bond->reader, fmin(next, now_s() + 0.01));
  }
}

static int compare_doubles(const void* a, const void* b) {
  const double x = *(const double*)a, y = *(const double*)b;
  return x < y ? -1 : x > y;
}

/* createBondConnection: start, then waitUntilFormed(bond_timeout / 2); then the node's
 * heartbeats for two seconds: their fields and their period. */
static void form_and_listen(Bond* bond, const char* id, double bond_timeout, double period) {
  bond_start(bond, id, bond_timeout);
  bond_spin(bond, now_s() + bond_timeout / 2, kWaiting);
  CHECK(bond->state == kAlive, "the bond '%s' did not form within %.2f s", id, bond_timeout / 2);
  if (bond->state == kAlive)
    printf("bond '%s' formed with the node's instance %s\n", id, bond->sister);
  bond_spin(bond, now_s() + 2.0, kAlive);
  CHECK(bond->state == kAlive, "the bond broke while the node ran");
  CHECK(bond->wrong == 0, "%d heartbeats of id '%s' had another instance_id or heartbeat_period",
        bond->wrong, id);
  CHECK(bond->n_gaps >= 5, "only %d heartbeat gaps in 2 s", bond->n_gaps);
  if (bond->n_gaps > 0) {
    qsort(bond->gaps, (size_t)bond->n_gaps, sizeof bond->gaps[0], compare_doubles);
    const double median = bond->gaps[bond->n_gaps / 2];
    printf("node heartbeats: %d, median gap %.3f s (heartbeat_period %.3f s)\n", bond->heard,
           median, period);
    CHECK(fabs(median - period) <= 0.4 * period, "median heartbeat gap %.3f s, period %.3f s",
          median, period);
  }
}

/* The watchdog: the node frozen, the bond must break after bond_timeout of silence. */
static void watchdog(Bond* bond, int node_pid, double bond_timeout, double period) {
  if (kill(node_pid, SIGSTOP) != 0) die("SIGSTOP to the node", DDS_RETCODE_ERROR);
  const double stopped = now_s();
  bond_spin(bond, stopped + bond_timeout + 5.0, kAlive);
  const double broke = now_s() - stopped;
  kill(node_pid, SIGCONT);
  CHECK(bond->state == kDead && !bond->sister_broke,
        "the bond did not break by silence within %.2f s of the node stopping", bond_timeout + 5.0);
  CHECK(broke >= bond_timeout - period - 0.05 && broke <= bond_timeout + 0.5,
        "the bond broke %.3f s after the node stopped, bond_timeout %.2f s", broke, bond_timeout);
  printf("watchdog: the bond broke %.3f s after the node stopped (bond_timeout %.2f s)\n", broke,
         bond_timeout);
}

/* Nav2's changeStateForNode without the bond: change_state, then get_state must be `goal`. */
static void transition(uint8_t id, const char* what, int goal) {
  const int ok = change_state(id, NULL);
  CHECK(ok == 1, "%s: change_state answered %d (1 success, 0 failure, -1 no reply)", what, ok);
  const int state = get_state();
  CHECK(state == goal, "%s: get_state %d, expected %d", what, state, goal);
  printf("%s: state %d\n", what, state);
}

static void usage(void) {
  fprintf(stderr,
          "usage: vnsba_cyclone_bond_client --domain N [--namespace NS] --id NAME --node-pid PID "
          "[--bond-timeout S] [--period S] [--lifecycle]\n");
  exit(2);
}

int main(int argc, char** argv) {
  int domain = -1;
  int node_pid = 0;
  const char* id = NULL;
  double bond_timeout = 2.0, period = 0.1;
  bool lifecycle = false;
  for (int i = 1; i < argc; ++i) {
    const char* a = argv[i];
    const char* v = i + 1 < argc ? argv[i + 1] : NULL;
    if (strcmp(a, "--domain") == 0 && v && parse_int(v, 0, 232, &domain)) {
      ++i;
    } else if (strcmp(a, "--namespace") == 0 && v) {
      ros_namespace = v;
      ++i;
    } else if (strcmp(a, "--id") == 0 && v) {
      id = v;
      ++i;
    } else if (strcmp(a, "--node-pid") == 0 && v && parse_int(v, 1, 1 << 30, &node_pid)) {
      ++i;
    } else if (strcmp(a, "--bond-timeout") == 0 && v) {
      bond_timeout = atof(v);
      ++i;
    } else if (strcmp(a, "--lifecycle") == 0) {
      lifecycle = true;
    } else if (strcmp(a, "--period") == 0 && v) {
      period = atof(v);
      ++i;
    } else {
      usage();
    }
  }
  if (domain < 0 || id == NULL || node_pid <= 0 || !(bond_timeout > 0.2) || !(period > 0)) usage();

  participant = dds_create_participant((dds_domainid_t)domain, NULL, NULL);
  if (participant < 0) die("participant", participant);
  Bond bond;
  memset(&bond, 0, sizeof bond);
  bond.expected_period = period;
  bond.writer = writer(&kBond, qos_of(false, 5));
  bond.reader = reader(&kBond, qos_of(false, 100));
  const dds_entity_t both[2] = {bond.writer, bond.reader};
  CHECK(wait_matched(both, 2, 20.0) >= 0, "the node's bond writer and reader never matched ours");

  if (lifecycle) {
    lifecycle_node_name = id;
    dds_entity_t entities[2 * kServices];
    for (int i = 0; i < kServices; ++i) {
      make_lifecycle_service(&lifecycle_services[i], i);
      entities[2 * i] = lifecycle_services[i].request;
      entities[2 * i + 1] = lifecycle_services[i].reply;
    }
    CHECK(wait_matched(entities, 2 * kServices, 20.0) >= 0,
          "the node's lifecycle services never matched");
    CHECK(get_state() == 1, "the managed node is not unconfigured at start");
    transition(1, "configure", 2);
    transition(3, "activate", 3);
  }
  form_and_listen(&bond, id, bond_timeout, period);
  if (lifecycle) {
    /* deactivate: the node breaks its bond with active=false (destroyBond), at once. */
    const double asked = now_s();
    transition(4, "deactivate", 2);
    bond_spin(&bond, asked + 1.0, kAlive);
    CHECK(bond.state == kDead && bond.sister_broke,
          "deactivate: the node's active=false did not end the bond within 1 s");
    char first[64];
    snprintf(first, sizeof first, "%s", bond.sister);
    transition(3, "activate again", 3);
    form_and_listen(&bond, id, bond_timeout, period);
    CHECK(strcmp(first, bond.sister) != 0, "the node's second bond has its first instance_id %s",
          first);
  }
  watchdog(&bond, node_pid, bond_timeout, period);
  if (lifecycle) {
    /* The manager's reset, then its shutdown's last step. */
    transition(4, "deactivate", 2);
    transition(2, "cleanup", 1);
    transition(5, "shutdown", 4);
  }

  /* A bond of another id: the node never answers it. */
  Bond other;
  memset(&other, 0, sizeof other);
  other.writer = bond.writer;
  other.reader = bond.reader;
  other.expected_period = period;
  bond_start(&other, "not_this_node", bond_timeout);
  bond_spin(&other, now_s() + 1.0, kWaiting);
  CHECK(other.state == kWaiting, "a bond of id 'not_this_node' formed");

  return report_run(participant, "bond");
}
