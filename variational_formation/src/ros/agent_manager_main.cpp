// The agents' nodelet manager (formation.launch nodelet:=true, doc/distributed.md, "Nodelets"):
// a nodelet manager that loads its own agents at start. A respawned manager therefore brings
// every agent back by itself, with no `nodelet load` process and no bond per agent (bonds time
// out under load, and a respawned loader clashes with its old name). It is still an ordinary
// manager: `nodelet load TYPE <this manager>` (agent.launch manager:=NAME) adds more nodelets.
//
// Private parameters (doc/ros_api.md, "agent_manager"): ~agents (required), ~stagger, and
// ~scenario, ~real_time_factor, ~monitor, ~agent_manager passed on to every agent (AgentNode
// checks them); nodelet itself reads ~num_worker_threads.
#include <cmath>
#include <thread>
#include <string>
#include <vector>

#include <nodelet/loader.h>
#include <ros/ros.h>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation/ros/local_states.hpp"
#include "variational_formation/ros/node_main.hpp"
#include "variational_formation/ros/parameters.hpp"
#include "variational_formation/ros/sensing_hub.hpp"
#include "variational_formation/ros/state_batch.hpp"

namespace {

/// ~agents as text: a list in a string ("0 1 2"), or one id.
std::string agentList(const ros::NodeHandle& pnh) {
  XmlRpc::XmlRpcValue value;
  if (!pnh.getParam("agents", value)) throw vf::InvalidInput("~agents: required parameter missing");
  if (value.getType() == XmlRpc::XmlRpcValue::TypeInt) return std::to_string(static_cast<int>(value));
  if (value.getType() != XmlRpc::XmlRpcValue::TypeString) {
    throw vf::InvalidInput("~agents: expected agent ids separated by spaces, got a value of another type");
  }
  return static_cast<std::string>(value);
}

/// Sets agent `id`'s private parameters (after clearing what an earlier run left there).
void setAgentParameters(const ros::NodeHandle& nh, const ros::NodeHandle& pnh, int id) {
  const std::string ns = "agent_" + std::to_string(id);
  nh.deleteParam(ns);
  ros::NodeHandle agent(nh, ns);
  agent.setParam("id", id);
  agent.setParam("mode", std::string("lockstep"));
  for (const char* key : {"scenario", "real_time_factor", "monitor"}) {
    XmlRpc::XmlRpcValue value;
    if (pnh.getParam(key, value)) agent.setParam(key, value);
  }
  // The agents' states carry this manager's name as caller id; their neighbours may be in others.
  agent.setParam("agent_manager", ros::this_node::getName() + " " + vf::optionalParam<std::string>(pnh, "agent_manager", ""));
}

const char* const kUsage =
    "usage: rosrun variational_formation agent_manager [ROS remappings and _param:=value]\n"
    "A nodelet manager that loads its own agents (variational_formation/Agent) at start.\n"
    "Private parameters: ~agents (required: ids separated by spaces), ~scenario,\n"
    "~real_time_factor, ~monitor, ~agent_manager, ~stagger [s], ~num_worker_threads.\n"
    "Started by formation.launch nodelet:=true; see doc/distributed.md, \"Nodelets\".\n";

}  // namespace

int main(int argc, char** argv) {
  if (vf::printedUsage(argc, argv, kUsage)) return 0;
  ros::init(argc, argv, "manager");
  ros::NodeHandle nh, pnh("~");
  const std::string me = ros::this_node::getName();
  try {
    const std::vector<int> ids = vf::parseAgentIds(agentList(pnh), "~agents");
    const double stagger = vf::optionalParam(pnh, "stagger", 0.0);
    if (!(stagger >= 0.0 && std::isfinite(stagger))) throw vf::InvalidInput("~stagger: must be >= 0 seconds");
    // One message per step with all of its agents' states, for the monitor and the recorder.
    vf::StateBatch::start(pnh, ids);
    // Its agents hand their states to each other in this process (doc/distributed.md, "Local delivery").
    vf::LocalStates::start(nh, ids);
    struct StopBatch {
      ~StopBatch() {  // after the loader (declared below) unloaded the agents
        vf::SensingHub::stop();
        vf::StateBatch::stop();
        vf::LocalStates::stop();
      }
    } stopBatch;
    // The agents' callbacks run on this process's own threads, one per ~num_worker_threads (0:
    // one per core, as nodelet counts), not on nodelet's queue manager.
    const int threads = vf::optionalParam(pnh, "num_worker_threads", 0);
    if (threads < 0) throw vf::InvalidInput("~num_worker_threads: must be >= 0, got " + std::to_string(threads));
    vf::AgentThreads::start(threads > 0 ? threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency())),
                            ids.size());
    struct EndThreads {
      ~EndThreads() { vf::AgentThreads::stop(); }  // after the loader unloaded the agents
    } endThreads;
    nodelet::Loader loader(pnh);  // the load_nodelet, unload_nodelet and list services, on the global queue
    struct HaltThreads {
      ~HaltThreads() { vf::AgentThreads::local()->halt(); }  // before: no agent callback runs while unloading
    } haltThreads;
    ros::AsyncSpinner spinner(1);
    spinner.start();
    for (std::size_t k = 0; k < ids.size() && ros::ok(); ++k) {
      if (k > 0 && stagger > 0.0) ros::WallDuration(stagger).sleep();
      setAgentParameters(nh, pnh, ids[k]);
      const std::string name = nh.resolveName("agent_" + std::to_string(ids[k]));
      // A nodelet that cannot start has said why in its own FATAL line (the loader, for a
      // missing plugin, in an ERROR line): exit without a second line.
      if (!loader.load(name, "variational_formation/Agent", ros::M_string(), std::vector<std::string>())) return 2;
    }
    ROS_INFO("%s: %zu agents loaded; their states also go out batched on %s/states", me.c_str(), ids.size(),
             me.c_str());
    ros::waitForShutdown();
  } catch (const std::exception& e) {
    ROS_FATAL("%s: %s", me.c_str(), e.what());
    return 2;
  }
  return 0;
}
