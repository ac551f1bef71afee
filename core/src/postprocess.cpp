// Polyline pruning (docs/algorithm.md section 4, paper 3.3) and local cubic-spline smoothing at
// turns (docs/algorithm.md section 5, paper 3.4), the exact ends and the relax smoother. Every
// check of a segment, and its cost, is MotionValidator's (motion_validator.hpp).
#include "vnsba/core/postprocess.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "vnsba/core/motion_validator.hpp"

namespace vnsba::core {

namespace {
// A shortcut "costs no more" than the stretch it replaces up to rounding: a straight stretch of
// the grid path, priced step by step, and the same stretch priced at once differ by an ulp or two,
// and without this slack pruning would keep a turning point there (docs/algorithm.md section 8:
// equal in exact arithmetic). Relative.
constexpr double kCostRoundingTolerance = 1.0 + 1e-12;
}  // namespace

double path_cost(const GridMap& map, const std::vector<Point2>& polyline, double cost_weight,
                 CornerPolicy policy) {
  return MotionValidator(map, policy, cost_weight).path_cost(polyline);
}

std::vector<Point2> prune_path(const GridMap& map, const std::vector<Cell>& path,
                               CornerPolicy policy, PlanningBudget* budget, double cost_weight) {
  std::vector<Point2> out;
  if (path.empty()) return out;
  out.push_back(cell_centre(path.front()));
  const MotionValidator motion(map, policy, cost_weight);
  // With costs: the grid path's cost up to each cell, to price the stretch a shortcut replaces.
  std::vector<double> cost_to;
  if (cost_weight > 0.0) {
    cost_to.assign(path.size(), 0.0);
    for (size_t k = 1; k < path.size(); ++k)
      cost_to[k] =
          cost_to[k - 1] + motion.segment_cost(cell_centre(path[k - 1]), cell_centre(path[k]));
  }
  auto affordable = [&](size_t from, size_t to) {
    return cost_to.empty() || motion.segment_cost(cell_centre(path[from]), cell_centre(path[to])) <=
                                  (cost_to[to] - cost_to[from]) * kCostRoundingTolerance;
  };
  size_t anchor = 0;  // index into path
  size_t i = 1;
  while (i < path.size()) {
    if (budget != nullptr && budget->poll() != StatusCode::kOk) return {};
    // A single step is the path itself, affordable by definition.
    if (motion.segment_valid(path[anchor], path[i]) && (anchor + 1 == i || affordable(anchor, i))) {
      ++i;
    } else if (anchor + 1 == i) {
      // Only an invalid input (a step without line of sight, e.g. through a wall or from a
      // blocked cell) gets here. Keep the step as it is rather than loop forever.
      anchor = i++;
      out.push_back(cell_centre(path[anchor]));
    } else {
      // P[i] is the first point the anchor cannot see: P[i-1] is a turning point. P[i] is
      // re-tested against the new anchor on the next iteration.
      anchor = i - 1;
      out.push_back(cell_centre(path[anchor]));
    }
  }
  // The last point, unless the fallback above already appended it (or the path is one cell).
  if (anchor + 1 != path.size()) out.push_back(cell_centre(path.back()));
  return out;
}

std::vector<Point2> join_exact_ends(const GridMap& map, std::vector<Point2> waypoints,
                                    const Point2& start, const Point2& goal, CornerPolicy policy,
                                    double cost_weight, bool drop_centres) {
  if (waypoints.empty()) return waypoints;
  // A requested point within rounding of its cell's centre (a world position converted to cells,
  // 1.5000000000000002 for 1.5) replaces the centre instead of adding a segment of 1e-16 cells
  // whose heading is noise (it turned two extra corners into a path planned from centres).
  constexpr double kSamePointCells = 1e-9;
  auto same = [&](const Point2& a, const Point2& b) { return (a - b).norm() <= kSamePointCells; };
  if (same(start, waypoints.front())) waypoints.front() = start;
  if (same(goal, waypoints.back())) waypoints.back() = goal;
  const bool start_added = start != waypoints.front();
  const bool goal_added = goal != waypoints.back();
  if (start_added) waypoints.insert(waypoints.begin(), start);
  if (goal_added) waypoints.push_back(goal);
  if (!drop_centres) return waypoints;
  // a -> b in place of a -> via -> b: clear, and no dearer (up to rounding, as in pruning).
  const MotionValidator motion(map, policy, cost_weight);
  auto shortcut = [&](const Point2& a, const Point2& via, const Point2& b) {
    return motion.segment_cost(a, b) <=
           (motion.segment_cost(a, via) + motion.segment_cost(via, b)) * kCostRoundingTolerance;
  };
  if (start_added && waypoints.size() >= 3 && shortcut(waypoints[0], waypoints[1], waypoints[2]))
    waypoints.erase(waypoints.begin() + 1);
  // waypoints[k - 2] is the last centre unless the first step dropped the only one (then the
  // path is start, goal: fewer than 3 points).
  const size_t k = waypoints.size();
  if (goal_added && k >= 3 && shortcut(waypoints[k - 3], waypoints[k - 2], waypoints[k - 1]))
    waypoints.erase(waypoints.end() - 2);
  return waypoints;
}

namespace {

constexpr double kCollinearRad = 1e-6;  // corners turning less than this are left alone

// A parametric cubic spline x(s), y(s) through four points with chord-length knots, clamped
// end derivatives, C1 and C2 at the two inner knots: three cubic pieces per coordinate.
//
// Parametric, not the paper's y = S(x): a vertical leg has the same x at several points, which
// y = S(x) cannot represent; x(s), y(s) does not care about the orientation of the corner.
// With chord-length s, |d/ds| is close to 1, so unit tangents are the right clamped derivatives.
struct CornerSpline {
  std::array<Point2, 4> p;
  std::array<double, 3> h{};      // knot spacings (chord lengths)
  Eigen::Matrix<double, 4, 2> m;  // second derivatives d2/ds2 at the knots, columns x and y

