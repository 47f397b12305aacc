// The formation's kappa (MonitorNode, monitor_node.hpp; doc/ros_api.md "monitor"): one
// dynamic_reconfigure server in the formation's namespace for every agent. The check is core's
// (refuseDampingGain); the timed agents apply what this server publishes, lockstep refuses.
#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation_core/model/validation.hpp"
#include "variational_formation/ros/monitor_node.hpp"

namespace vf {

void MonitorNode::setUpParameters(ros::NodeHandle& nh, bool timed) {
  kappa_ = scenario_.dampingGain;
  kappaFixed_ = !timed;
  kappaName_ = nh.resolveName("kappa");
  // The server starts from ~kappa on the parameter server: the scenario's, not an earlier run's.
  nh.setParam("kappa", kappa_);
  reconfigure_ = std::make_unique<dynamic_reconfigure::Server<variational_formation::FormationConfig>>(nh);
  reconfigure_->setCallback(
      [this](variational_formation::FormationConfig& config, uint32_t level) { onReconfigure(config, level); });
}

void MonitorNode::onReconfigure(variational_formation::FormationConfig& config, uint32_t) {
  if (config.kappa == kappa_) return;
  if (kappaFixed_) {
    ROS_WARN("monitor: %s: %s refused, kappa stays %g: lockstep agents keep the scenario's kappa, so that the run "
             "stays bit for bit equal to simulate (mode timed takes a new kappa during a run)",
             kappaName_.c_str(), formatNumber(config.kappa).c_str(), kappa_);
  } else if (const auto refusal = refuseDampingGain(scenario_.timeStep, config.kappa, kappa_, kappaName_)) {
    ROS_WARN("monitor: %s", refusal->c_str());
  } else {
    kappa_ = config.kappa;
    ROS_INFO("monitor: %s set to %g for every agent; each applies it from its next tick (completed step %ld)",
             kappaName_.c_str(), kappa_, completedStep());
  }
  config.kappa = kappa_;  // what the server keeps, reports back and publishes to the agents
}

}  // namespace vf
