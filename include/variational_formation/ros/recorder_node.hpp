#pragma once

#include <string>
#include <vector>

#include <ros/ros.h>
#include <rosbag/bag.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/MarkerArray.h>

#include "variational_formation/AgentState.h"
#include "variational_formation/FormationStatus.h"
#include "variational_formation/core/scenario.hpp"

namespace vf {

using variational_formation::AgentState;
using variational_formation::FormationStatus;

/**
 * Records a run to a bag: every agent state, status, marker array and /tf message. Unlike
 * `rosbag record` (a fixed queue of 100 per topic, which drops messages when a fast run
 * outpaces it), it subscribes with queues that hold a whole run, and it knows the scenario, so
 * it closes the bag and exits once the last step of every stream is written.
 * Private parameters: ~scenario, ~bag (both required).
 */
class RecorderNode {
 public:
  RecorderNode(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  /// Until every stream's last step is written (or shutdown for unbounded runs).
  void run();

 private:
  template <typename M>
  void subscribe(ros::NodeHandle& nh, const std::string& topic, std::function<void(const M&)> count);
  bool complete() const;

  rosbag::Bag bag_;
  std::string path_;
  std::vector<ros::Subscriber> subs_;
  long steps_ = 0;
  int agents_ = 0;
  std::vector<long> stateCount_, tfCount_;
  long statusCount_ = 0, markerCount_ = 0, written_ = 0;
};

}  // namespace vf
