// Node configuration: a plain struct filled from YAML (config/default.yaml documents every key).
//
// Loading never throws and never stops at the first problem: every bad key is reported at once,
// each message naming the key, the value found and what was expected, so a user fixes a config
// file in one pass. Executables refuse to start on any error.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/planner_options.hpp"
#include "vnsba/core/status.hpp"

namespace vnsba::node {

// Topic names as a ROS 2 node would use them (no "rt/" prefix; see dds_topic_name()).
struct TopicNames {
  std::string projected_map = "projected_map";  // in: nav_msgs/OccupancyGrid slices
  std::string goal_pose = "goal_pose";          // in: geometry_msgs/PoseStamped (rviz2 goal tool)
  std::string robot_pose = "robot_pose";        // in: geometry_msgs/PoseStamped, start for goals
  std::string plan_request = "plan_request";    // in: vnsba_msgs/PlanRequest
  std::string plan = "plan";                    // out: nav_msgs/Path
  std::string plan_status = "plan_status";      // out: vnsba_msgs/PlanStatus
  std::string planner_debug = "planner_debug";  // out: vnsba_msgs/PlannerDebug
  std::string octomap = "octomap_binary";       // in (vnsba_slicer): octomap_msgs/Octomap
  // Debug layers with stock ROS 2 types, for rviz2's Path, Map and PointStamped displays.
  std::string plan_raw = "plan_raw";        // out: nav_msgs/Path, the search's grid path
  std::string plan_pruned = "plan_pruned";  // out: nav_msgs/Path, the pruned waypoints
  std::string expansions_forward = "planner_expansions_forward";    // out: nav_msgs/OccupancyGrid
  std::string expansions_backward = "planner_expansions_backward";  // out: nav_msgs/OccupancyGrid
  std::string meeting_point = "planner_meeting_point";  // out: geometry_msgs/PointStamped
  // ROS 2's absolute tf and clock topics (robot_pose_source: tf; use_sim_time: true).
  std::string tf = "/tf";                // in: tf2_msgs/TFMessage
  std::string tf_static = "/tf_static";  // in: tf2_msgs/TFMessage, transient local
  std::string clock = "/clock";          // in: rosgraph_msgs/Clock
  // Nav2's planner actions (ROS 2 action names; each is three services and two topics under
  // <name>/_action/, per rcl_action), served while actions.enabled.
  std::string compute_path_to_pose = "compute_path_to_pose";
  std::string compute_path_through_poses = "compute_path_through_poses";
  // Nav2's planner_server service nav2_msgs/srv/IsPathValid (a ROS 2 service name: the DDS
  // topics rq/<name>Request and rr/<name>Reply), served while actions.enabled.
  std::string is_path_valid = "is_path_valid";
};

// How a service reply (an action's send_goal, get_result, cancel_goal) is tied to its request
// on the wire, which differs between ROS 2 middlewares.
enum class ReplyMapping {
  kAuto,        // per client, from the vendor id of its participant (discovery)
  kFastRtps,    // rmw_fastrtps: the reply's related sample identity is the request's
  kCycloneDds,  // rmw_cyclonedds: a 16-byte header (client id, sequence) before the payload
};

// bond.*: the heartbeat Nav2's lifecycle manager watches (bond/msg/Status on the topic `bond`,
// resolved under `namespace`; vnsba/node/bond.hpp, bond_link.hpp, docs/nav2.md "Bringup").
enum class BondMode {
  kManaged,  // a managed node bonds while active (activate to deactivate), as Nav2's servers do;
             // a self-activating node never does
  kAlways,   // also a self-activating node, from start to stop (a watchdog without lifecycle)
  kOff,      // never (Nav2's bond_heartbeat_period <= 0; the manager needs bond_timeout 0 then)
};
struct BondConfig {
  BondMode mode = BondMode::kManaged;
  // bond.heartbeat_period, seconds in [0.01, 60]: Nav2's bond_heartbeat_period parameter (Jazzy
  // and Kilted default 0.1 s; Humble fixes 0.1 s).
  std::chrono::milliseconds heartbeat_period{100};
};

// actions.*: the Nav2 action servers.
struct ActionConfig {
  bool enabled = true;
  // actions.result_timeout, seconds in [0, 86400]: how long a finished goal's result is kept
  // for a late get_result (rcl_action's default: 15 minutes), then forgotten.
  std::chrono::milliseconds result_timeout{900000};
  // actions.max_results, 1..100000: finished goals kept per action server at most (bounded
  // memory whatever the rate of goals: each costs about 64 bytes per pose of its path); over it
  // the oldest delivered result is forgotten first. Under a burst a goal can finish long before
  // its client's get_result arrives: 10 clients x 1,000 goals at once lost a third of their
  // results to a cap of 1,024, none to 10,000.
  int max_results = 10000;
  ReplyMapping reply_mapping = ReplyMapping::kAuto;
  // actions.kept_results_mb, MiB in [1, 65536]: one budget for the results every action server
  // of the node keeps (each result counted at its encoded size, kKeptResultOverheadBytes plus
  // about 72 bytes a pose with frame_id "map"); over it the oldest delivered result of any server
  // is forgotten first, then the oldest.
  int kept_results_mb = 256;
  // actions.max_result_poses, 1..10000000: the most poses a result may carry. A goal whose poses
  // cannot fit (the straight lines through its goals, at planner.path_spacing) is ABORTED before
  // it is planned, one whose path has more is ABORTED after, each naming this key.
  int max_result_poses = 50000;
  // actions.max_goal_poses, 1..100000: the most poses a ComputePathThroughPoses goal may list
  // (each a leg to plan).
  int max_goal_poses = 1000;
  // actions.replies_in_flight_mb, MiB in [1, 4096], per action server: get_result replies written
  // and not yet acknowledged by every reader at most (the reply writer's history holds this
  // many bytes of results, at least 4 results).
  int replies_in_flight_mb = 64;
  // actions.reply_ack_timeout, seconds in [0.05, 60]: a reader that has not acknowledged the
  // replies written within this is taken as not acknowledging; the others' replies then go on
  // without waiting for it (reply_flow.hpp), and its own are dropped from the writer's history
  // first.
  std::chrono::milliseconds reply_ack_timeout{2000};
  // actions.max_pending_replies, 1..100000: replies to one client held by one service of a
  // server (waiting for its reply reader to match, or for the writer); more are dropped with a
  // warning naming the client.
  int max_pending_replies = 10000;
  // actions.status_finished_goals, 0..100000: the status topic lists every goal not yet finished
  // and this many of those that finished last (rcl_action lists every goal it keeps).
  int status_finished_goals = 100;
};
// What a kept result costs beside its encoded bytes (the goal's entry, id and bookkeeping).
inline constexpr size_t kKeptResultOverheadBytes = 256;

// Where the start of a goal_pose goal comes from.
enum class RobotPoseSource {
  kTopic,  // the newest sample on topics.robot_pose (of robot_pose_type)
  kTf,     // tf: the pose of base_frame in frame_id, composed from /tf and /tf_static
};
// The type on topics.robot_pose (robot_pose_source: topic).
enum class RobotPoseType {
  kPoseStamped,                // geometry_msgs/PoseStamped
  kPoseWithCovarianceStamped,  // geometry_msgs/PoseWithCovarianceStamped (amcl's amcl_pose)
};

enum class DebugPublishing {
  kAuto,    // publish planner_debug only while some reader is matched
  kAlways,  // always publish
  kNever,   // never publish
};

enum class MapDurability { kTransientLocal, kVolatile };

// map.cost_source: what the slice's values mean.
enum class MapCostSource {
  kOwn,      // an occupancy map: occupied_threshold, robot_radius and the gradient apply
  kCostmap,  // Nav2's costmap as it publishes it: planned on as it is (planning_grid_options)
};
// Nav2's costmap in an OccupancyGrid (its cost_translation_table): 0 free, 1..98 graded costs,
// 99 inscribed, 100 lethal, -1 unknown. Cells at or above this are blocked.
inline constexpr int kCostmapInscribed = 99;

// security.*: DDS Security with an SROS2 keystore (node/security.hpp: the ROS_SECURITY_*
// environment applied on top, the enclave checked, the participant's properties).
enum class SecurityStrategy {
  kEnforce,     // a security setup that fails stops the executable; never an open participant
  kPermissive,  // as SROS2: no keystore, enclave or file there runs unsecured, with a warning
};
// ros.distro: the ROS 2 distribution whose wire types the node serves and its tools speak
// (nav2_msgs' actions and services differ between them: docs/nav2.md "Distributions").
enum class RosDistro { kHumble, kJazzy, kKilted };
// Every distribution in the order above, and its name as ros.distro and --distro spell it.
inline constexpr RosDistro kRosDistros[] = {RosDistro::kHumble, RosDistro::kJazzy,
                                            RosDistro::kKilted};
inline constexpr const char* distro_name(RosDistro distro) {
  switch (distro) {
    case RosDistro::kHumble:
      return "humble";
    case RosDistro::kKilted:
      return "kilted";
    case RosDistro::kJazzy:
      break;
  }
  return "jazzy";
}

struct SecurityConfig {
  bool enable = false;   // security.enable (ROS_SECURITY_ENABLE=true turns it on too)
  std::string keystore;  // security.keystore: the keystore directory (ROS_SECURITY_KEYSTORE)
  // security.enclave: "/vnsba/node", the directory <keystore>/enclaves/vnsba/node; empty = the
  // executable's own (/vnsba/node, /vnsba/slicer, /vnsba/recorder, /vnsba/send_goal).
  std::string enclave;
  SecurityStrategy strategy = SecurityStrategy::kEnforce;  // security.strategy
};

// OctoMap slicing settings (used by vnsba_slicer).
struct SlicerConfig {
  double z_min = 0.1;       // metres, lower bound of the height band
  double z_max = 1.5;       // metres, upper bound of the height band (>= z_min)
  double resolution = 0.0;  // metres per cell; 0 = the tree's leaf size, else a coarser multiple
  bool remove_speckles = false;  // drop occupied cells with no occupied 8-neighbour
};

// Defaults that differ from core's: a node guards its memory (map.memory_budget_mb, and
// map.max_cells as the upper limit of any build) and bounds every search in time.
constexpr int64_t kDefaultMaxCells = core::kMaxCellsLimit;  // 16384 x 16384 cells
// The largest map.memory_budget_mb (MiB): 1 TiB.
inline constexpr int kMaxMapMemoryBudgetMb = 1 << 20;
constexpr std::chrono::seconds kDefaultMaxPlanningTime{5};

inline core::GridBuildOptions default_map_options() {
  core::GridBuildOptions options;
  options.max_cells = kDefaultMaxCells;
  return options;
}

// planner.path_spacing: the published path has a pose at most this many metres apart
// (docs/algorithm.md section 8); unset = the map's resolution.
inline constexpr core::OptionRange kPathSpacingRange{"path_spacing", "metres", 0.0, 10.0, true};

// The planner.* keys. A key the file or default.yaml gives is a setting; a key both leave out
// (default.yaml comments out neighborhood, prune, smooth and path_spacing) stays unset and
// follows the paper configuration (core::default_options) of whichever planner runs. The options
// of a request are make_options(the request's planner, or `kind`, settings), so a request that
// picks another planner keeps every configured key. max_planning_time (default.yaml's 5 s) is a
// setting like the others and holds for every planner too.
// The longest planner name (a request's planner, a Nav2 planner_id, an alias) and frame id
// (frame_id, a pose's header.frame_id) the node takes, in bytes.
inline constexpr size_t kMaxPlannerNameBytes = 64;
inline constexpr size_t kMaxFrameIdBytes = 256;

// planner.aliases's target that means planner.name, whatever it is.
inline constexpr const char* kDefaultPlannerAlias = "default";

struct PlannerConfig {
  core::PlannerKind kind = core::PlannerKind::kVnsBaStar;  // planner.name
  // planner.name: auto. `kind` is then core::recommended_planner for the file's cost_weight,
  // neighborhood and corner_policy, and prune and smooth are on unless the file sets them
  // (options(): core::make_auto_options).
  bool auto_kind = false;
  core::PlannerSettings settings = default_settings();  // every other planner.* key
                                                        // (cost_weight, goal_tolerance and
                                                        // start_tolerance included)
  // planner.path_spacing, metres in kPathSpacingRange; unset = the resolution of the map each
  // plan runs on. Not a core option: it shapes the published poses (core::path_poses), not the
  // plan, so it holds for every planner.
  std::optional<double> path_spacing;
  // planner.aliases: other names a request's planner (a Nav2 goal's planner_id) may give, each
  // for a planner name, `auto`, or kDefaultPlannerAlias: planner.name as configured. Nav2's
  // default behaviour trees and planner_selector name "GridBased".
  std::vector<std::pair<std::string, std::string>> aliases = {{"GridBased", kDefaultPlannerAlias}};
  // The planner an alias stands for (its target), or nullopt when `name` is no alias.
  std::optional<std::string> alias_target(const std::string& name) const {
    for (const auto& [alias, target] : aliases)
      if (alias == name) return target;
    return std::nullopt;
  }

