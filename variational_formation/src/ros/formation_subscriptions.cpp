#include "variational_formation/ros/formation_subscriptions.hpp"



namespace vf {

void subscribeToFormation(
    ros::NodeHandle& nh, const std::vector<int>& neighbours, uint32_t stateQueue,
    const std::function<void(int, const ros::MessageEvent<variational_formation_msgs::AgentState const>&)>& onState,
    const std::function<void(const ros::MessageEvent<variational_formation_msgs::RunProgress const>&)>& onProgress,
    std::vector<ros::Subscriber>& states, ros::Subscriber& progress) {
  using variational_formation_msgs::AgentState;
  using variational_formation_msgs::RunProgress;
  for (int j : neighbours) {
    states.push_back(nh.subscribe<AgentState>(
        "agent_" + std::to_string(j) + "/state", stateQueue,
        boost::function<void(const ros::MessageEvent<AgentState const>&)>(
            [onState, j](const ros::MessageEvent<AgentState const>& e) { onState(j, e); }),
        ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay()));
  }
  progress = nh.subscribe<RunProgress>("progress", 10,
                                       boost::function<void(const ros::MessageEvent<RunProgress const>&)>(onProgress),
                                       ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
}

Command commandOf(const variational_formation_msgs::FormationCommand& m) {
  Command c;
  c.velocity = {m.velocity.x, m.velocity.y, m.velocity.z};
  c.angularRate = {m.angular_rate.x, m.angular_rate.y, m.angular_rate.z};
  c.scale = m.scale;
  return c;
}

}  // namespace vf
