#include "vnsba/node/planner_node.hpp"

#include <spdlog/spdlog.h>

#include <memory>
#include <set>
#include <utility>

#include "answers.hpp"
#include "debug_publisher.hpp"
#include "fleet.hpp"
#include "fleet_router.hpp"
#include "map_input.hpp"
#include "node_readers.hpp"
#include "path_validity_service.hpp"
#include "planning_workers.hpp"
#include "replier.hpp"
#include "request_admission.hpp"
#include "request_intake.hpp"
#include "robot_poses.hpp"
#include "vnsba/node/bond_link.hpp"
#include "vnsba/node/dds.hpp"
#include "vnsba/node/security.hpp"
#include "vnsba/node/time_source.hpp"
#include "work_queues.hpp"

namespace vnsba::node {

// The node's roles, composed: each is made here with the references it needs of the others;
// start() makes their DDS entities (writers, then readers and action servers) and only then
// starts their threads; stop() ends input first and the replier last.
class PlannerNode::Impl {
 public:
  explicit Impl(NodeConfig config);

  core::Status start();
  void stop();
  Stats stats() const;

  const NodeConfig cfg_;
  const int worker_count_ = planning_workers(cfg_);
  TimeSource time_{cfg_.use_sim_time};
  const Fleet fleet_{cfg_};
  // Declared before the participant, which calls it, so that it is destroyed after it.
  std::unique_ptr<ParticipantWatch> participant_watch_;
  std::unique_ptr<Participant> participant_;
  NodeReaders readers_;

  RobotPoses poses_{cfg_, fleet_, time_};
  RequestIntake intake_{cfg_, fleet_};
  WorkQueues queues_{cfg_, fleet_};
  Replier replier_{cfg_, fleet_, intake_};
  Answers answers_{fleet_, replier_, intake_};
  DebugPublisher debug_{cfg_, fleet_};
  // A request that waited for the first map goes to the admission, declared after the maps:
  // only the map thread calls it, which starts once every role exists.
  MapInput maps_{cfg_, worker_count_, answers_,
                 [&admission = admission_](const Robot& robot, Job job) {
                   admission.submit(robot, std::move(job));
                 }};
  RequestAdmission admission_{cfg_, fleet_, intake_, maps_, queues_, poses_, answers_};
  PlanningWorkers workers_{cfg_, worker_count_, fleet_, queues_, maps_, answers_, debug_, time_};
  FleetRouter router_{cfg_, fleet_, admission_, intake_, replier_, time_};
  PathValidityService path_validity_{cfg_, maps_, poses_};
  // The heartbeat Nav2's lifecycle manager watches (bond.*): made with the participant where a
  // bond may run; a bond runs on it while a managed node is active (bond.mode managed) or from
  // start to stop (always).
  std::unique_ptr<BondLink> bond_;
  bool started_ = false;

  // Nav2's createBond() / destroyBond() (nav2_util's LifecycleNode): a bond with the manager,
  // whose id is the node's name.
  void create_bond();
  void destroy_bond();

