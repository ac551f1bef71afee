#include "vnsba/core/planner_options.hpp"

#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>
#include <string>

namespace vnsba::core {

namespace {

struct PlannerName {
  PlannerKind kind;
  std::string_view name;
};
constexpr PlannerName kPlannerNames[] = {
    {PlannerKind::kAStar, "astar"},
    {PlannerKind::kWeightedAStar, "weighted_astar"},
    {PlannerKind::kBidirectionalAStar, "bidirectional_astar"},
    {PlannerKind::kAlternatingBidirectionalAStar, "alternating_bidirectional_astar"},
    {PlannerKind::kVnsBaStar, "vns_bastar"},
    {PlannerKind::kJps, "jps"},
};

}  // namespace

std::string OptionRange::describe() const {
  // Shortest form a user would type: 0.05, 10, 1e6 (not 1e+06).
  auto number = [](double v) {
    char text[32];
    std::snprintf(text, sizeof(text), "%g", v);
    std::string s = text;
    if (const size_t e = s.find("e+"); e != std::string::npos) {
      size_t digits = e + 2;
      while (digits + 1 < s.size() && s[digits] == '0') ++digits;
      s = s.substr(0, e + 1) + s.substr(digits);
    }
    return s;
  };
  return (*unit ? std::string("a number of ") + unit : std::string("a number")) + " in " +
         (min_excluded ? "(" : "[") + number(min) + ", " + number(max) + "]";
}

std::string_view to_string(PathSmoother smoother) {
  return smoother == PathSmoother::kRelax ? "relax" : "none";
}

std::optional<PathSmoother> path_smoother_from_string(std::string_view name) {
  if (name == "none") return PathSmoother::kNone;
  if (name == "relax") return PathSmoother::kRelax;
  return std::nullopt;
}

std::string_view to_string(PlannerKind kind) {
  for (const auto& entry : kPlannerNames)
    if (entry.kind == kind) return entry.name;
  return "unknown";
}

std::optional<PlannerKind> planner_kind_from_string(std::string_view name) {
  for (const auto& entry : kPlannerNames)
    if (entry.name == name) return entry.kind;
  return std::nullopt;
}

const std::vector<PlannerKind>& all_planner_kinds() {
  static const std::vector<PlannerKind> kinds = [] {
    std::vector<PlannerKind> out;
    for (const auto& entry : kPlannerNames) out.push_back(entry.kind);
    return out;
  }();
  return kinds;
}

// Jump Point Search prunes every move that an optimal 8-connected path without corner cutting
// does not need: its rules hold for that graph only.
bool supports(PlannerKind kind, Neighborhood neighborhood) {
  return kind != PlannerKind::kJps || neighborhood == Neighborhood::kEight;
}
bool supports(PlannerKind kind, CornerPolicy policy) {
  return kind != PlannerKind::kJps || policy == CornerPolicy::kNever;
}

bool supports_costs(PlannerKind kind) {
  return kind != PlannerKind::kJps;
}

bool drop_unsupported_costs(PlannerOptions& options) {
  if (supports_costs(options.planner) || !(options.cost_weight > 0.0)) return false;
  options.cost_weight = 0.0;
  return true;
}

PlannerKind recommended_planner(double cost_weight, Neighborhood neighborhood,
                                CornerPolicy corner_policy) {
  const bool uniform_costs = !(cost_weight > 0.0);
  return uniform_costs && supports(PlannerKind::kJps, neighborhood) &&
                 supports(PlannerKind::kJps, corner_policy)
             ? PlannerKind::kJps
             : kCostAwareChoice;
}

PlannerOptions default_options(PlannerKind kind) {
  PlannerOptions options;
  options.planner = kind;
  const bool paper_method = kind == PlannerKind::kVnsBaStar;
  options.neighborhood = paper_method ? Neighborhood::kEightElevenThirteen : Neighborhood::kEight;
  options.prune = paper_method;
  options.smooth = paper_method;
  return options;
}

Status validate(const PlannerOptions& o) {
  // Called by every plan: the stream (and its locale) is made only when something is wrong.
  std::optional<std::ostringstream> stream;
  auto err = [&]() -> std::ostringstream& { return stream ? *stream : stream.emplace(); };
  auto check = [&](const OptionRange& range, double value) {
    if (range.contains(value)) return true;
    err() << range.key << " must be " << range.describe() << " (got " << value << "); ";
    return false;
  };
  const bool omega_ok = check(kOmegaRange, o.omega);
  const bool eta_ok = check(kEtaRange, o.eta);
  if (o.planner == PlannerKind::kVnsBaStar && omega_ok && eta_ok && o.omega == 0.0 &&
      o.eta == 0.0) {
    err() << "omega and eta must not both be 0 (the heuristic would vanish); ";
  }
  if (!supports(o.planner, o.corner_policy))
    err() << "corner_policy " << to_string(o.corner_policy) << " is not supported by "
          << to_string(o.planner)
          << ", whose jump rules need both cells beside a diagonal move free (use never, or "
             "another planner); ";
  if (!supports(o.planner, o.neighborhood))
    err() << "neighborhood " << to_string(o.neighborhood) << " is not supported by "
          << to_string(o.planner)
          << ", which searches the 8-neighbourhood (use 8, or another planner); ";
  if (check(kCostWeightRange, o.cost_weight) && o.cost_weight > 0.0 && !supports_costs(o.planner))
    err() << "cost_weight " << o.cost_weight << " is not supported by " << to_string(o.planner)
          << ", whose jump rules hold only on a grid of uniform costs (use cost_weight 0, or "
             "another planner); ";
  auto check_tolerance = [&](const char* key, double value) {
    if (kToleranceRange.contains(value)) return;
    err() << key << " must be " << kToleranceRange.describe() << " (got " << value << "); ";
  };
  check_tolerance("goal_tolerance", o.goal_tolerance);
  check_tolerance("start_tolerance", o.start_tolerance);
  check(kSmoothingDistanceRange, o.smoothing_distance);
  check(kSampleStepRange, o.sample_step);
  if (o.smoother != PathSmoother::kNone && o.smoother != PathSmoother::kRelax)
    err() << "smoother is not a known smoother; ";
  const bool smoothness_ok = check(kSmootherSmoothnessRange, o.smoother_smoothness);
  const bool closeness_ok = check(kSmootherClosenessRange, o.smoother_closeness);
  if (smoothness_ok && closeness_ok && !(2.0 * o.smoother_smoothness + o.smoother_closeness < 2.0))
    err() << "2 * smoother_smoothness + smoother_closeness must be below 2, or the relaxation "
             "overshoots further each iteration (got "
          << 2.0 * o.smoother_smoothness + o.smoother_closeness << "); ";
  check(kSmootherCostRange, o.smoother_cost);
  check(kSmootherIterationsRange, o.smoother_iterations);
  const double seconds = std::chrono::duration<double>(o.max_planning_time).count();
  check(kMaxPlanningTimeRange, seconds);
  if (!planner_kind_from_string(to_string(o.planner))) err() << "planner is not a known planner; ";
  if (!stream) return Status::ok();
  std::string message = stream->str();
  message.resize(message.size() - 2);
  return Status::error(StatusCode::kInvalidRequest, "invalid options: " + message);
}

PlannerOptions make_options(PlannerKind kind, const PlannerSettings& s) {
  PlannerOptions o = default_options(kind);
  if (s.omega) o.omega = *s.omega;
  if (s.eta) o.eta = *s.eta;
  if (s.neighborhood) o.neighborhood = *s.neighborhood;
  if (s.corner_policy) o.corner_policy = *s.corner_policy;
  if (s.prune) o.prune = *s.prune;
  if (s.smooth) o.smooth = *s.smooth;
  if (s.smoothing_distance) o.smoothing_distance = *s.smoothing_distance;
  if (s.sample_step) o.sample_step = *s.sample_step;
  if (s.max_planning_time) o.max_planning_time = *s.max_planning_time;
  if (s.record_expansions) o.record_expansions = *s.record_expansions;
  if (s.compute_length_ratio) o.compute_length_ratio = *s.compute_length_ratio;
  if (s.cost_weight) o.cost_weight = *s.cost_weight;
  if (s.goal_tolerance) o.goal_tolerance = *s.goal_tolerance;
  if (s.start_tolerance) o.start_tolerance = *s.start_tolerance;
  if (s.smoother) o.smoother = *s.smoother;
  if (s.smoother_smoothness) o.smoother_smoothness = *s.smoother_smoothness;
  if (s.smoother_closeness) o.smoother_closeness = *s.smoother_closeness;
  if (s.smoother_cost) o.smoother_cost = *s.smoother_cost;
  if (s.smoother_iterations) o.smoother_iterations = *s.smoother_iterations;
  return o;
}

std::string accepted_planner_names() {
  std::string names(kAutoPlannerName);
  for (const auto& entry : kPlannerNames) names += ", " + std::string(entry.name);
  return names;
}

PlannerSettings with_auto_defaults(PlannerSettings settings) {
  if (!settings.prune) settings.prune = true;
  if (!settings.smooth) settings.smooth = true;
  return settings;
}

PlannerOptions make_auto_options(const PlannerSettings& settings) {
  const PlannerSettings chosen = with_auto_defaults(settings);
  const PlannerOptions moves = make_options(kCostAwareChoice, chosen);
  return make_options(
      recommended_planner(moves.cost_weight, moves.neighborhood, moves.corner_policy), chosen);
}

}  // namespace vnsba::core