  // The spacing of the poses of a path planned on a map of `resolution` metres per cell.
  double path_spacing_for(double resolution) const { return path_spacing.value_or(resolution); }

  // The options of a run with the configured planner: with auto_kind, core::make_auto_options
  // (pruning and smoothing on unless the file set them; the choice was measured so).
  core::PlannerOptions options() const {
    return auto_kind ? core::make_auto_options(settings) : core::make_options(kind, settings);
  }
  // A request that names a planner: every key the file gives, the rest that planner's paper
  // configuration (auto or not: default.yaml says so).
  core::PlannerOptions options(core::PlannerKind override_kind) const {
    return core::make_options(override_kind, settings);
  }
  // A request that names `auto`: the file's keys with auto's rule, whatever planner.name says.
  core::PlannerOptions auto_options() const { return core::make_auto_options(settings); }

  static core::PlannerSettings default_settings() {
    core::PlannerSettings s;
    s.max_planning_time = kDefaultMaxPlanningTime;
    return s;
  }
};

// `lifecycle`: how the node goes through ROS 2's managed-node lifecycle (lifecycle.hpp,
// docs/nav2.md "Lifecycle").
enum class LifecycleMode {
  kSelfActivating,  // configures and activates itself at start (DDS users: plans at once)
  kManaged,         // waits, unconfigured, for change_state (nav2_lifecycle_manager)
};

struct NodeConfig {
  int domain_id = 0;  // DDS domain, 0..232 (the --domain flag overrides it)
  // `node_name`: the node's ROS 2 name (the --name flag overrides it); its lifecycle services
  // are /<namespace>/<node_name>/change_state, ... A valid ROS 2 node name (node_name_problem).
  std::string node_name = "vnsba_node";
  LifecycleMode lifecycle = LifecycleMode::kSelfActivating;
  bool ros2_naming = true;       // DDS topic = "rt/" + name, as ROS 2 names its topics
  std::string frame_id = "map";  // the frame of slices, requests and paths
  // `namespace`: the ROS 2 namespace of every relative topic name ("robot7": goal_pose is
  // rt/robot7/goal_pose); names with a leading '/' stay absolute. Stored without leading or
  // trailing '/'; empty = none.
  std::string ros_namespace;
  // `robots`: one node serving several robots (a fleet on one shared map). Each name is a
  // namespace under ros_namespace ("robot1": goal_pose is rt/<namespace>/robot1/goal_pose) for
  // the robot's topics (goal_pose, robot_pose, plan_request, plan, plan_status and the debug
  // topics); the map topic and tf/clock resolve under ros_namespace alone and are read once.
  // Stored normalized as ros_namespace; empty = one robot, the node's own namespace.
  std::vector<std::string> robots;
  TopicNames topics;