  // nullopt when a chord is degenerate (e.g. a full reversal, P2 == P3) or the solve is not
  // finite.
  static std::optional<CornerSpline> fit(const std::array<Point2, 4>& points,
                                         const Point2& start_tangent, const Point2& end_tangent) {
    CornerSpline spline;
    spline.p = points;
    double total = 0.0;
    for (int i = 0; i < 3; ++i) {
      spline.h[i] = (points[i + 1] - points[i]).norm();
      total += spline.h[i];
    }
    for (double hi : spline.h) {
      if (!(hi > 1e-9 * total)) return std::nullopt;
    }
    const auto& h = spline.h;
    // The classic clamped-spline system for the knot second derivatives (moments) M0..M3:
    // the two clamped ends plus C2 continuity at P2 and P3, solved for x and y together.
    Eigen::Matrix4d a = Eigen::Matrix4d::Zero();
    Eigen::Matrix<double, 4, 2> rhs;
    const Point2 slope0 = (points[1] - points[0]) / h[0];
    const Point2 slope1 = (points[2] - points[1]) / h[1];
    const Point2 slope2 = (points[3] - points[2]) / h[2];
    a.row(0) << 2 * h[0], h[0], 0, 0;
    a.row(1) << h[0], 2 * (h[0] + h[1]), h[1], 0;
    a.row(2) << 0, h[1], 2 * (h[1] + h[2]), h[2];
    a.row(3) << 0, 0, h[2], 2 * h[2];
    rhs.row(0) = 6.0 * (slope0 - start_tangent).transpose();
    rhs.row(1) = 6.0 * (slope1 - slope0).transpose();
    rhs.row(2) = 6.0 * (slope2 - slope1).transpose();
    rhs.row(3) = 6.0 * (end_tangent - slope2).transpose();
    spline.m = a.partialPivLu().solve(rhs);
    if (!spline.m.allFinite()) return std::nullopt;
    return spline;
  }

