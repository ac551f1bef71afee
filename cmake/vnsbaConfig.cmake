# find_package(vnsba): the planning library (vnsba::core, Eigen only) and the map files library
# (vnsba::maps: Moving AI, map_server, OctoMap), as installed by `cmake --install`.
include(CMakeFindDependencyMacro)
find_dependency(Eigen3 3.3 NO_MODULE)
find_dependency(octomap 1.9)
find_dependency(yaml-cpp)  # linked privately by the static vnsba::maps
include(${CMAKE_CURRENT_LIST_DIR}/vnsbaTargets.cmake)
