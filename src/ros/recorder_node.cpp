#include "variational_formation/ros/recorder_node.hpp"

#include <ros/callback_queue.h>

#include "variational_formation/ros/parameters.hpp"

namespace vf {

namespace {
constexpr uint32_t kQueue = 1000000;  // a whole run: nothing is dropped while the disk catches up
}

template <typename M>
void RecorderNode::subscribe(ros::NodeHandle& nh, const std::string& topic,
                             std::function<void(const M&)> count) {
  subs_.push_back(nh.subscribe(topic, kQueue, boost::function<void(const typename M::ConstPtr&)>(
                                                  [this, topic, count](const typename M::ConstPtr& m) {
                                                    try {
                                                      bag_.write(topic, ros::Time::now(), *m);
                                                      ++written_;
                                                      count(*m);
                                                    } catch (const std::exception& e) {
                                                      ROS_ERROR_THROTTLE(1.0, "recorder: %s", e.what());
                                                    }
                                                  }),
                               ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay()));
}

RecorderNode::RecorderNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
  const Scenario scenario = loadScenario(requiredParam<std::string>(pnh, "scenario"));
  path_ = requiredParam<std::string>(pnh, "bag");
  steps_ = scenario.steps;
  agents_ = scenario.agentCount();
  stateCount_.assign(static_cast<std::size_t>(agents_), 0);
  tfCount_.assign(static_cast<std::size_t>(agents_), 0);
  try {
    bag_.open(path_, rosbag::bagmode::Write);
  } catch (const std::exception& e) {
    throw InvalidInput("~bag: cannot write '" + path_ + "': " + e.what());
  }
  for (int i = 0; i < agents_; ++i) {
    subscribe<AgentState>(nh, "/formation/agent_" + std::to_string(i) + "/state",
                          [this, i](const AgentState&) { ++stateCount_[static_cast<std::size_t>(i)]; });
  }
  subscribe<FormationStatus>(nh, "/formation/status", [this](const FormationStatus&) { ++statusCount_; });
  subscribe<visualization_msgs::MarkerArray>(nh, "/formation/markers",
                                             [this](const visualization_msgs::MarkerArray&) { ++markerCount_; });
  subscribe<tf2_msgs::TFMessage>(nh, "/tf", [this](const tf2_msgs::TFMessage& m) {
    for (const auto& t : m.transforms) {
      const std::string prefix = "agent_";
      if (t.child_frame_id.rfind(prefix, 0) != 0) continue;
      try {
        const int i = std::stoi(t.child_frame_id.substr(prefix.size()));
        if (i >= 0 && i < agents_) ++tfCount_[static_cast<std::size_t>(i)];
      } catch (const std::exception&) {
      }
    }
  });
  ROS_INFO("recorder: writing %s (%d agents, %ld steps)", path_.c_str(), agents_, steps_);
}

bool RecorderNode::complete() const {
  if (steps_ == 0) return false;
  const long each = steps_ + 1;
  for (int i = 0; i < agents_; ++i) {
    if (stateCount_[static_cast<std::size_t>(i)] < each || tfCount_[static_cast<std::size_t>(i)] < each) return false;
  }
  return statusCount_ >= each && markerCount_ >= each;
}

void RecorderNode::run() {
  auto* queue = ros::getGlobalCallbackQueue();
  while (ros::ok() && !complete()) queue->callAvailable(ros::WallDuration(0.01));
  bag_.close();
  ROS_INFO("recorder: %s closed, %ld messages%s", path_.c_str(), written_,
           complete() ? " (every step of every stream)" : " (interrupted)");
}

}  // namespace vf