  // How incoming slices become planning grids (occupied_threshold, allow_unknown,
  // robot_radius in metres, the cost gradient inflation_radius in metres and
  // cost_scaling_factor per metre, max_cells as the size limit of an accepted slice). A loaded
  // config has config/default.yaml's real robot unless the file says otherwise; paper.yaml's is
  // the paper's binary grid (no radius, no gradient).
  core::GridBuildOptions map = default_map_options();
  // map.durability: the slice reader's DDS durability. transient_local (default, as Nav2's static
  // layer with map_subscribe_transient_local) also receives the last map of a latched publisher
  // that started first, but never matches a volatile one (octomap_server with latch:=false, any
  // QoS(10) publisher); volatile matches both and receives maps published after it joined.
  MapDurability map_durability = MapDurability::kTransientLocal;
  // map.cost_source: own (default) or costmap (Nav2's global costmap on topics.projected_map).
  MapCostSource map_cost_source = MapCostSource::kOwn;
  // map.memory_budget_mb, MiB in [1, kMaxMapMemoryBudgetMb]: the most a slice may take while it
  // is converted (slice_memory: the GridMap it becomes with the build's scratch, and the
  // slice's values). A larger one is refused (INVALID_MAP naming its size, the MiB it needed and
  // this key) before anything is allocated; the node keeps planning on its previous map.
  int map_memory_budget_mb = 2048;

