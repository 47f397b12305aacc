#pragma once

#include <string>
#include <vector>

namespace vf {

/**
 * The folders where a scenario name is looked up, in order: `<entry>/variational_formation/config`
 * (and `<entry>/config` for an entry that is the package itself) for each entry of
 * ROS_PACKAGE_PATH, as roslaunch's $(find) would; then, found from the running program's own
 * path, the share folder of the install space it lives in (<prefix>/share/variational_formation)
 * or the sources of the catkin workspace whose devel space it lives in
 * (<ws>/src/variational_formation), so that no ROS set-up is needed.
 */
std::vector<std::string> scenarioFolders();

/**
 * The scenario file meant by the --scenario of a tool, as the launch files read it: a path
 * that exists always wins; a bare name (no '/'), such as "hexagon" or "hexagon.yaml", is
 * `<name>.yaml` in the first of scenarioFolders() that has it; any other path is returned as it
 * is, for the loader to report. @throws InvalidInput naming the search places if a bare name
 * is found nowhere.
 */
std::string resolveScenario(const std::string& nameOrPath);

}  // namespace vf
