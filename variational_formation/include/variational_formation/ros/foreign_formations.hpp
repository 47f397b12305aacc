#pragma once

#include <memory>
#include <string>
#include <vector>

#include <ros/ros.h>

#include "variational_formation_core/safety/foreign_agents.hpp"

namespace vf {

/// The parameter `avoid` (doc/ros_api.md): the other formations whose agents a formation with
/// `safety:` keeps r from (doc/maths.md §10, "Other formations").
struct AvoidList {
  bool everyOther = true;               ///< "all": every other formation publishing agent states on the master
  std::vector<std::string> namespaces;  ///< otherwise only these, full names; empty: none
  bool none() const { return !everyOther && namespaces.empty(); }
  /// Whether the formation in namespace `formation` (full name) is avoided.
  bool avoids(const std::string& formation) const;
  /// "every other formation on the master", "none", or the list.
  std::string describe() const;
};

/**
 * Reads `avoid`, looked up from the private namespace upwards (searchParam, as formation.launch
 * sets it for the whole formation; default "all"): "all", "none", or formation namespaces
 * separated by spaces or commas, each the namespace of the agents' state topics or the group
 * that holds it (team_b stands for /team_b/formation), relative to the root.
 * @throws InvalidInput naming the parameter, the value and why.
 */
AvoidList avoidParameter(const ros::NodeHandle& pnh);

/**
 * The agents of other formations on this master, as last heard (core ForeignAgents), for the
 * formation in one namespace: one per namespace and process, shared by its agents and kept while
 * one holds it. A thread of its own reads the master's topic list every 2 s (ros::master::getTopics)
 * and subscribes to each `<ns>/agent_<i>/state` of type AgentState in another namespace that
 * `avoid` names; the states are taken on a callback queue and spinner of its own (never the
 * agents'), from a node of that namespace only, and held with their wall-clock receive time.
 */
class ForeignFormations {
 public:
  /// The watcher of nh's formation (nullptr with avoid none). @param dimension d of the formation.
  static std::shared_ptr<ForeignFormations> watch(const ros::NodeHandle& nh, const AvoidList& avoid, int dimension);
  virtual ~ForeignFormations() = default;
  /// What it has heard.
  virtual std::shared_ptr<const ForeignAgents> agents() const = 0;
};

}  // namespace vf