  // The point at parameter u in [0, h[piece]] measured from the start of `piece` (0, 1 or 2).
  Point2 at(int piece, double u) const {
    const double hi = h[piece];
    const double v = hi - u;
    const Point2 m0 = m.row(piece).transpose(), m1 = m.row(piece + 1).transpose();
    return (m0 * (v * v * v) + m1 * (u * u * u)) / (6.0 * hi) +
           (p[piece] / hi - m0 * (hi / 6.0)) * v + (p[piece + 1] / hi - m1 * (hi / 6.0)) * u;
  }
};

// Appends the samples of one piece (excluding its start knot, ending exactly on its end knot)
// at most `step` apart. The first guess assumes the arc is at most 1.5 x the chord; the gaps are
// then measured and the count doubled until they all fit (the bound is not a theorem).
void sample_piece(const CornerSpline& spline, int piece, double step, std::vector<Point2>& out) {
  const double hi = spline.h[piece];
  int n = std::max(1, static_cast<int>(std::ceil(1.5 * hi / step)));
  std::vector<Point2> samples;
  for (int attempt = 0; attempt < 16; ++attempt, n *= 2) {
    samples.clear();
    Point2 last = spline.p[piece];
    bool fits = true;
    for (int j = 1; j <= n; ++j) {
      const Point2 q = j == n ? spline.p[piece + 1] : spline.at(piece, hi * j / n);
      fits = fits && (q - last).norm() <= step;
      samples.push_back(q);
      last = q;
    }
    if (fits) break;
  }
  out.insert(out.end(), samples.begin(), samples.end());
}

// The replacement P1, samples..., P4 of corner T (neighbours A and B) at distance d, or nullopt
// when the spline cannot be fitted or any of its segments, or the joins prev -> P1 and P4 -> B,
// lacks line of sight, or (cost_weight > 0) when prev -> P1, the curve and P4 -> B cost more than
// `cost_before`, the cost of prev -> T -> B (the same for every d: the caller prices it once).
std::optional<std::vector<Point2>> smooth_corner(const MotionValidator& motion, const Point2& prev,
                                                 const Point2& a, const Point2& t, const Point2& b,
                                                 double d, const SmoothingOptions& options,
                                                 double cost_before) {
  const Point2 to_a = (a - t).normalized(), to_b = (b - t).normalized();
  // T itself is not a control point: a curve forced through the corner would bulge outside it,
  // towards the obstacle the path turned around (the paper's reason for P1..P4).
  const std::array<Point2, 4> points = {t + 2 * d * to_a, t + d * to_a, t + d * to_b,
                                        t + 2 * d * to_b};
  const auto spline = CornerSpline::fit(points, -to_a, to_b);
  if (!spline) return std::nullopt;
  std::vector<Point2> curve = {points[0]};
  for (int piece = 0; piece < 3; ++piece) sample_piece(*spline, piece, options.sample_step, curve);

  if (!motion.segment_valid(prev, curve.front())) return std::nullopt;
  for (size_t i = 1; i < curve.size(); ++i) {
    if (!motion.segment_valid(curve[i - 1], curve[i])) return std::nullopt;
  }
  if (!motion.segment_valid(curve.back(), b)) return std::nullopt;
  if (options.cost_weight > 0.0) {
    // The path so far ends at prev, and what follows it is prev -> T -> B and the legs after B.
    // With the curve, prev -> P1, the curve and P4 -> B take the place of prev -> T -> B; kept
    // only when they cost no more, so each corner leaves the whole path no dearer, whatever the
    // corners before and after do. (Pricing P1 -> T -> P4 alone is not enough: a piece of a
    // diagonal leg that passes exactly through cell corners can, by rounding, cross beside a
    // corner that the whole leg passes through, and meet a dearer cell.)
    const double after = motion.segment_cost(prev, curve.front()) + motion.path_cost(curve) +
                         motion.segment_cost(curve.back(), b);
    if (!(after <= cost_before * kCostRoundingTolerance)) return std::nullopt;
  }
  return curve;
}

}  // namespace

std::vector<Point2> smooth_path(const GridMap& map, const std::vector<Point2>& waypoints,
                                const SmoothingOptions& options, PlanningBudget* budget) {
  // Nothing to smooth, or no usable sampling (a non-positive step would never terminate).
  if (waypoints.size() < 3 || !std::isfinite(options.sample_step) || options.sample_step <= 0.0) {
    return waypoints;
  }
  const MotionValidator motion(map, options.corner_policy, options.cost_weight);
  std::vector<Point2> out = {waypoints.front()};
  for (size_t i = 1; i + 1 < waypoints.size(); ++i) {
    // A and B come from the input, not from the already-smoothed output.
    const Point2& a = waypoints[i - 1];
    const Point2& t = waypoints[i];
    const Point2& b = waypoints[i + 1];
    // Zero-length legs (repeated points) also give 0 here and keep T: no division by zero.
    const bool straight = !(std::abs(heading_change(a, t, b)) > kCollinearRad);
    // Capping d at a quarter of each leg puts P1 and P4 at most half-way along it, so the
    // smoothings of two neighbouring corners never overlap (they may at most touch).
    double d = std::min({options.smoothing_distance, (t - a).norm() / 4, (b - t).norm() / 4});
    std::optional<std::vector<Point2>> curve;
    if (!straight && std::isfinite(d) && d > 0.0) {
      const double cost_before =
          options.cost_weight > 0.0 ? motion.segment_cost(out.back(), t) + motion.segment_cost(t, b)
                                    : 0.0;
      for (int attempt = 0; attempt <= std::max(0, options.max_halvings); ++attempt, d /= 2) {
        if (budget != nullptr && budget->poll() != StatusCode::kOk) return {};
        curve = smooth_corner(motion, out.back(), a, t, b, d, options, cost_before);
        if (curve) break;
      }
    }
    if (!curve) {
      out.push_back(t);  // collinear, degenerate, or no collision-free curve: keep T sharp
      continue;
    }
    // P1 may coincide with the previous corner's P4 when both sit half-way along a leg.
    const bool skip_first = (curve->front() - out.back()).norm() <= 1e-12;
    out.insert(out.end(), curve->begin() + (skip_first ? 1 : 0), curve->end());
  }
  out.push_back(waypoints.back());
  return out;
}

namespace {

// The gradient, per cell, of the cell costs interpolated bilinearly between cell centres, at p
// (continuous cell coordinates). Blocked cells and the map's border count 1 (GridMap::cost_data),
// so the gradient also points away from walls where a free cell beside them costs less.
Point2 cost_gradient(const GridMap& map, const Point2& p) {
  const float* costs = map.cost_data();
  if (costs == nullptr) return Point2::Zero();
  const double u = p.x() - 0.5, v = p.y() - 0.5;
  // The four centres around p, kept inside the padded layout (x in [-1, width]).
  const int32_t x0 = std::clamp(static_cast<int32_t>(std::floor(u)), -1, map.width() - 1);
  const int32_t y0 = std::clamp(static_cast<int32_t>(std::floor(v)), -1, map.height() - 1);
  const double fx = std::clamp(u - x0, 0.0, 1.0), fy = std::clamp(v - y0, 0.0, 1.0);
  const size_t at = map.padded_index(x0, y0), up = at + static_cast<size_t>(map.stride());
  const double c00 = costs[at], c10 = costs[at + 1], c01 = costs[up], c11 = costs[up + 1];
  return {(1.0 - fy) * (c10 - c00) + fy * (c11 - c01), (1.0 - fx) * (c01 - c00) + fx * (c11 - c10)};
}

// The path with points added so that no segment is longer than `spacing` (its own points kept).
std::vector<Point2> densify(const std::vector<Point2>& path, double spacing) {
  std::vector<Point2> out;
  if (path.empty()) return out;
  out.push_back(path.front());
  for (size_t i = 1; i < path.size(); ++i) {
    const Point2 from = path[i - 1], step = path[i] - from;
    const int pieces = std::max(1, static_cast<int>(std::ceil(step.norm() / spacing)));
    for (int k = 1; k < pieces; ++k) out.push_back(from + step * (static_cast<double>(k) / pieces));
    out.push_back(path[i]);
  }
  return out;
}

}  // namespace

namespace {

// A run of points each within kRelaxCompactCells of the chord from the last kept point to the
// run's end is replaced by that chord when it keeps the clearance `motion` asks (at most
// kMaxSkipped points a chord, so the checks stay short). Compacting a compacted path changes
// nothing.
std::vector<Point2> compact(const std::vector<Point2>& points, const MotionValidator& motion) {
  constexpr size_t kMaxSkipped = 16;
  if (points.size() < 3) return points;
  const size_t last = points.size() - 1;
  std::vector<Point2> out = {points.front()};
  size_t anchor = 0;
  while (anchor < last) {
    size_t end = anchor + 1;
    while (end < last && end - anchor <= kMaxSkipped) {
      bool close = true;
      for (size_t k = anchor + 1; k <= end && close; ++k)
        close =
            distance_to_segment(points[k], points[anchor], points[end + 1]) <= kRelaxCompactCells;
      if (!close) break;
      ++end;
    }
    // points[anchor] -> points[end] skips anchor + 1 .. end - 1; a single step is the path itself.
    if (end > anchor + 1 && !motion.segment_keeps_clearance(points[anchor], points[end]))
      end = anchor + 1;
    out.push_back(points[end]);
    anchor = end;
  }
  return out;
}

}  // namespace

std::vector<Point2> relax_path(const GridMap& map, const std::vector<Point2>& path,
                               const RelaxOptions& options, double min_clearance_cells,
                               PlanningBudget* budget) {
  if (path.size() < 3) return path;
  // Cost plays no part in the checks: relax follows the cost gradient instead (below).
  const MotionValidator motion(map, options.corner_policy, 0.0, min_clearance_cells);
  // The input compacted as the result is (a smoothed corner's samples, 0.25 cells apart, thinned
  // to about a cell), then no segment longer than kRelaxSpacingCells.
  std::vector<Point2> points = densify(compact(path, motion), kRelaxSpacingCells);
  if (points.size() < 3) return points;
  const std::vector<Point2> planned = points;
  const double cost_gain = map.has_costs() ? options.cost * options.cost_weight : 0.0;
  const size_t last = points.size() - 1;
  // A point whose neighbours and itself stayed put in the last iteration would get the same step
  // as then, already refused or below kRelaxSettledCells: only the others are visited.
  std::vector<uint8_t> moved(points.size(), 1), moving(points.size(), 0);
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    if (budget != nullptr && budget->poll() != StatusCode::kOk) return {};
    bool any_moved = false;
    std::fill(moving.begin(), moving.end(), 0);
    for (size_t i = 1; i < last; ++i) {
      // moving[i - 1] is this iteration's (Gauss-Seidel), moved[i + 1] the last one's.
      if (!(moved[i - 1] | moved[i] | moved[i + 1] | moving[i - 1])) continue;
      // Polled per point (the budget reads the clock every 256 polls), as pruning polls per check.
      if (budget != nullptr && budget->poll() != StatusCode::kOk) return {};
      const Point2& previous = points[i - 1];
      const Point2& next = points[i + 1];
      Point2 step = options.smoothness * (previous + next - 2.0 * points[i]) +
                    options.closeness * (planned[i] - points[i]);
      if (cost_gain > 0.0) step -= cost_gain * cost_gradient(map, points[i]);
      const double length = step.norm();
      if (!(length > kRelaxSettledCells)) continue;
      if (length > kRelaxMaxStepCells) step *= kRelaxMaxStepCells / length;
      for (int attempt = 0; attempt < 3; ++attempt, step /= 2.0) {
        const Point2 candidate = points[i] + step;
        if (motion.segment_keeps_clearance(previous, candidate) &&
            motion.segment_keeps_clearance(candidate, next)) {
          points[i] = candidate;
          moving[i] = 1;
          any_moved = true;
          break;
        }
      }
    }
    moved.swap(moving);
    if (!any_moved) break;
  }
  return compact(points, motion);
}

}  // namespace vnsba::core
