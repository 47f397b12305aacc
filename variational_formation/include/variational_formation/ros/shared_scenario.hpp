#pragma once
// Scenario files loaded once per process and content.

#include <string>

#include "variational_formation_core/model/scenario.hpp"

namespace vf {

/**
 * loadScenario(path), parsed and checked once per content in this process: the agents of one
 * nodelet manager all load the same file, and its rigidity test costs O(n^3) (0.05 s at 200
 * agents). A file that changed is loaded again; an error is thrown as loadScenario throws it.
 */
Scenario sharedScenario(const std::string& path);

}  // namespace vf
