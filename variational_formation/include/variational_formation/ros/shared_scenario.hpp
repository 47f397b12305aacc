#pragma once
// Scenario files loaded once per process and content.

#include <memory>
#include <string>

#include "variational_formation_core/model/formation.hpp"
#include "variational_formation_core/model/scenario.hpp"

namespace vf {

/**
 * loadScenario(path), parsed and checked once per content in this process: the agents of one
 * nodelet manager all load the same file, and its rigidity test costs O(n^3) (0.05 s at 200
 * agents). A file that changed is loaded again; an error is thrown as loadScenario throws it.
 */
Scenario sharedScenario(const std::string& path);

/**
 * The same scenario, not copied: the agents of one manager hold this one object, and with it
 * one formation (sharedFormation), instead of n copies of O(n) each (doc/benchmarks.md).
 */
std::shared_ptr<const Scenario> sharedScenarioObject(const std::string& path);

/// makeFormation(*scenario), made once per object that sharedScenarioObject returned.
std::shared_ptr<const Formation> sharedFormation(const std::shared_ptr<const Scenario>& scenario);

}  // namespace vf
