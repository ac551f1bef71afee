#include "vnsba/node/transforms.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "vnsba/node/config.hpp"

namespace vnsba::node {

namespace {

std::string frame_quoted(std::string_view frame) {
  return "'" + std::string(frame) + "'";
}

std::string seconds(double s) {
  std::ostringstream out;
  out.precision(3);
  out << std::fixed << s << " s";
  return out.str();
}

}  // namespace

TransformTree::SetResult TransformTree::set(std::string_view parent_frame,
                                            std::string_view child_frame,
                                            const Eigen::Vector3d& translation_m,
                                            const Eigen::Quaterniond& rotation, double stamp_s,
                                            bool is_static) {
  const std::string_view parent = without_leading_slash(parent_frame);
  const std::string_view child = without_leading_slash(child_frame);
  const std::string what =
      "transform " + frame_quoted(parent) + " -> " + frame_quoted(child) + ": ";
  auto refuse = [&](Refusal refusal, const std::string& why) {
    return SetResult{refusal, what + why};
  };
  if (parent.empty() || child.empty())
    return refuse(Refusal::kInvalid, "header.frame_id and child_frame_id must both be non-empty");
  if (parent == child) return refuse(Refusal::kInvalid, "a frame cannot be its own parent");
  if (!translation_m.allFinite() || !rotation.coeffs().allFinite() || !std::isfinite(stamp_s))
    return refuse(Refusal::kInvalid, "translation, rotation and stamp must be finite");
  if (rotation.norm() < 1e-9) return refuse(Refusal::kInvalid, "rotation is a zero quaternion");
  auto it = parent_of_.find(child);
  // A new frame past the limit is refused before any walk: a flood of new frames costs a
  // look-up each.
  if (it == parent_of_.end() && parent_of_.size() >= kMaxFrames)
    return refuse(Refusal::kTooManyFrames, "more than " + std::to_string(kMaxFrames) + " frames");
  // The parent's chain up to its root: a loop would make every lookup through it walk forever,
  // and the walk stops after kMaxDepth transforms.
  size_t depth = 1;  // transforms from the root down to `child`, this one included
  for (std::string_view frame = parent;; ++depth) {
    const auto up = parent_of_.find(frame);
    if (up == parent_of_.end()) break;
    if (up->second.parent == child)
      return refuse(Refusal::kLoop, "would close a loop (" + frame_quoted(child) +
                                        " is already an ancestor of " + frame_quoted(parent) + ")");
    if (depth >= kMaxDepth)
      return refuse(Refusal::kTooDeep, "would make a chain of more than " +
                                           std::to_string(kMaxDepth) +
                                           " transforms from the root frame (the limit)");
    frame = up->second.parent;
  }
  if (it == parent_of_.end()) it = parent_of_.emplace(std::string(child), Edge()).first;
  Edge& edge = it->second;
  edge.parent = std::string(parent);
  edge.child_in_parent = Eigen::Translation3d(translation_m) * rotation.normalized();
  edge.stamp_s = stamp_s;
  edge.is_static = is_static;
  return {};
}

size_t TransformTree::clear_dynamic() {
  size_t dropped = 0;
  for (auto it = parent_of_.begin(); it != parent_of_.end();) {
    if (it->second.is_static) {
      ++it;
    } else {
      it = parent_of_.erase(it);
      ++dropped;
    }
  }
  return dropped;
}

TransformTree::Lookup TransformTree::lookup(std::string_view target_frame,
                                            std::string_view source_frame, double now_s,
                                            double tolerance_s) const {
  const std::string_view target = without_leading_slash(target_frame);
  const std::string_view source = without_leading_slash(source_frame);
  Lookup result;
  if (target == source) {
    result.ok = true;
    return result;
  }
  const std::string what =
      "no transform from " + frame_quoted(target) + " to " + frame_quoted(source) + ": ";
  // Every walk stops after kMaxDepth transforms: set() keeps chains within it, but a frame
  // given a new parent carries its own subtree along, which can make a deeper one.
  const std::string too_deep = what + "the chain above " + frame_quoted(source) + " and " +
                               frame_quoted(target) + " holds more than " +
                               std::to_string(kMaxDepth) + " transforms (the limit)";
  std::vector<Ancestor> up_from_source;
  Chain chain;
  std::optional<std::string> problem = ancestors(source, too_deep, up_from_source);
  if (!problem) problem = join(target, source, up_from_source, what, too_deep, chain);
  if (!problem) problem = stamp_problem(chain.edges, target, source, now_s, tolerance_s);
  if (problem) {
    result.problem = std::move(*problem);
    return result;
  }
  result.source_in_target = chain.source_in_target;
  result.ok = true;
  return result;
}

// The source and every frame above it, each with the source's pose in it.
std::optional<std::string> TransformTree::ancestors(std::string_view source,
                                                    const std::string& too_deep,
                                                    std::vector<Ancestor>& up_from_source) const {
  up_from_source = {{source, Eigen::Isometry3d::Identity(), nullptr}};
  for (;;) {
    const auto it = parent_of_.find(up_from_source.back().frame);
    if (it == parent_of_.end()) return std::nullopt;
    if (up_from_source.size() > kMaxDepth) return too_deep;
    up_from_source.push_back({it->second.parent,
                              it->second.child_in_parent * up_from_source.back().source_in_frame,
                              &*it});
  }
}

// Walks up from the target until it meets a frame above the source: the edges of both walks up
// to that frame join the two.
std::optional<std::string> TransformTree::join(std::string_view target, std::string_view source,
                                               const std::vector<Ancestor>& up_from_source,
                                               const std::string& what, const std::string& too_deep,
                                               Chain& chain) const {
  Eigen::Isometry3d target_in_frame = Eigen::Isometry3d::Identity();
  std::string_view frame = target;
  for (;;) {
    const auto common = std::find_if(up_from_source.begin(), up_from_source.end(),
                                     [&](const Ancestor& step) { return step.frame == frame; });
    if (common != up_from_source.end()) {
      for (auto step = up_from_source.begin() + 1; step <= common; ++step)
        chain.edges.push_back(step->edge);
      chain.source_in_target = target_in_frame.inverse() * common->source_in_frame;
      return std::nullopt;
    }
    const auto it = parent_of_.find(frame);
    if (it == parent_of_.end()) {
      const std::string_view source_root = up_from_source.back().frame;
      if (parent_of_.empty()) return what + "no transform has been received";
      if (up_from_source.size() == 1)
        return what + "no transform with child frame " + frame_quoted(source) + " has been " +
               "received";
      return what + "the received transforms join " + frame_quoted(source) + " up to " +
             frame_quoted(source_root) + " and " + frame_quoted(target) + " up to " +
             frame_quoted(frame) + ", and none joins those two";
    }
    if (chain.edges.size() >= kMaxDepth) return too_deep;
    chain.edges.push_back(&*it);
    target_in_frame = it->second.child_in_parent * target_in_frame;
    frame = it->second.parent;
  }
}

// The newest dynamic transform on the chain must not be ahead of the clock, and the oldest
// decides staleness, as it would time out a tf2 lookup.
std::optional<std::string> TransformTree::stamp_problem(const std::vector<EdgeRef>& edges,
                                                        std::string_view target,
                                                        std::string_view source, double now_s,
                                                        double tolerance_s) {
  EdgeRef oldest = nullptr;
  EdgeRef newest = nullptr;
  for (const EdgeRef edge : edges) {
    if (edge->second.is_static) continue;
    if (oldest == nullptr || edge->second.stamp_s < oldest->second.stamp_s) oldest = edge;
    if (newest == nullptr || edge->second.stamp_s > newest->second.stamp_s) newest = edge;
  }
  const std::string transform =
      "transform from " + frame_quoted(target) + " to " + frame_quoted(source);
  if (newest != nullptr && newest->second.stamp_s - now_s > kMaxAheadS) {
    return transform + " is in the future: " + frame_quoted(newest->second.parent) + " -> " +
           frame_quoted(newest->first) + " is stamped " + seconds(newest->second.stamp_s) + ", " +
           seconds(newest->second.stamp_s - now_s) + " after the node's clock (" + seconds(now_s) +
           "; at most " + seconds(kMaxAheadS) +
           " ahead is taken, as tf2 does not extrapolate into the future)";
  }
  if (oldest != nullptr && now_s - oldest->second.stamp_s > tolerance_s) {
    return transform + " is stale: " + frame_quoted(oldest->second.parent) + " -> " +
           frame_quoted(oldest->first) + " is " + seconds(now_s - oldest->second.stamp_s) +
           " old (transform_tolerance " + seconds(tolerance_s) + ")";
  }
  return std::nullopt;
}

}  // namespace vnsba::node
