#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include <diagnostic_updater/diagnostic_updater.h>
#include <dynamic_reconfigure/Config.h>
#include <dynamic_reconfigure/server.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>

#include "variational_formation_msgs/AgentState.h"
#include "variational_formation_msgs/FormationCommands.h"
#include "variational_formation_msgs/RecallState.h"
#include "variational_formation_msgs/RunProgress.h"
#include "variational_formation/TimedAgentConfig.h"
#include "variational_formation_core/agents/link_faults.hpp"
#include "variational_formation_core/robots/robot_link.hpp"
#include "variational_formation_core/agents/timed_agent.hpp"
#include "variational_formation/ros/foreign_formations.hpp"
#include "variational_formation/ros/frame_gate.hpp"
#include "variational_formation/ros/frames.hpp"

namespace vf {

using variational_formation_msgs::AgentState;
using variational_formation_msgs::RecallState;
using variational_formation_msgs::RunProgress;

/**
 * ROS I/O of one agent in time-driven mode (doc/robots.md). A wall-clock timer of period h/rate
 * calls TimedAgent::tick with the newest neighbour states it holds; it never waits. Received
 * neighbour states (only from the node that owns them) go through LinkFaults (injected delay,
 * jitter, loss) before the agent sees them. All maths is TimedAgent's.
 *
 * It starts when the monitor's latched `progress` allows step 1 (as in lockstep) and ignores
 * the flow-control window afterwards. A respawned agent asks its neighbours and the monitor for
 * its newest state (`~recall`, as in lockstep) and restarts from it at rest.
 *
 * Robot mode (~robot true, doc/robots.md): the agent reads its robot's `odom` (nav_msgs/Odometry)
 * and sends it `cmd_vel` (Twist) and `setpoint` (PoseStamped), public topics in the robot's
 * namespace ~robot_namespace (default robot_<id>, relative, so remappable like any driver's). The
 * maths of the link (holonomic or unicycle hand point, odometry or integrated feedback) is
 * RobotLink's. It holds until the first odometry; refused odometry (NaN, a quaternion that is not
 * a rotation, a frame other than the world frame: FrameGate) is dropped, counted and warned about. At start it compares the robot's lag plus
 * one tick with the scenario's delay margin (checkRobotLag): a WARN if the lag exceeds it with
 * odometry feedback, else one INFO line (with integrated feedback the margin does not bound it).
 *
 * Safety (a scenario with `safety:`, doc/robots.md "Safety"): the agent subscribes to every
 * agent's state, not only its neighbours', and filters each step (TimedSafety), widening r by
 * the age of each state (from its stamp) times the max speed.
 *
 * Diagnostics on /diagnostics (diagnostic_updater, about 1 Hz): step rate, each neighbour's age,
 * accepted and dropped states, injected losses, held ticks; WARN while holding.
 *
 * dynamic_reconfigure (`rosrun dynamic_reconfigure dynparam set /formation/agent_0 kappa 6`): kappa,
 * starting from the scenario's; lockstep keeps it fixed, so that it stays bit for bit exact. It
 * also follows the formation's kappa, served by the monitor in its namespace (`dynparam set
 * /formation kappa 6`), from that server's latched parameter_updates. A value the scenario's
 * check refuses is warned about and the old kappa is kept and reported back.
 *
 * Topics, services and private parameters: doc/ros_api.md, "agent (timed mode)".
 */
class TimedAgentNode {
 public:
  /// @throws InvalidInput on a missing or bad parameter or scenario.
  TimedAgentNode(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  /// Spins until shutdown. @return 0, or 1 if the monitor said the run failed.
  int run();

 private:
  struct Received {
    int sender;
    AgentState state;
  };
  void onNeighbourState(int neighbour, const ros::MessageEvent<AgentState const>& event);
  void onProgress(const ros::MessageEvent<RunProgress const>& event);
  void onOdometry(const nav_msgs::Odometry& odom);
  /// The monitor's issued commands: the newest applies from the next tick.
  void onCommands(const ros::MessageEvent<variational_formation_msgs::FormationCommands const>& event);
  void onTick();
  void publish();
  void sendCommand();
  void setUpRobot(ros::NodeHandle& nh, ros::NodeHandle& pnh, const Scenario& scenario, int id);
  /// The safety filter (a scenario with `safety:`): its max speed and hand offset.
  void setUpSafety(const ros::NodeHandle& pnh, const Scenario& scenario);
  /// When a state was sent, on now()'s clock [s] (NaN: unknown, the receive time counts).
  double sentAt(const AgentState& state) const;
  void reportWaiting();
  void drop(const std::string& why);
  void recover();
  bool onRecall(RecallState::Request& request, RecallState::Response& response);
  double now() const { return ros::WallTime::now().toSec(); }
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);
  void onReconfigure(variational_formation::TimedAgentConfig& config, uint32_t level);
  /// The formation's parameters (the monitor's dynamic_reconfigure server): its kappa applies here.
  void onFormationParameters(const ros::MessageEvent<dynamic_reconfigure::Config const>& event);
  /// A new kappa [1/s] named `field`, from the next tick; refused with a WARN by core's check.
  /// @return the kappa in force.
  double applyDampingGain(double kappa, const std::string& field);

  ros::NodeHandle nh_;
  std::unique_ptr<TimedAgent> agent_;
  std::unique_ptr<LinkFaults<Received>> faults_;
  ros::Publisher statePub_, posePub_, setpointPub_, cmdVelPub_;
  std::vector<ros::Subscriber> subs_;
  std::map<int, std::string> owners_;  // full node names of the agents it hears (neighbours; all with safety)
  std::shared_ptr<ForeignFormations> foreign_;  // with safety and avoid: other formations' agents
  std::map<int, AgentState> newest_;          // each neighbour's newest accepted state, for ~recall
  ros::Subscriber progressSub_, odomSub_, commandSub_, formationParametersSub_;
  std::size_t commandsSeen_ = 0;
  ros::ServiceServer recallServer_;
  std::string monitor_;
  tf2_ros::TransformBroadcaster tf_;
  ros::WallTimer tickTimer_, watchTimer_;
  double rate_ = 0.0;
  double h_ = 0.0;
  bool robot_ = false;
  std::unique_ptr<RobotLink> link_;  // robot mode only
  std::vector<double> start_;         // the position the next tick starts from (robot mode)
  long badOdometry_ = 0;
  std::unique_ptr<FrameGate> odomFrames_;  // robot mode: odometry in another frame than worldFrame_
  RobotLagCheck lagCheck_;
  bool running_ = false;
  long dropped_ = 0;
  int exitStatus_ = -1;  // -1: running
  ros::WallTime lastReportAt_, lastPublishAt_;
  diagnostic_updater::Updater diagnostics_;
  long diagnosedStep_ = 0;
  double diagnosedAt_ = 0.0;
  std::unique_ptr<dynamic_reconfigure::Server<variational_formation::TimedAgentConfig>> reconfigure_;
  std::string name_, frame_, worldFrame_;
};

}  // namespace vf