  // The planner and what the file configured of its options (max_planning_time is read in
  // seconds, 0 = unlimited; compute_length_ratio costs a second, optimal A* search per plan;
  // cost_weight, goal_tolerance and start_tolerance unset by default, i.e. 0: the paper).
  PlannerConfig planner;

  bool preempt = true;      // a newer request cancels the one being planned (Nav2-like)
  int queue_capacity = 64;  // requests waiting to be planned when preempt is false, 1..100000
  // requests.reply_wait, seconds in [0, 10]: how long a plan_request's status waits for a status
  // reader of the requesting participant to be matched before it is written anyway (0: never
  // waits). Fresh clients are matched within one discovery round (0.5 s here).
  std::chrono::milliseconds reply_wait{2000};
  // requests.map_wait, seconds in [0, 60]: how long a request that arrives before the first map
  // waits for one before it is answered NO_MAP (0: at once). A client that latches its map and
  // asks right away would otherwise race its own map.
  std::chrono::milliseconds map_wait{0};
  // requests.workers: planning threads, 0 = one per core (std::thread::hardware_concurrency).
  // A robot's requests are planned one at a time, in order (preemption is per robot), so more
  // workers than robots are never used. Each worker keeps its own search state per map.
  int workers = 0;

  ActionConfig actions;
  BondConfig bond;