 private:
  // start()'s steps, in order.
  core::Status create_participant();
  core::Status create_bond_link();
  core::Status add_writers(const Robot& robot);
  core::Status add_node_readers();
  core::Status add_robot_readers(const Robot& robot);
  void log_started() const;
  // What makes a remote endpoint on `topic` match the node's, for the incompatible-QoS warning.
  std::string qos_fix(const std::string& topic, const std::string& policy) const;
};

PlannerNode::Impl::Impl(NodeConfig config) : cfg_(std::move(config)) {}

std::string PlannerNode::Impl::qos_fix(const std::string& topic, const std::string& policy) const {
  if (topic == maps_.topic()) {
    if (policy == "DURABILITY" && cfg_.map_durability == MapDurability::kTransientLocal)
      return "the map publisher is volatile: set map.durability: volatile in the node's config";
    return "the node reads maps reliable, " +
           std::string(cfg_.map_durability == MapDurability::kVolatile ? "volatile"
                                                                       : "transient local") +
           " (map.durability)";
  }
  const std::pair<const std::string*, TopicQos> fixed[] = {
      {&cfg_.topics.goal_pose, TopicQos::kEvents},
      {&cfg_.topics.robot_pose, TopicQos::kLatest},
      {&cfg_.topics.plan_request, TopicQos::kEvents},
      {&cfg_.topics.plan, TopicQos::kLatest},
      {&cfg_.topics.plan_status, TopicQos::kStatus},
      {&cfg_.topics.planner_debug, TopicQos::kDebug},
      {&cfg_.topics.plan_raw, TopicQos::kLatched},
      {&cfg_.topics.plan_pruned, TopicQos::kLatched},
      {&cfg_.topics.expansions_forward, TopicQos::kLatched},
      {&cfg_.topics.expansions_backward, TopicQos::kLatched},
      {&cfg_.topics.meeting_point, TopicQos::kLatched},
      {&cfg_.topics.tf, TopicQos::kStream},
      {&cfg_.topics.tf_static, TopicQos::kStatic},
      {&cfg_.topics.clock, TopicQos::kStream}};
  for (const Robot& robot : fleet_)
    for (const auto& [configured, profile] : fixed)
      if (topic == robot.topic(*configured)) return "the node's endpoint is " + describe(profile);
  return "";
}

// ---------------------------------------------------------------------------------------------
// Start and stop.

core::Status PlannerNode::Impl::start() {
  if (core::Status s = create_participant(); !s.is_ok()) return s;
  // Writers first, so that every request read can be answered.
  for (const Robot& robot : fleet_)
    if (core::Status s = add_writers(robot); !s.is_ok()) return s;
  // Then the readers: the node's own, then each robot's and its action servers.
  if (core::Status s = add_node_readers(); !s.is_ok()) return s;
  if (core::Status s = create_bond_link(); !s.is_ok()) return s;
  for (const Robot& robot : fleet_) {
    if (core::Status s = add_robot_readers(robot); !s.is_ok()) return s;
    if (cfg_.actions.enabled)
      if (core::Status s = router_.add_action_servers(readers_, participant_watch_.get(), robot);
          !s.is_ok())
        return s;
    // planner_server serves is_path_valid beside its actions.
    if (cfg_.actions.enabled)
      if (core::Status s = path_validity_.add(readers_, participant_watch_.get(), robot, replier_);
          !s.is_ok())
        return s;
  }
  if (cfg_.map_cost_source == MapCostSource::kCostmap)
    spdlog::info(
        "map.cost_source costmap: slices are Nav2 costmaps, planned on as they are (99 and 100 "
        "blocked, 1..98 costs); occupied_threshold, robot_radius and inflation_radius not applied");
  // The threads start once every entity exists: the replier walks each robot's action servers and
  // the intake each robot's inputs, and neither list changes from here until stop(). What arrived
  // while the readers were made waits in them (the intake listeners only wake the intake, and the
  // slice for the map thread is kept by MapInput); the intake starts last, once whatever it hands
  // on can be planned and answered.
  replier_.start();
  maps_.start();
  workers_.start();
  intake_.start();
  started_ = true;
  log_started();
  if (cfg_.bond.mode == BondMode::kAlways) create_bond();
  return core::Status::ok();
}

core::Status PlannerNode::Impl::create_bond_link() {
  // Only where a bond may run: a self-activating node under bond.mode managed never bonds, and
  // gets no bond endpoints nor thread (a DDS user's node is as before).
  const bool may_bond =
      cfg_.bond.mode == BondMode::kAlways ||
      (cfg_.bond.mode == BondMode::kManaged && cfg_.lifecycle == LifecycleMode::kManaged);
  if (!may_bond) return core::Status::ok();
  // bondcpp's topic "bond" is relative: under the node's namespace (rt/<namespace>/bond).
  auto link = BondLink::create(*participant_, dds_topic_name(cfg_, "bond"));
  if (!link) return link.error();
  bond_ = std::move(link).value();
  return core::Status::ok();
}

void PlannerNode::Impl::create_bond() {
  if (!bond_) return;
  const std::string id = cfg_.node_name;  // Nav2: bond::Bond("bond", this->get_name(), ...)
  spdlog::info("Creating bond ({}) to lifecycle manager on '{}', a heartbeat every {} s", id,
               dds_topic_name(cfg_, "bond"), cfg_.bond.heartbeat_period.count() / 1000.0);
  bond_->start(
      id, BondTimings::nav2_managed_node(cfg_.bond.heartbeat_period),
      [id](const std::string& sister) {
        spdlog::info("bond ({}) formed with the lifecycle manager (instance {})", id, sister);
      },
      // Nav2's managed nodes do nothing when the manager's side breaks: their bond ignores the
      // manager's silence (SisterSilence::kIgnored), and the manager's active=false (its
      // deactivate) just ends the bond. The manager drives the node's state through the
      // lifecycle services; the node keeps its state. Logged only.
      [id](BondEnd why) {
        spdlog::info("bond ({}) with the lifecycle manager ended: {}", id, bond_end_name(why));
      });
}

void PlannerNode::Impl::destroy_bond() {
  if (!bond_) return;
  const BondState state = bond_->state();
  // Broken already: by us (awaiting the manager's answer) or for good.
  if (state == BondState::kNotStarted || state == BondState::kAwaitSisterDeath ||
      state == BondState::kDead)
    return;
  spdlog::info("Destroying bond ({}) to lifecycle manager", cfg_.node_name);
  bond_->break_bond();
}

// The watch on other writers of our status topics, and the participant.
core::Status PlannerNode::Impl::create_participant() {
  std::set<std::string> status_topics;
  for (const Robot& robot : fleet_) status_topics.insert(robot.topic(cfg_.topics.plan_status));
  // Two nodes on one domain and topics answer every request twice: say so (issue 13).
  participant_watch_ = std::make_unique<ParticipantWatch>(
      status_topics,
      [this](const std::string& who, const std::string& guid) {
        spdlog::warn(
            "another participant ('{}', GUID prefix {}) also writes a plan_status topic of this "
            "node ('{}'{}): every request there gets one answer from each; give each node its own "
            "domain_id, topics or robots",
            printable(who), guid, fleet_.front().topic(cfg_.topics.plan_status),
            fleet_.size() > 1 ? " or another robot's" : "");
      },
      [this](const std::string& topic, const std::string& policy) {
        return qos_fix(topic, policy);
      });
  auto participant =
      Participant::create_configured(cfg_, "vnsba_node", kNodeEnclave, participant_watch_.get());
  if (!participant) return participant.error();
  participant_ = std::move(participant).value();
  readers_.use(*participant_);
  return core::Status::ok();
}

// A robot's writers: its plan, its plan_status, its debug.
core::Status PlannerNode::Impl::add_writers(const Robot& robot) {
  if (core::Status s = workers_.add_plan_writer(*participant_, robot); !s.is_ok()) return s;
  if (core::Status s = replier_.add_status_writer(*participant_, robot); !s.is_ok()) return s;
  return debug_.add_writers(*participant_, robot);
}

// The readers of the node as a whole: the clock (so that the first goal already has the
// simulation's time), the map, then the transforms (the robots' poses before the goals, so
// that a goal never waits for a reader created after it).
core::Status PlannerNode::Impl::add_node_readers() {
  if (core::Status s = poses_.add_clock_reader(readers_); !s.is_ok()) return s;
  if (core::Status s = maps_.add_reader(readers_); !s.is_ok()) return s;
  return poses_.add_transform_readers(readers_);
}

// A robot's readers: its pose (unless the transforms give it), its goals and its requests.
core::Status PlannerNode::Impl::add_robot_readers(const Robot& robot) {
  if (core::Status s = poses_.add_pose_reader(readers_, robot); !s.is_ok()) return s;
  return router_.add_request_readers(readers_, robot);
}

void PlannerNode::Impl::log_started() const {
  const Robot& first = fleet_.front();
  if (fleet_.size() == 1) {
    spdlog::info("vnsba_node up on domain {}: slices on '{}', requests on '{}', goals on '{}'",
                 cfg_.domain_id, maps_.topic(), first.topic(cfg_.topics.plan_request),
                 first.topic(cfg_.topics.goal_pose));
  } else {
    spdlog::info(
        "vnsba_node up on domain {}: slices on '{}', {} robots ('{}' ... '{}'), {} planning "
        "workers",
        cfg_.domain_id, maps_.topic(), fleet_.size(), first.topic(cfg_.topics.plan_request),
        fleet_.back().topic(cfg_.topics.plan_request), worker_count_);
  }
}

void PlannerNode::Impl::stop() {
  // Nav2's LifecycleNode breaks its bond before its context shuts down (on_rcl_preshutdown):
  // the manager hears active=false rather than silence.
  destroy_bond();
  if (bond_) bond_->close();
  // Every request taken from here on is answered CANCELED at once; what the readers still hold
  // is taken and answered so, then the readers go: nothing the bus delivered goes unanswered.
  intake_.stop();
  if (participant_) participant_->delete_readers();  // no new input from here on
  queues_.stop("node is shutting down");
  // The map thread first: a map it installs now hands the requests that waited for it on
  // (the admission answers them CANCELED from here on), so none can reach a queue no worker
  // reads.
  maps_.stop();
  workers_.join();  // each answers its robot's queued requests first
  maps_.expire_all();
  const Replier::Clock::time_point drain_deadline = Replier::Clock::now() + kDrainTimeout;
  replier_.stop(drain_deadline);  // writes every status still held
  if (started_) replier_.wait_for_acknowledgements(drain_deadline);
  if (participant_) participant_->shutdown();
  participant_.reset();
  // The writers were deleted with the participant; the action servers and the listeners go
  // after it.
  workers_.forget_writers();
  debug_.forget_writers();
  replier_.forget_endpoints();
  router_.release();
  path_validity_.release();
  intake_.forget_readers();
  readers_.clear();
}

PlannerNode::Stats PlannerNode::Impl::stats() const {
  Stats s;
  s.requests_received = admission_.received();
  s.statuses_published = answers_.published();
  s.maps_accepted = maps_.accepted();
  s.maps_rejected = maps_.rejected();
  s.maps_superseded = maps_.superseded();
  s.plans_ok = workers_.plans_ok();
  s.queue_peak = queues_.peak();
  s.other_status_writers = participant_watch_ ? participant_watch_->count() : 0;
  s.incompatible_qos = participant_watch_ ? participant_watch_->incompatible_qos() : 0;
  s.action_goals = replier_.action_goals();
  s.plan_readers = workers_.plan_readers();
  s.status_readers = replier_.status_readers();
  return s;
}

// ---------------------------------------------------------------------------------------------

PlannerNode::PlannerNode(NodeConfig config) : impl_(std::make_unique<Impl>(std::move(config))) {}
PlannerNode::~PlannerNode() {
  stop();
}

core::Status PlannerNode::start() {
  core::Status status = impl_->start();
  if (!status.is_ok()) impl_->stop();
  return status;
}

void PlannerNode::stop() {
  impl_->stop();
}

PlannerNode::Stats PlannerNode::stats() const {
  return impl_->stats();
}

bool PlannerNode::wait_for_map(std::chrono::milliseconds timeout) const {
  return impl_->maps_.wait_for_map(timeout);
}

void PlannerNode::set_accepting(bool accepting) {
  impl_->admission_.set_accepting(accepting);
  // A managed node bonds while active, as Nav2's servers do (createBond() at the end of
  // on_activate, destroyBond() in on_deactivate: nav2_planner's planner_server.cpp); a
  // self-activating one only with bond.mode always, which bonded at start().
  if (impl_->cfg_.bond.mode == BondMode::kManaged &&
      impl_->cfg_.lifecycle == LifecycleMode::kManaged) {
    if (accepting)
      impl_->create_bond();
    else
      impl_->destroy_bond();
  }
}

const NodeConfig& PlannerNode::config() const {
  return impl_->cfg_;
}

}  // namespace vnsba::node
