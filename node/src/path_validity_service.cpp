#include "path_validity_service.hpp"

#include <spdlog/spdlog.h>

#include "action_traits.hpp"
#include "is_path_valid.hpp"

namespace vnsba::node {

namespace {

// A request whose path announces more poses than its bytes can hold is refused before decoding
// (announced_poses_problem), as such goals are: the list follows the path's std_msgs/Header, with
// nothing before the header (a goal has its 16-byte id there).
constexpr size_t kBytesBeforePathHeader = 0;

template <class Wire>
std::unique_ptr<ServiceServer<typename Wire::RequestType, typename Wire::ResponseType>> make_server(
    const NodeConfig& cfg, const MapInput& maps, RobotPoses& poses, const Robot& robot,
    const ParticipantWatch* vendors, std::mutex& mutex, std::condition_variable& cv) {
  using Server = ServiceServer<typename Wire::RequestType, typename Wire::ResponseType>;
  const std::string name = ros_topic_name(robot.cfg, cfg.topics.is_path_valid);
  auto server = std::make_unique<Server>(
      name, robot.cfg, vendors, mutex, cv,
      [&maps, &poses, &robot, name](Server& self, const ReplyAddress& from,
                                    typename Wire::Request&& request) {
        typename Wire::Response response;
        const std::shared_ptr<const ActiveMap> map = maps.current();
        const size_t poses_asked = request.path().poses().size();
        const std::string problem =
            answer_is_path_valid(request, map ? map->grid.get() : nullptr, poses.position_of(robot),
                                 robot.cfg, response);
        if (!problem.empty())
          spdlog::warn("{}: a path of {} poses not checked: {}", name, poses_asked, problem);
        else
          spdlog::debug("{}: a path of {} poses is {} ({} invalid)", name, poses_asked,
                        response.is_valid() ? "valid" : "invalid",
                        response.invalid_pose_indices().size());
        self.reply(from, response, "an is_path_valid reply");
      });
  server->refuse_before_decoding([](const RawSample& raw, WireMapping mapping) {
    return announced_poses_problem(raw, mapping, /*after_a_header=*/true, kBytesBeforePathHeader,
                                   "path.poses");
  });
  return server;
}

}  // namespace

PathValidityService::PathValidityService(const NodeConfig& config, const MapInput& maps,
                                         RobotPoses& poses)
    : cfg_(config), maps_(maps), poses_(poses) {}

PathValidityService::~PathValidityService() = default;

core::Status PathValidityService::add(NodeReaders& readers, const ParticipantWatch* vendors,
                                      const Robot& robot, Replier& replier) {
  core::Status created = core::Status::ok();
  auto make = [&](auto wire) {
    auto server = make_server<decltype(wire)>(cfg_, maps_, poses_, robot, vendors, replier.mutex(),
                                              replier.wake());
    created = readers.add_service(*server);
    replier.add_service(*server);
    servers_.push_back(std::move(server));
  };
  with_wire<IsPathValid>(cfg_.ros_distro, make);
  return created;
}

void PathValidityService::release() {
  servers_.clear();
}

}  // namespace vnsba::node