  DebugPublishing debug = DebugPublishing::kAuto;
  std::string log_level = "info";  // trace, debug, info, warn, error, critical, off

  SlicerConfig slicer;

  // network.localhost_only: every participant (node and tools) sends and listens on 127.0.0.1
  // only, and so advertises only loopback locators: what a ROS 2 system with
  // ROS_LOCALHOST_ONLY=1 reaches (that variable set to 1 turns it on too, as in rmw_fastrtps).
  bool localhost_only = false;
  // discovery.servers: Fast DDS Discovery Servers as "IPv4:port", the list position being the
  // server id (its GUID prefix 44.53.<id>.5f.45.50.52.4f.53.49.4d.41, as `fast-discovery-server
  // -i <id>` makes it), exactly as ROS_DISCOVERY_SERVER lists them. Non-empty: every participant
  // is a Discovery Server client and discovers others only through these servers. Empty: simple
  // discovery, unless ROS_DISCOVERY_SERVER is set, which Fast DDS applies itself.
  std::vector<std::string> discovery_servers;
  // The start of goal_pose goals (plan_requests carry their own): robot_pose_source,
  // robot_pose_type, base_frame (the robot's frame in tf) and transform_tolerance (seconds in
  // [0, 60]: a dynamic transform older than this is stale and the goal is refused naming it).
  RobotPoseSource robot_pose_source = RobotPoseSource::kTopic;
  RobotPoseType robot_pose_type = RobotPoseType::kPoseStamped;
  std::string base_frame = "base_link";
  double transform_tolerance_s = 0.5;
  // use_sim_time: the node's clock (stamps of what it publishes, the age of transforms) is the
  // newest rosgraph_msgs/Clock on topics.clock, zero until one arrives, as in ROS 2.
  bool use_sim_time = false;
  // DDS Security for every participant of the executable (off by default).
  SecurityConfig security;
  // dds.participant_profile: the profile_name of a <participant> in the Fast DDS XML profiles
  // (FASTRTPS_DEFAULT_PROFILES_FILE, DEFAULT_FASTRTPS_PROFILES.xml) every participant of the
  // executable starts from; empty = the default profile. The node's rules go on top (dds.hpp).
  std::string participant_profile;
  // ros.distro: the ROS 2 distribution whose nav2_msgs types go on the wire (Jazzy by default).
  RosDistro ros_distro = RosDistro::kJazzy;

