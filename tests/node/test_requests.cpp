// The request rules without DDS (requests.hpp, slice_slot.hpp): what is checked on arrival,
// what preempts or replaces what, and how a newer slice supersedes an older one.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "paper_config.hpp"
#include "vnsba/node/requests.hpp"
#include "vnsba/node/slice_slot.hpp"

namespace vnsba::test {
namespace {

using node::Job;
using node::RequestIdentity;
namespace wire = node::wire;

RequestIdentity client(uint8_t participant, int64_t sequence) {
  RequestIdentity id;
  id.writer_guid.fill(participant);
  id.writer_guid[15] = 0x03;  // entity id: the same writer kind in every client
  id.sequence_number = sequence;
  return id;
}

Job job(const std::string& id, double sx, double sy, double gx, double gy,
        RequestIdentity identity = client(1, 1)) {
  Job j;
  j.id = id;
  j.identity = identity;
  j.start = node::to_pose_msg(sx, sy, 0.0, "map", node::now_msg());
  j.goal = node::to_pose_msg(gx, gy, 0.0, "map", node::now_msg());
  return j;
}

// A 10 x 5 map at 1 m, origin (0, 0), with a wall cell at (5, 2).
core::GridMap small_map() {
  core::OccupancyGrid g;
  g.width = 10;
  g.height = 5;
  g.resolution = 1.0;
  g.data.assign(50, 0);
  g.data[2 * 10 + 5] = 100;
  return std::move(core::GridMap::build(g)).value();
}

TEST(Printable, EscapesControlCharactersAndCutsLongText) {
  EXPECT_EQ(node::printable("plain id-7"), "plain id-7");
  EXPECT_EQ(node::printable("a\nb\tc\rd\\e"), "a\\nb\\tc\\rd\\\\e");
  EXPECT_EQ(node::printable("x\x1b[31mred"), "x\\x1b[31mred");
  EXPECT_EQ(node::printable(std::string("\0z", 2)), "\\x00z");
  EXPECT_EQ(node::printable("\x7f"), "\\x7f");
  EXPECT_EQ(node::printable("\xc2\x9b"
                            "2J"),
            "\\xc2\\x9b2J");                                 // C1 CSI, UTF-8 encoded
  EXPECT_EQ(node::printable("caf\xc3\xa9"), "caf\xc3\xa9");  // UTF-8 stays
  EXPECT_EQ(node::printable("\xff\xfe"), "\\xff\\xfe");      // not UTF-8
  // Overlong LF and CSI, a surrogate, beyond U+10FFFF, a right-to-left override: all escaped.
  for (const char* bad :
       {"\xe0\x80\x8a", "\xe0\x82\x9b", "\xed\xa0\x80", "\xf4\x90\x80\x80", "\xe2\x80\xae"}) {
    const std::string shown = node::printable(bad);
    EXPECT_EQ(shown.find_first_of("\x80\x8a\x9b\xa0\xae"), std::string::npos) << shown;
    EXPECT_EQ(shown.rfind("\\x", 0), 0u) << shown;
  }
  const std::string log_forgery = "id\n[2026-12-01 00:00:00.000] [error] fake";
  EXPECT_EQ(node::printable(log_forgery).find('\n'), std::string::npos);
  const std::string huge(500000, 'a');
  const std::string shown = node::printable(huge, 64);
  EXPECT_EQ(shown, std::string(64, 'a') + "... (500000 bytes)");
  // A multi-byte character is never cut in half.
  EXPECT_EQ(node::printable("ab\xc3\xa9", 3), "ab... (4 bytes)");
}

TEST(ResolveRequest, StringFieldsAreBoundedAndNamed) {
  const node::NodeConfig cfg = paper_test_config();
  const core::GridMap map = small_map();
  Job long_id = job(std::string(node::kMaxIdBytes + 1, 'i'), 0.5, 0.5, 8.5, 0.5);
  auto r = node::resolve_request(long_id, cfg, &map);
  EXPECT_EQ(r.status.code, wire::INVALID_REQUEST);
  EXPECT_NE(r.status.message.find("id: 257 bytes"), std::string::npos) << r.status.message;
  EXPECT_NE(r.status.message.find("limit of 256 bytes"), std::string::npos);
  EXPECT_EQ(node::echoed_id(long_id.id).size(), node::kMaxIdBytes);
  Job at_limit = job(std::string(node::kMaxIdBytes, 'i'), 0.5, 0.5, 8.5, 0.5);
  EXPECT_TRUE(node::resolve_request(at_limit, cfg, &map).status.ok());

  Job long_planner = job("p", 0.5, 0.5, 8.5, 0.5);
  long_planner.planner = std::string(500000, 'x');
  r = node::resolve_request(long_planner, cfg, &map);
  EXPECT_EQ(r.status.code, wire::INVALID_REQUEST);
  EXPECT_EQ(r.status.message.find("planner: 500000 bytes"), 0u) << r.status.message;

  Job long_frame = job("f", 0.5, 0.5, 8.5, 0.5);
  long_frame.goal.header().frame_id(std::string(300, 'm'));
  r = node::resolve_request(long_frame, cfg, &map);
  EXPECT_EQ(r.status.code, wire::INVALID_REQUEST);
  EXPECT_EQ(r.status.message.find("goal.header.frame_id: 300 bytes"), 0u) << r.status.message;

  Job evil_planner = job("e", 0.5, 0.5, 8.5, 0.5);
  evil_planner.planner = "x\n[error] forged\x1b[2J";
  r = node::resolve_request(evil_planner, cfg, &map);
  EXPECT_EQ(r.status.code, wire::INVALID_REQUEST);
  EXPECT_EQ(r.status.message.find('\n'), std::string::npos) << r.status.message;
  EXPECT_EQ(r.status.message.find('\x1b'), std::string::npos) << r.status.message;
  EXPECT_NE(r.status.message.find("x\\n[error] forged\\x1b[2J"), std::string::npos);
}

TEST(ResolveRequest, EveryCheckNamesItsField) {
  const node::NodeConfig cfg = paper_test_config();
  const core::GridMap map = small_map();
  struct Case {
    Job job;
    const core::GridMap* map;
    uint8_t code;
    std::string words;
  };
  Job wrong_frame = job("w", 0.5, 0.5, 8.5, 0.5);
  wrong_frame.start.header().frame_id("odom");
  Job no_start = job("s", 0.5, 0.5, 8.5, 0.5);
  no_start.missing_start = "start: no robot_pose received yet";
  Job unknown_planner = job("u", 0.5, 0.5, 8.5, 0.5);
  unknown_planner.planner = "dijkstra";
  const Case cases[] = {
      {job("", 0.5, 0.5, 8.5, 0.5), &map, wire::INVALID_REQUEST, "id: must not be empty"},
      {unknown_planner, &map, wire::INVALID_REQUEST, "planner: unknown planner 'dijkstra'"},
      {no_start, &map, wire::INVALID_REQUEST, "no robot_pose"},
      {wrong_frame, &map, wire::FRAME_MISMATCH, "start.header.frame_id is 'odom'"},
      {job("n", std::nan(""), 0.5, 8.5, 0.5), &map, wire::INVALID_REQUEST, "start.pose.position.x"},
      {job("m", 0.5, 0.5, 8.5, 0.5), nullptr, wire::NO_MAP, "no map"},
      {job("o", -3.0, 0.5, 8.5, 0.5), &map, wire::START_OUTSIDE_MAP, "start (-3.000, 0.500) m"},
      {job("h", 0.5, 0.5, 1e300, 0.5), &map, wire::GOAL_OUTSIDE_MAP, "goal (1e+300, 0.500) m"},
      {job("b", 5.5, 2.5, 8.5, 0.5), &map, wire::START_OCCUPIED, "start"},
      {job("g", 0.5, 0.5, 5.5, 2.5), &map, wire::GOAL_OCCUPIED, "goal"},
  };
  for (const Case& c : cases) {
    const auto r = node::resolve_request(c.job, cfg, c.map);
    EXPECT_EQ(node::code_name(r.status.code), node::code_name(c.code)) << c.job.id;
    EXPECT_NE(r.status.message.find(c.words), std::string::npos)
        << c.job.id << ": " << r.status.message;
  }
  // NO_MAP names the topic the slices arrive on: the config's, or the one the node gives (a
  // fleet's robot has a namespace of its own, the map is the node's).
  const auto no_map = node::resolve_request(job("m", 0.5, 0.5, 8.5, 0.5), cfg, nullptr);
  EXPECT_NE(
      no_map.status.message.find("'" + node::dds_topic_name(cfg, cfg.topics.projected_map) + "'"),
      std::string::npos)
      << no_map.status.message;
  const auto fleet_no_map =
      node::resolve_request(job("m", 0.5, 0.5, 8.5, 0.5), cfg, nullptr, "rt/site2/projected_map");
  EXPECT_NE(fleet_no_map.status.message.find("'rt/site2/projected_map'"), std::string::npos)
      << fleet_no_map.status.message;
  const auto ok = node::resolve_request(job("ok", 0.5, 0.5, 8.5, 4.5), cfg, &map);
  ASSERT_TRUE(ok.status.ok()) << ok.status.message;
  EXPECT_EQ(ok.query.start, (core::Cell{0, 0}));
  EXPECT_EQ(ok.query.goal, (core::Cell{8, 4}));
  EXPECT_EQ(ok.planner_name, "vns_bastar");
}

// docs/algorithm.md section 8 in requests: a 2 m x 1 m map at 0.1 m, origin (0, 0), one occupied
// cell (10, 5) whose 4-neighbours robot_radius 0.1 m inflates; a cost gradient to 0.3 m.
node::NodeConfig tolerant_config() {
  node::NodeConfig cfg = paper_test_config();
  cfg.map.robot_radius = 0.1;
  cfg.map.inflation_radius = 0.3;
  cfg.planner.settings.cost_weight = 1.0;
  cfg.planner.settings.goal_tolerance = 0.3;
  cfg.planner.settings.start_tolerance = 0.15;
  return cfg;
}
core::GridMap inflated_map(const node::NodeConfig& cfg) {
  core::OccupancyGrid g;
  g.width = 20;
  g.height = 10;
  g.resolution = 0.1;
  g.data.assign(200, 0);
  g.data[5 * 20 + 10] = 100;
  return std::move(core::GridMap::build(g, cfg.map)).value();
}

// The requested points reach core (PlanQuery start_point/goal_point, in cells), so a tolerance
// picks the free cell nearest the real point, not the nearest to the blocked cell's centre.
TEST(ResolveRequest, RequestedPositionsReachTheQuery) {
  const node::NodeConfig cfg = tolerant_config();
  const core::GridMap map = inflated_map(cfg);
  ASSERT_EQ(map.layer({11, 5}), core::CellLayer::kInflated);
  const auto r = node::resolve_request(job("p", 0.25, 0.25, 1.16, 0.55), cfg, &map);
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  EXPECT_EQ(r.query.goal, (core::Cell{11, 5}));
  ASSERT_TRUE(r.query.goal_point && r.query.start_point);
  EXPECT_NEAR(r.query.goal_point->x(), 11.6, 1e-9);
  EXPECT_NEAR(r.query.goal_point->y(), 5.5, 1e-9);
  EXPECT_NEAR(r.query.start_point->x(), 2.5, 1e-9);
  const auto used = core::resolve_endpoints(map, r.query, r.options);
  ASSERT_TRUE(used) << used.error().message;
  // (12, 5) is 0.09 m from the point; from the centre of (11, 5) it would tie with (11, 4),
  // which the lower index wins.
  EXPECT_EQ(used->goal, (core::Cell{12, 5}));
  EXPECT_TRUE(used->goal_adjusted);
  EXPECT_NEAR(used->goal_moved_m, 0.09, 1e-9);
}

// With goal_tolerance > 0 a goal just outside the map is core's to resolve; farther than the
// tolerance it is GOAL_OUTSIDE_MAP in metres, as before. START_OUTSIDE_MAP is unchanged.
TEST(ResolveRequest, AGoalOutsideTheMapIsMovedOntoItWithinGoalTolerance) {
  const node::NodeConfig cfg = tolerant_config();
  const core::GridMap map = inflated_map(cfg);
  const auto near = node::resolve_request(job("near", 0.25, 0.25, 2.1, 0.55), cfg, &map);
  ASSERT_TRUE(near.status.ok()) << near.status.message;
  EXPECT_EQ(near.query.goal, (core::Cell{21, 5}));  // floor of the grid point, outside the map
  const auto used = core::resolve_endpoints(map, near.query, near.options);
  ASSERT_TRUE(used) << used.error().message;
  EXPECT_EQ(used->goal, (core::Cell{19, 5}));
  EXPECT_NEAR(used->goal_moved_m, 0.15, 1e-9);

  struct Case {
    double gx;
    std::string words;
  };
  const Case refused[] = {
      // Nearer than the tolerance to the map, but no cell centre within it: core's verdict.
      {2.28,
       "goal (2.280, 0.550) m is outside the map [0.000, 2.000] x [0.000, 1.000] m; no free "
       "cell within goal_tolerance 0.3 m"},
      {2.5,
       "goal (2.500, 0.550) m is outside the map [0.000, 2.000] x [0.000, 1.000] m; no free "
       "cell within goal_tolerance 0.3 m"},
      {1e300, "goal (1e+300, 0.550) m is outside the map"},
  };
  for (const Case& c : refused) {
    const auto r = node::resolve_request(job("far", 0.25, 0.25, c.gx, 0.55), cfg, &map);
    EXPECT_EQ(node::code_name(r.status.code), "GOAL_OUTSIDE_MAP") << c.gx;
    EXPECT_NE(r.status.message.find(c.words), std::string::npos) << r.status.message;
  }
  node::NodeConfig exact = cfg;
  exact.planner.settings.goal_tolerance = 0.0;
  const auto r = node::resolve_request(job("exact", 0.25, 0.25, 2.1, 0.55), exact, &map);
  EXPECT_EQ(node::code_name(r.status.code), "GOAL_OUTSIDE_MAP");
  EXPECT_EQ(r.status.message.find("tolerance"), std::string::npos) << r.status.message;
  const auto start = node::resolve_request(job("s", -0.05, 0.25, 1.0, 0.25), cfg, &map);
  EXPECT_EQ(node::code_name(start.status.code), "START_OUTSIDE_MAP");
}

// jps plans on uniform costs only. A request that picks it on a node configured with costs
// plans with cost_weight 0 and a warning naming the key; every other configured option stays.
// A corner policy jps cannot search with is still refused, before the map is looked at.
// A goal within goal_tolerance of a map of nanometre cells can lie billions of cells away: refused
// as outside, never cast to a cell index out of int32's range (a review finding; UBSan checks it).
TEST(ResolveRequest, AGoalTooManyCellsAwayIsOutsideWhateverTheTolerance) {
  node::NodeConfig cfg = paper_test_config();
  cfg.planner.settings.goal_tolerance = 5.0;
  core::OccupancyGrid g;
  g.width = 20;
  g.height = 10;
  g.resolution = 1e-9;
  g.data.assign(200, 0);
  auto built = core::GridMap::build(g);
  ASSERT_TRUE(built) << built.error().message;
  // 3 m: 3e9 cells, past int32's range.
  const auto r = node::resolve_request(job("far", 5e-9, 5e-9, 3.0, 5e-9), cfg, &built.value());
  EXPECT_EQ(node::code_name(r.status.code), "GOAL_OUTSIDE_MAP") << r.status.message;
  EXPECT_NE(r.status.message.find("more than 1e9 cells"), std::string::npos) << r.status.message;
  // 0.5 m (5e8 cells) is within reach: moved onto the map.
  const auto near = node::resolve_request(job("near", 5e-9, 5e-9, 0.5, 5e-9), cfg, &built.value());
  EXPECT_TRUE(near.status.ok()) << near.status.message;
}

TEST(ResolveRequest, JpsOnANodeWithCostsPlansOnUniformCostsWithAWarning) {
  const node::NodeConfig cfg = tolerant_config();
  ASSERT_GT(cfg.planner.options().cost_weight, 0.0);
  const core::GridMap map = inflated_map(cfg);
  Job jps = job("j", 0.25, 0.25, 1.85, 0.85);
  jps.planner = "jps";
  const auto r = node::resolve_request(jps, cfg, &map);
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  EXPECT_EQ(r.planner_name, "jps");
  EXPECT_EQ(r.options.cost_weight, 0.0);
  EXPECT_EQ(r.options.goal_tolerance, cfg.planner.options().goal_tolerance);
  EXPECT_TRUE(core::validate(r.options).is_ok());
  EXPECT_NE(r.warning.find("planner.cost_weight 1 not applied"), std::string::npos) << r.warning;
  // The configured planner keeps its costs, and so does astar.
  Job astar = jps;
  astar.planner = "astar";
  const auto a = node::resolve_request(astar, cfg, &map);
  ASSERT_TRUE(a.status.ok()) << a.status.message;
  EXPECT_EQ(a.options.cost_weight, cfg.planner.options().cost_weight);
  EXPECT_TRUE(a.warning.empty()) << a.warning;
  // Without costs there is nothing to warn about.
  node::NodeConfig uniform = cfg;
  uniform.planner.settings.cost_weight = 0.0;
  const auto u = node::resolve_request(jps, uniform, &map);
  EXPECT_TRUE(u.status.ok());
  EXPECT_TRUE(u.warning.empty()) << u.warning;
  // A setting jps cannot plan with at all is refused, map or no map.
  node::NodeConfig touch = cfg;
  touch.planner.settings.corner_policy = core::CornerPolicy::kTouch;
  for (const core::GridMap* m : {&map, static_cast<const core::GridMap*>(nullptr)}) {
    const auto t = node::resolve_request(jps, touch, m);
    EXPECT_EQ(node::code_name(t.status.code), "INVALID_REQUEST");
    EXPECT_NE(t.status.message.find("corner_policy"), std::string::npos) << t.status.message;
  }
}

// planner.name: auto (default.yaml's): a request that names no planner runs auto's choice, pruned
// and smoothed; one that names `auto` too, whatever planner.name says; one that names a planner
// gets that planner's paper configuration for the keys the file leaves out.
TEST(ResolveRequest, AutoAndNamedPlannersGetTheirOwnOptions) {
  const node::ConfigResult parsed = node::parse_config("");
  ASSERT_TRUE(parsed.config.has_value());
  node::NodeConfig cfg = *parsed.config;
  ASSERT_TRUE(cfg.planner.auto_kind);
  const core::GridMap map = small_map();
  Job unnamed = job("u", 0.5, 0.5, 9.5, 4.5);
  const auto u = node::resolve_request(unnamed, cfg, &map);
  ASSERT_TRUE(u.status.ok()) << u.status.message;
  EXPECT_EQ(u.planner_name, core::to_string(core::kCostAwareChoice));
  EXPECT_TRUE(u.options.prune && u.options.smooth);
  Job named = unnamed;
  named.planner = "astar";
  const auto a = node::resolve_request(named, cfg, &map);
  ASSERT_TRUE(a.status.ok()) << a.status.message;
  EXPECT_EQ(a.planner_name, "astar");
  EXPECT_FALSE(a.options.prune);  // astar's paper configuration: the file leaves prune out
  EXPECT_FALSE(a.options.smooth);
  EXPECT_EQ(a.options.smoother, core::PathSmoother::kRelax);  // the file's key applies
  // `auto` on a node whose planner.name is another planner, with and without costs.
  node::NodeConfig named_config = cfg;
  named_config.planner.auto_kind = false;
  named_config.planner.kind = core::PlannerKind::kVnsBaStar;
  Job automatic = unnamed;
  automatic.planner = "auto";
  for (const double weight : {2.0, 0.0}) {
    named_config.planner.settings.cost_weight = weight;
    const auto r = node::resolve_request(automatic, named_config, &map);
    ASSERT_TRUE(r.status.ok()) << r.status.message;
    EXPECT_EQ(r.planner_name, core::to_string(core::recommended_planner(
                                  weight, core::Neighborhood::kEight, core::CornerPolicy::kNever)));
    EXPECT_TRUE(r.options.prune && r.options.smooth);
  }
  // An unknown name lists auto among the known ones.
  Job unknown = unnamed;
  unknown.planner = "automatic";
  const auto bad = node::resolve_request(unknown, cfg, &map);
  EXPECT_EQ(node::code_name(bad.status.code), "INVALID_REQUEST");
  EXPECT_NE(bad.status.message.find("known: auto, astar"), std::string::npos) << bad.status.message;
}

// The goal's orientation: a unit quaternion gives the final yaw; a finite one of another norm
// is ignored with a warning (never a failure).
TEST(ResolveRequest, GoalOrientationGivesTheFinalYawOrAWarning) {
  const node::NodeConfig cfg = paper_test_config();
  const core::GridMap map = small_map();
  Job facing = job("y", 0.5, 0.5, 8.5, 4.5);
  facing.goal = node::to_pose_msg(8.5, 4.5, 2.0, "map", node::now_msg());
  const auto unit = node::resolve_request(facing, cfg, &map);
  ASSERT_TRUE(unit.status.ok()) << unit.status.message;
  ASSERT_TRUE(unit.goal_yaw);
  EXPECT_NEAR(*unit.goal_yaw, 2.0, 1e-12);
  EXPECT_EQ(unit.warning, "");

  Job scaled = facing;
  auto& q = scaled.goal.pose().orientation();
  q.z(0.5 * q.z());
  q.w(0.5 * q.w());
  const auto half = node::resolve_request(scaled, cfg, &map);
  ASSERT_TRUE(half.status.ok()) << half.status.message;
  EXPECT_FALSE(half.goal_yaw);
  EXPECT_EQ(
      half.warning.rfind("warning: goal orientation ignored: quaternion norm 0.5 is not 1", 0), 0u)
      << half.warning;

  Job zero = facing;
  zero.goal.pose().orientation().z(0.0);
  zero.goal.pose().orientation().w(0.0);
  const auto none = node::resolve_request(zero, cfg, &map);
  ASSERT_TRUE(none.status.ok()) << none.status.message;
  EXPECT_FALSE(none.goal_yaw);
  EXPECT_NE(none.warning.find("quaternion norm 0 is not 1"), std::string::npos) << none.warning;
}

// A request is checked once (resolve_request, on arrival); the worker plans it as accepted.
// resolve_leg gives a leg of it (its own endpoints on a newer map, a later leg of
// ComputePathThroughPoses): the planner as chosen on acceptance, the endpoints located on the
// map given, and each leg's own failures and orientation remark.
TEST(ResolveLeg, KeepsTheAcceptedPlannerAndLocatesTheLegOnItsMap) {
  const node::NodeConfig cfg = tolerant_config();
  const core::GridMap map = inflated_map(cfg);
  Job request = job("leg", 0.25, 0.25, 1.85, 0.85);
  request.planner = "jps";  // on a node with costs: uniform costs and a warning
  const auto accepted = node::resolve_request(request, cfg, &map);
  ASSERT_TRUE(accepted.status.ok()) << accepted.status.message;
  ASSERT_FALSE(accepted.planner_warning.empty());
  EXPECT_EQ(accepted.warning, accepted.planner_warning);

  // The planner is not chosen again: a changed planner field does not matter any more.
  Job renamed = request;
  renamed.planner = "no_such_planner";
  const auto same = node::resolve_leg(renamed, accepted, cfg, &map);
  ASSERT_TRUE(same.status.ok()) << same.status.message;
  EXPECT_EQ(same.planner_name, "jps");
  EXPECT_EQ(same.options.cost_weight, 0.0);
  EXPECT_EQ(same.warning, accepted.warning);
  EXPECT_EQ(same.query.start, accepted.query.start);
  EXPECT_EQ(same.query.goal, accepted.query.goal);

  // World points on a map whose corner lies 0.5 m further west: cells floor((x + 0.5) / 0.1),
  // floor(y / 0.1) there, (7, 2) and (13, 8).
  core::OccupancyGrid shifted;
  shifted.width = 20;
  shifted.height = 10;
  shifted.resolution = 0.1;
  shifted.origin_x = -0.5;
  shifted.data.assign(200, 0);
  const core::GridMap east = std::move(core::GridMap::build(shifted, cfg.map)).value();
  Job moved = job("leg", 0.25, 0.25, 0.85, 0.85);
  const auto on_east = node::resolve_leg(moved, accepted, cfg, &east);
  ASSERT_TRUE(on_east.status.ok()) << on_east.status.message;
  EXPECT_EQ(on_east.query.start, (core::Cell{7, 2}));
  EXPECT_EQ(on_east.query.goal, (core::Cell{13, 8}));

  // A later leg's goal is checked as a request's would be, in resolve_request's order: its
  // frame id's length first (before the planner is named), then the rest; an orientation
  // remark is the leg's own, after the planner's warning.
  Job long_frame = request;
  long_frame.goal.header().frame_id(std::string(node::kMaxFrameIdBytes + 1, 'f'));
  const auto refused = node::resolve_leg(long_frame, accepted, cfg, &map);
  EXPECT_EQ(node::code_name(refused.status.code), "INVALID_REQUEST");
  EXPECT_NE(refused.status.message.find("goal.header.frame_id"), std::string::npos)
      << refused.status.message;
  EXPECT_EQ(refused.planner_name, "");
  Job outside = request;
  outside.goal = node::to_pose_msg(9.0, 0.5, 0.0, "map", node::now_msg());
  EXPECT_EQ(node::code_name(node::resolve_leg(outside, accepted, cfg, &map).status.code),
            "GOAL_OUTSIDE_MAP");
  Job unfaced = request;
  unfaced.goal.pose().orientation().w(0.0);
  const auto remark = node::resolve_leg(unfaced, accepted, cfg, &map);
  ASSERT_TRUE(remark.status.ok()) << remark.status.message;
  EXPECT_EQ(remark.warning.rfind(accepted.planner_warning + "; warning: goal orientation", 0), 0u)
      << remark.warning;
}

std::vector<std::string> ids(const std::vector<Job>& jobs) {
  std::vector<std::string> out;
  for (const Job& j : jobs) out.push_back(j.id);
  return out;
}

TEST(RequestQueue, PreemptCancelsEveryOlderRequest) {
  node::RequestQueue queue(8, /*preempt=*/true);
  EXPECT_TRUE(queue.admit(job("a", 0, 0, 1, 1, client(1, 1))).empty());
  const std::optional<Job> planning = queue.next();
  ASSERT_TRUE(planning);
  EXPECT_TRUE(queue.admit(job("b", 0, 0, 1, 1, client(2, 1))).empty());
  EXPECT_TRUE(planning->interruption->flag) << "the plan in progress is preempted";
  EXPECT_EQ(planning->interruption->reason, "preempted by newer request 'b'");
  const auto answered = queue.admit(job("c", 0, 0, 1, 1, client(3, 1)));
  EXPECT_EQ(ids(answered), std::vector<std::string>{"b"});
  EXPECT_EQ(answered[0].interruption->reason, "preempted by newer request 'c'");
  EXPECT_EQ(queue.waiting(), 1u);
}

// Issue 13: two back-to-back requests with one id gave CANCELED then OK with no word on why.
// The newer replaces the older of the same client, whether it waits or is being planned, and
// with or without preemption; another client's request with the same id is left alone.
TEST(RequestQueue, ANewerRequestWithTheSameIdFromTheSameClientReplacesTheOlder) {
  for (bool preempt : {false, true}) {
    node::RequestQueue queue(8, preempt);
    queue.admit(job("x", 0, 0, 1, 1, client(1, 1)));
    const std::optional<Job> planning = queue.next();
    ASSERT_TRUE(planning);
    EXPECT_EQ(queue.admit(job("y", 0, 0, 1, 1, client(1, 2))).size(), 0u)
        << "nothing waits yet to be preempted or replaced";
    const auto answered = queue.admit(job("x", 0, 0, 1, 1, client(1, 3)));
    EXPECT_TRUE(planning->interruption->flag) << "preempt " << preempt;
    EXPECT_EQ(planning->interruption->reason.rfind(preempt ? "preempted"
                                                           : "replaced by a newer "
                                                             "request with the same id 'x'",
                                                   0),
              0u)
        << planning->interruption->reason;
    if (!preempt) {
      EXPECT_TRUE(answered.empty()) << "'y' keeps its place";
      EXPECT_EQ(queue.waiting(), 2u);
      // Another client's "x" replaces nothing.
      EXPECT_TRUE(queue.admit(job("x", 0, 0, 1, 1, client(2, 1))).empty());
      EXPECT_EQ(queue.waiting(), 3u);
      // The same client's third "x" replaces its waiting second one only.
      const auto replaced = queue.admit(job("x", 0, 0, 1, 1, client(1, 4)));
      ASSERT_EQ(replaced.size(), 1u);
      EXPECT_EQ(replaced[0].identity.sequence_number, 3);
      EXPECT_EQ(replaced[0].interruption->reason,
                "replaced by a newer request with the same id 'x' from the same client");
      EXPECT_EQ(queue.waiting(), 3u);
    }
  }
}

// Review: on a full queue a same-id request flagged the one being planned as replaced, then was
// refused itself, so neither was planned. A refused request replaces and preempts nothing.
TEST(RequestQueue, ARefusedRequestReplacesNothing) {
  node::RequestQueue queue(1, /*preempt=*/false);
  queue.admit(job("a", 0, 0, 1, 1, client(1, 1)));
  const std::optional<Job> planning = queue.next();
  queue.admit(job("b", 0, 0, 1, 1, client(2, 1)));  // fills the queue
  const auto refused = queue.admit(job("a", 0, 0, 1, 1, client(1, 2)));
  ASSERT_EQ(ids(refused), std::vector<std::string>{"a"});
  EXPECT_EQ(refused[0].identity.sequence_number, 2);
  EXPECT_FALSE(planning->interruption->flag) << planning->interruption->reason;
  // With room made by the replacement itself, the same-id request is admitted.
  node::RequestQueue roomy(1, false);
  roomy.admit(job("a", 0, 0, 1, 1, client(1, 1)));
  const auto replaced = roomy.admit(job("a", 0, 0, 1, 1, client(1, 2)));
  ASSERT_EQ(replaced.size(), 1u);
  EXPECT_EQ(replaced[0].identity.sequence_number, 1);
  EXPECT_EQ(roomy.waiting(), 1u);
}

TEST(RequestQueue, AFullQueueRefusesTheNewRequestOnly) {
  node::RequestQueue queue(2, /*preempt=*/false);
  queue.admit(job("a", 0, 0, 1, 1, client(1, 1)));
  queue.admit(job("b", 0, 0, 1, 1, client(1, 2)));
  const auto refused = queue.admit(job("c", 0, 0, 1, 1, client(1, 3)));
  ASSERT_EQ(ids(refused), std::vector<std::string>{"c"});
  EXPECT_EQ(refused[0].interruption->reason, "request queue is full (requests.queue_capacity = 2)");
  EXPECT_EQ(queue.next()->id, "a");
  EXPECT_EQ(queue.next()->id, "b");
  EXPECT_FALSE(queue.next());
}

// Issue 13: a 400 x 400 slice took 113 s to convert and a valid map sent 0.5 s later waited for
// it. A newer slice replaces a waiting one and tells the conversion in progress to stop.
TEST(SliceSlot, ANewerSliceSupersedesTheWaitingAndTheConvertingOne) {
  node::SliceSlot slot;
  EXPECT_FALSE(slot.take());
  node::OccupancyGridMsg first, second, third;
  first.info().width(1);
  second.info().width(2);
  third.info().width(3);
  auto put = slot.put(std::move(first));
  EXPECT_FALSE(put.replaced_waiting);
  EXPECT_FALSE(put.superseded_converting);
  auto converting = slot.take();
  ASSERT_TRUE(converting);
  EXPECT_EQ(converting->slice.info().width(), 1u);
  EXPECT_FALSE(converting->superseded->load());
  put = slot.put(std::move(second));
  EXPECT_TRUE(put.superseded_converting);
  EXPECT_TRUE(converting->superseded->load()) << "GridMap::build polls this flag";
  put = slot.put(std::move(third));
  EXPECT_TRUE(put.replaced_waiting);
  EXPECT_FALSE(put.superseded_converting) << "told once";
  slot.finish(false);
  auto next = slot.take();
  ASSERT_TRUE(next);
  EXPECT_EQ(next->slice.info().width(), 3u) << "only the newest slice is converted";
  EXPECT_FALSE(next->superseded->load());
  slot.finish(true);
  node::OccupancyGridMsg fourth;
  EXPECT_FALSE(slot.put(std::move(fourth)).superseded_converting) << "nothing in conversion";
}

// Review: slices arriving faster than a map converts canceled every conversion, so no map ever
// went live. After kMaxSupersededInARow stopped conversions the next one is let finish.
TEST(SliceSlot, AStreamOfSlicesStillLetsEveryThirdConversionFinish) {
  node::SliceSlot slot;
  slot.put(node::OccupancyGridMsg());
  for (int round = 0; round < 3; ++round) {
    for (int stopped = 0; stopped < node::SliceSlot::kMaxSupersededInARow; ++stopped) {
      auto converting = slot.take();
      ASSERT_TRUE(converting);
      EXPECT_TRUE(slot.put(node::OccupancyGridMsg()).superseded_converting);
      EXPECT_TRUE(converting->superseded->load());
      slot.finish(false);
    }
    auto protected_one = slot.take();
    ASSERT_TRUE(protected_one);
    EXPECT_FALSE(slot.put(node::OccupancyGridMsg()).superseded_converting);
    EXPECT_FALSE(protected_one->superseded->load()) << "round " << round;
    slot.finish(true);  // it went live; the count starts again
  }
}

}  // namespace
}  // namespace vnsba::test
