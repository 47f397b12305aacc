// An agent's recovery and the states it serves (AgentNode, agent_node.hpp; doc/distributed.md,
// "Crash recovery"): after a restart it asks who holds its newest state and resumes from it; it
// answers `~recall` (the newest state it holds of an agent) and `~history` (its own recent states
// or a neighbour's) for others that restart.
#include "variational_formation/ros/agent_node.hpp"

#include <memory>
#include <thread>

#include <ros/callback_queue_interface.h>

#include "variational_formation/ros/pacer.hpp"
#include "variational_formation/ros/liveness.hpp"
#include "variational_formation/ros/participant_names.hpp"
#include "variational_formation/ros/recalled.hpp"
#include "variational_formation/ros/service_call.hpp"

namespace vf {

AgentNode::Recovery AgentNode::askHolders() const {
  // With an own board every agent holds our newest state: one that used our last step may be
  // ahead of the neighbours and the monitor (doc/distributed.md, "Sensing").
  return recallNewest(nh_, agent().id(), sources(), monitor_);
}

void AgentNode::resume(const Recovery& r) {
  const long best = r.step;
  const RecallState::Response& found = r.found;
  const std::string& from = r.from;
  if (best <= 0) {
    ROS_INFO("%s: nobody holds a state of mine beyond step 0: starting from the scenario", name_.c_str());
    return;
  }
  try {
    protocol_->resume(best, found.position, found.previous_position);
    ROS_INFO("%s: recovered step %ld from %s; resuming", name_.c_str(), best, from.c_str());
  } catch (const std::exception& e) {
    ROS_WARN("%s: cannot resume from %s (%s): starting from the scenario", name_.c_str(), from.c_str(), e.what());
  }
}

void AgentNode::recallAgain() {
  ROS_WARN("%s: a neighbour is two steps past my step %ld, so it holds a newer state of mine than "
           "the one I resumed from; asking the holders again", name_.c_str(), agent().step());
  // Not on the agent's queue: the holders may be served by this process's other threads.
  const std::shared_ptr<bool> alive = alive_;
  ros::CallbackQueueInterface* queue = nh_.getCallbackQueue();
  std::thread([this, alive, queue, nh = nh_, id = agent().id(), holders = sources(), monitor = monitor_] {
    const Recovery r = recallNewest(nh, id, holders, monitor);
    queue->addCallback(boost::make_shared<QueuedCall>([this, alive, r] {
      if (!*alive) return;
      if (r.step > agent().step()) ROS_INFO("%s: %s holds my step %ld", name_.c_str(), r.from.c_str(), r.step);
      carryOut(protocol_->step(Protocol::Recalled{r.step, r.found.position, r.found.previous_position}));
    }), reinterpret_cast<uint64_t>(this));
  }).detach();
}

void AgentNode::askNeighbourHistories(const std::vector<int>& ids) {
  // Who holds neighbour j's recent states: j itself, and j's neighbours (the states of j they
  // accepted); not this agent, which has just started.
  std::vector<std::string> services;
  std::vector<RecallHistory> calls;
  std::vector<int> whose;
  for (int j : ids) {
    std::vector<int> holders{j};
    for (const Neighbour& k : formation_->neighbours(j)) {
      if (k.agent != agent().id()) holders.push_back(k.agent);
    }
    for (int k : holders) {
      services.push_back(agentNodeName(nh_, k) + "/history");
      calls.emplace_back();
      calls.back().request.id = j;
      whose.push_back(j);
    }
  }
  const std::shared_ptr<bool> alive = alive_;
  ros::CallbackQueueInterface* queue = nh_.getCallbackQueue();
  // Not on the agent's queue: the holders may be served by this process's other threads.
  std::thread([this, alive, queue, services, calls, whose]() mutable {
    const std::vector<bool> answered = callAllWithTimeout(services, calls, 2.0);
    auto histories = std::make_shared<Protocol::NeighbourHistories>();
    std::size_t holders = 0;
    for (std::size_t c = 0; c < calls.size(); ++c) {
      if (!answered[c]) continue;
      ++holders;
      for (const AgentState& s : calls[c].response.states) {
        // Only states of the agent asked about: a holder answers for that agent alone.
        if (static_cast<int>(s.id) == whose[c]) {
          histories->states.push_back({whose[c], boost::make_shared<const AgentState>(s)});
        }
      }
    }
    queue->addCallback(boost::make_shared<QueuedCall>([this, alive, histories, holders, asked = calls.size()] {
      if (!*alive) return;
      ROS_INFO("%s: %zu of %zu holders answered, with %zu states", name_.c_str(), holders, asked,
               histories->states.size());
      carryOut(protocol_->step(*histories));
    }), reinterpret_cast<uint64_t>(this));
  }).detach();
}

void AgentNode::monitorConnected() {
  if (!awaitMonitor_) return;
  awaitMonitor_ = false;
  if (progressHeld_) {
    ROS_INFO("%s: resumed; the monitor took %.3f s to connect to this manager's states, and the agent waited for it",
             name_.c_str(), secondsSince(awaitSince_));
    progressHeld_ = false;
    onProgress(heldProgress_);
  }
}

bool AgentNode::onRecall(RecallState::Request& request, RecallState::Response& response) {
  long step = -1;
  response.held = agent().neighbourState(static_cast<int>(request.id), step, response.position,
                                         response.previous_position);
  response.step = step;
  return true;
}

bool AgentNode::onHistory(RecallHistory::Request& request, RecallHistory::Response& response) {
  // Its own states, or those it holds of the neighbour request.id.
  if (const auto* held = protocol_->history(static_cast<int>(request.id))) {
    for (const AgentState::ConstPtr& state : *held) response.states.push_back(*state);
  }
  response.progress = protocol_->lastProgress();
  response.has_progress = protocol_->hasProgress();
  return true;
}

}  // namespace vf