 private:
  // No configuration is made from nothing: every NodeConfig starts from config/default.yaml
  // (default_config(), paper_config(), load_config(), parse_config()), the one source of
  // defaults, and every tool, bench and test gets its values from there. The initializers above
  // are only the blank that default.yaml's keys overwrite: it gives every key but the ones it
  // comments out on purpose, which stay unset (test Config.DefaultYamlGivesEveryValueShown).
  NodeConfig() = default;
  friend struct ConfigReader;  // config.cpp: reads the built-in default.yaml onto the blank
};

// Bounds of `robots` and requests.workers (each robot has about ten DDS endpoints; each worker
// keeps tens of bytes of search state per cell).
inline constexpr size_t kMaxRobots = 1000;
inline constexpr int kMaxWorkers = 256;

// The planning threads a node runs for `config`: requests.workers (0: the cores), at most one per
// robot, at least one.
int planning_workers(const NodeConfig& config);

// The configuration as robot `robot` (an entry of `robots`, or "" for the node's own) sees it:
// ros_namespace is the robot's namespace, so dds_topic_name gives the robot's topics.
NodeConfig robot_view(const NodeConfig& config, const std::string& robot);

// How a slice becomes the planning grid under `config`: its map.* options, or for map.cost_source
// costmap the costmap's own values (blocked from kCostmapInscribed, a cost c = v / 100 below it)
// with no second inflation (robot_radius and inflation_radius 0: the costmap is inflated
// already). The node and vnsba_plan both build their grids with it.
core::GridBuildOptions planning_grid_options(const NodeConfig& config);

struct ConfigResult {
  std::optional<NodeConfig> config;  // set when there are no errors
  std::vector<std::string> errors;   // one line per bad key: "key: found X, expected Y"
};

// Reads and validates a YAML file. A missing or unparsable file is one error naming the file
// (and the 1-based line and column for syntax errors). Every key is optional: a key the file
// leaves out has config/default.yaml's value (compiled in, so an empty file gives exactly
// default.yaml's configuration whichever file a tool was pointed at). Unknown keys are errors
// (with a "did you mean" for near misses). Never throws.
//
// There is no other way to make a NodeConfig: code that builds one field by field starts from
// default_config() or paper_config().
ConfigResult load_config(const std::string& path);

// config/default.yaml's configuration (what an empty file gives).
ConfigResult default_config();

// config/paper.yaml's configuration, read over default.yaml as any file is: the paper's binary
// grid (no robot radius, inflation, costs or tolerance) with vns_bastar and its paper options.
// Compiled in, as default.yaml is. Tests and benchmarks that measure the paper's setting start
// from it.
ConfigResult paper_config();

// Every key of `config` with its value, as a YAML config file that loads back to `config`
// (`vnsba_node --print-config`). Settings left to each planner's paper configuration (unset
// planner.prune, smooth, neighborhood, path_spacing) are left out, as in default.yaml.
std::string config_as_yaml(const NodeConfig& config);

// The same from YAML text; `source` names it in messages.
ConfigResult parse_config(const std::string& yaml_text, const std::string& source = "<config>");

// The config a tool reads when it is given no --config, so that it runs from any directory: the
// installed `<prefix>/share/vnsba/default.yaml` beside the running executable
// (`<prefix>/bin/<tool>`), then the source tree's `config/default.yaml` (a build tree's tools).
// Returns the first that exists, or kInvalidRequest listing where it looked.
core::Expected<std::string> find_default_config();

// ROS_LOCALHOST_ONLY=1 in the environment (as rmw_fastrtps reads it): forces localhost_only.
bool ros_localhost_only_from_environment();
// ROS_DOMAIN_ID in the environment, as rcl reads it: unset or empty is nullopt (no choice); an
// integer 0..232 the domain; anything else an error naming the variable and its value.
core::Expected<std::optional<int>> ros_domain_id_from_environment();
// Every tool's --config help text, which says where the file comes from without the option.
inline constexpr const char* kConfigOptionHelp =
    "YAML configuration file (default: <prefix>/share/vnsba/default.yaml of this installation, "
    "else the source tree's config/default.yaml)";

// A ROS 2 name without one leading '/': topics ("/plan" is "plan") and frame ids ("/map" is
// "map", as tf2 strips it).
std::string_view without_leading_slash(std::string_view name);

// What is wrong with a ROS 2 node name ("" when valid), as rmw_validate_node_name checks it:
// non-empty, letters, digits and '_' only, not starting with a digit, at most 255 characters.
std::string node_name_problem(const std::string& name);
// The node's full ROS 2 name: "/<namespace>/<node_name>" ("/vnsba_node" without a namespace).
std::string node_full_name(const NodeConfig& config);

// What is wrong with a discovery.servers entry ("" when it is "a.b.c.d:port").
std::string discovery_server_problem(const std::string& locator);
// A ROS 2 namespace as NodeConfig::ros_namespace keeps it: "/robot7/" and "robot7" give
// "robot7", "" and "/" give "" (none). Refused (kInvalidRequest, the message saying what was
// expected) unless the rest is a topic name without '~'.
core::Expected<std::string> normalized_namespace(std::string_view given);
// The DDS topic name of a configured topic name, resolved as ROS 2 resolves names: a relative
// name goes under the namespace ("plan" -> "robot7/plan"), an absolute one ("/map") does not and
// loses its '/'; then "rt/" in front with ros2_naming ("rt/robot7/plan", "rt/map").
std::string dds_topic_name(const NodeConfig& config, const std::string& name);
// The full ROS 2 name of a configured topic name ("/robot7/plan"), as `ros2 topic list` shows it.
std::string ros_topic_name(const NodeConfig& config, const std::string& name);
// ROS 2's longest full topic name (rmw's RMW_TOPIC_MAX_NAME_LENGTH: 255 less 8 characters kept for
// the middleware's prefixes); config loading refuses a namespace, robot or topic past it.
inline constexpr size_t kMaxTopicNameLength = 247;
// Fast DDS's longest DDS topic name (a string_255 in discovery): the node's action services add
// "rq" and "Request" to a ROS name, so an action's name must leave room for them.
inline constexpr size_t kMaxDdsTopicNameLength = 255;
// "" when every topic of `config` (of every robot) is within kMaxTopicNameLength, else one error
// naming the keys that made it long ("namespace, topics.projected_map: found ...").
std::string overlong_topic_name(const NodeConfig& config);

}  // namespace vnsba::node
