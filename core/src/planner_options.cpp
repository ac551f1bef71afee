#include "vnsba/core/planner_options.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <ostream>
#include <sstream>
#include <string>

#include "vnsba/core/planner_registry.hpp"

namespace vnsba::core {

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
  return kind.descriptor() != nullptr ? kind.descriptor()->name : "unknown";
}

std::ostream& operator<<(std::ostream& out, PlannerKind kind) {
  return out << to_string(kind);
}

namespace {

// The planner's place in the registration (the default-constructed kind before every planner).
size_t registration_index(PlannerKind kind) {
  const auto& all = registered_planners();
  const auto it = std::find(all.begin(), all.end(), kind.descriptor());
  return it == all.end() ? 0 : static_cast<size_t>(it - all.begin()) + 1;
}

}  // namespace

bool operator<(PlannerKind a, PlannerKind b) {
  return registration_index(a) < registration_index(b);
}

std::optional<PlannerKind> planner_kind_from_string(std::string_view name) {
  if (const PlannerDescriptor* planner = find_planner(name)) return PlannerKind(planner);
  return std::nullopt;
}

const std::vector<PlannerKind>& all_planner_kinds() {
  static const std::vector<PlannerKind> kinds = [] {
    std::vector<PlannerKind> out;
    for (const PlannerDescriptor* planner : registered_planners()) out.emplace_back(planner);
    return out;
  }();
  return kinds;
}

// A planner's capabilities (planner_registry.hpp); the default-constructed kind has none.
bool supports(PlannerKind kind, Neighborhood neighborhood) {
  const PlannerDescriptor* planner = kind.descriptor();
  return neighborhood == Neighborhood::kEight || (planner != nullptr && planner->can.long_moves);
}
bool supports(PlannerKind kind, CornerPolicy policy) {
  const PlannerDescriptor* planner = kind.descriptor();
  return policy == CornerPolicy::kNever || (planner != nullptr && planner->can.corner_cutting);
}

bool supports_costs(PlannerKind kind) {
  return kind.descriptor() != nullptr && kind.descriptor()->can.costs;
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
  if (kind.descriptor() != nullptr) kind.descriptor()->paper_configuration(options);
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
  const PlannerDescriptor* planner = o.planner.descriptor();
  if (planner == nullptr) {
    err() << "planner is not a known planner; ";
  } else {
    // The ranges of every planner's own options (a request that switches planners keeps them),
    // then the rules of this planner's.
    bool own_ok = true;
    for (const OwnOption* own : all_own_options())
      own_ok = check(*own->range, o.*own->option) && own_ok;
    std::vector<OptionProblem> problems;
    if (own_ok && planner->check_own_options != nullptr) planner->check_own_options(o, problems);
    for (const OptionProblem& problem : problems) {
      for (size_t k = 0; k < problem.keys.size(); ++k)
        err() << (k == 0 ? "" : k + 1 == problem.keys.size() ? " and " : ", ") << problem.keys[k];
      err() << " " << problem.rule << " for " << planner->name << " (" << problem.why << "); ";
    }
    if (!supports(o.planner, o.corner_policy))
      err() << "corner_policy " << to_string(o.corner_policy) << " is not supported by "
            << planner->name << " (" << planner->can.without_corner_cutting
            << "; use never, or another planner); ";
    if (!supports(o.planner, o.neighborhood))
      err() << "neighborhood " << to_string(o.neighborhood) << " is not supported by "
            << planner->name << " (" << planner->can.without_long_moves
            << "; use 8, or another planner); ";
  }
  if (check(kCostWeightRange, o.cost_weight) && o.cost_weight > 0.0 && planner != nullptr &&
      !planner->can.costs)
    err() << "cost_weight " << o.cost_weight << " is not supported by " << planner->name << " ("
          << planner->can.without_costs << "; use cost_weight 0, or another planner); ";
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
  if (!stream) return Status::ok();
  std::string message = stream->str();
  message.resize(message.size() - 2);
  return Status::error(StatusCode::kInvalidRequest, "invalid options: " + message);
}

PlannerOptions make_options(PlannerKind kind, const PlannerSettings& s) {
  PlannerOptions o = default_options(kind);
  // The options planners own (omega and eta: VNS-BA*'s), set whichever planner runs, so that a
  // request switching planners keeps them.
  for (const OwnOption* own : all_own_options())
    if (const std::optional<double>& value = s.*own->setting) o.*own->option = *value;
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
  for (const PlannerDescriptor* planner : registered_planners())
    names += ", " + std::string(planner->name);
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
