#include "variational_formation/ros/mujoco_world_node.hpp"

#include <cmath>

#include <nav_msgs/Odometry.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/JointState.h>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation_core/model/scenario.hpp"
#include "variational_formation/ros/output_files.hpp"
#include "variational_formation/ros/parameters.hpp"
#include "variational_formation/ros/frames.hpp"
#include "variational_formation/ros/markers.hpp"
#include "variational_formation/ros/world_contact.hpp"
#include "variational_formation/ros/world_markers.hpp"
#include "variational_formation/world/mjcf_model.hpp"

namespace vf {

namespace {

// The world's numbers from the private parameters present; the rest keep their defaults.
WorldSettings worldSettings(const ros::NodeHandle& pnh) {
  WorldSettings settings;
  settings.kinematics = parseWorldKinematics(optionalParam<std::string>(pnh, "kinematics", "holonomic"));
  // Spelled out (not worldParameterNames()) so that test/doc/test_docs.py sees each read;
  // setWorldParameter refuses a name the settings do not have.
  for (const char* name : {"time_step", "real_time_factor", "friction", "mass", "body_radius", "hand_offset",
                           "wheel_radius", "track", "max_wheel_torque", "max_wheel_speed", "wheel_gain",
                           "wheel_armature", "caster_friction", "max_force", "max_speed", "base_gain"}) {
    if (pnh.hasParam(name)) setWorldParameter(settings, name, requiredParam<double>(pnh, name));
  }
  validateWorldSettings(settings);
  return settings;
}

void setYaw(geometry_msgs::Quaternion& q, double heading) {
  q.z = std::sin(0.5 * heading);
  q.w = std::cos(0.5 * heading);
}

}  // namespace

MujocoWorldNode::MujocoWorldNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) : nh_(nh) {
  const std::string scenarioFile = requiredParam<std::string>(pnh, "scenario");
  const std::string model = optionalParam<std::string>(pnh, "model", "");
  const std::string odometry = optionalParam<std::string>(pnh, "odometry", "ground_truth");
  const int headingSeed = optionalParam(pnh, "heading_seed", 0);
  const double publishRate = optionalParam(pnh, "publish_rate", 100.0);
  const double markerRate = optionalParam(pnh, "marker_rate", 20.0);
  clock_ = optionalParam(pnh, "clock", false);
  cmdTimeout_ = optionalParam(pnh, "cmd_timeout", cmdTimeout_);
  worldFrame_ = worldFrame(pnh);
  WorldSettings settings;
  try {
    settings = worldSettings(pnh);
    requireFiniteAbove("publish_rate", publishRate, 0.0, "Hz");
    requireFiniteAtLeast("marker_rate", markerRate, 0.0, "Hz");
    requireFiniteAtLeast("cmd_timeout", cmdTimeout_, 0.0, "s");
    requireFiniteAtLeast("heading_seed", headingSeed, 0.0, "");
    if (odometry != "ground_truth" && odometry != "wheels") {
      throw InvalidInput("odometry: expected ground_truth or wheels, got '" + odometry + "'");
    }
    wheelOdometry_ = odometry == "wheels";
    if (wheelOdometry_ && settings.kinematics != WorldKinematics::Unicycle) {
      throw InvalidInput("odometry: wheels needs kinematics unicycle (a holonomic base has no wheels)");
    }
    if (settings.realTimeFactor == 0.0 && !clock_) {
      throw InvalidInput("real_time_factor: 0 (as fast as possible) needs clock true: agents on wall time cannot follow");
    }
  } catch (const InvalidInput& e) {
    throw InvalidInput(std::string("~") + e.what());  // the core names the parameter without '~'
  }
  const Scenario scenario = loadScenario(scenarioFile);
  const int count = scenario.agentCount();
  agentRadius_ = agentSphereRadius(makeFormation(scenario));
  if (model.empty()) {
    const std::vector<PlanarPose> starts = worldStartPoses(scenario, settings, static_cast<std::uint64_t>(headingSeed));
    world_ = std::make_unique<MujocoWorld>(buildWorldMjcf(settings, starts, worldObstacles(scenario)),
                                           "the scenario's world", count, settings);
  } else {
    world_ = MujocoWorld::fromFile(model, count, settings);
  }
  realTimeFactor_ = settings.realTimeFactor;
  publishPeriod_ = 1.0 / publishRate;
  markerPeriod_ = markerRate > 0.0 ? 1.0 / markerRate : -1.0;
  resultFile_ = outputPath(nh, optionalParam<std::string>(pnh, "result_file", ""));
  const std::string prefix = framePrefix(nh);
  robots_.resize(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    RobotIo& io = robots_[static_cast<std::size_t>(i)];
    const std::string ns = "robot_" + std::to_string(i);
    io.frame = prefix + ns + "/base_link";
    io.odom = nh.advertise<nav_msgs::Odometry>(ns + "/odom", 100);
    io.joints = nh.advertise<sensor_msgs::JointState>(ns + "/joint_states", 100);
    io.command = nh.subscribe<geometry_msgs::Twist>(
        ns + "/cmd_vel", 100, [this, i](const geometry_msgs::Twist::ConstPtr& m) { onCommand(i, m); },
        ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  }
  contactPub_ = pnh.advertise<variational_formation_msgs::WorldContact>("contacts", 100);
  if (markerPeriod_ > 0.0) markerPub_ = pnh.advertise<visualization_msgs::MarkerArray>("markers", 10);
  if (clock_) clockPub_ = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
  progressSub_ = nh.subscribe("progress", 10, &MujocoWorldNode::onProgress, this);
  diagnostics_.setHardwareID(prefix + "world");
  diagnostics_.add("MuJoCo world", this, &MujocoWorldNode::diagnose);
  ROS_INFO("%s: %d robots (%s) from %s, %s; odometry %s, %s, publishing at %g Hz, cmd_vel timeout %g s",
           ros::this_node::getName().c_str(), count, model.empty() ? "built" : model.c_str(),
           scenarioFile.c_str(), describeWorldSettings(settings).c_str(), odometry.c_str(),
           clock_ ? "publishing /clock" : "on wall time", publishRate, cmdTimeout_);
}

void MujocoWorldNode::onCommand(int robot, const geometry_msgs::Twist::ConstPtr& msg) {
  try {
    if (world_->setCommand(robot, msg->linear.x, msg->linear.y, msg->angular.z)) ++saturated_;
    RobotIo& io = robots_[static_cast<std::size_t>(robot)];
    io.lastCommand = world_->time();
    io.stopped = false;
  } catch (const InvalidInput& e) {
    ++malformed_;
    ROS_WARN_THROTTLE(1.0, "%s: robot_%d: dropped a cmd_vel: %s; %ld dropped so far",
                      ros::this_node::getName().c_str(), robot, e.what(), malformed_);
  }
}

void MujocoWorldNode::onProgress(const variational_formation_msgs::RunProgress::ConstPtr& msg) {
  if (msg->state != variational_formation_msgs::RunProgress::FINISHED &&
      msg->state != variational_formation_msgs::RunProgress::FAILED) {
    return;
  }
  runOver_ = true;
  appendResult();
}

ros::Time MujocoWorldNode::stamp() const {
  return clock_ ? ros::Time(world_->time()) : ros::Time::now();
}

void MujocoWorldNode::advance(double until) {
  const double halfStep = 0.5 * world_->settings().timeStep;
  while (world_->time() + halfStep < until) {
    world_->step();
    for (const ContactEvent& c : world_->newContacts()) {
      contactPub_.publish(worldContactMessage(c, stamp(), worldFrame_, world_->contacts().count()));
      ROS_WARN("%s: contact %ld at t = %.3f s: %s and %s, normal force %.3g N", ros::this_node::getName().c_str(),
               world_->contacts().count(), c.time, c.first.c_str(), c.second.c_str(), c.normalForce);
    }
  }
}

void MujocoWorldNode::publish() {
  const ros::Time now = stamp();
  if (clock_) {
    rosgraph_msgs::Clock clock;
    clock.clock = now;
    clockPub_.publish(clock);
  }
  std_msgs::Header header;
  header.stamp = now;
  header.frame_id = worldFrame_;
  for (int i = 0; i < world_->robotCount(); ++i) {
    RobotIo& io = robots_[static_cast<std::size_t>(i)];
    // A robot whose agent stopped talking stops, as robot_sim does (simulated time).
    if (!io.stopped && cmdTimeout_ > 0.0 && world_->time() - io.lastCommand > cmdTimeout_) {
      world_->setCommand(i, 0.0, 0.0, 0.0);
      io.stopped = true;
      ROS_WARN("%s: robot_%d: no cmd_vel for %g s: stopping", ros::this_node::getName().c_str(), i, cmdTimeout_);
    }
    const PlanarPose truth = world_->pose(i);
    const PlanarPose measured = wheelOdometry_ ? world_->wheelOdometry(i) : truth;
    const BaseTwist twist = world_->twist(i);
    nav_msgs::Odometry odom;
    odom.header = header;
    odom.child_frame_id = io.frame;
    odom.pose.pose.position.x = measured.x;
    odom.pose.pose.position.y = measured.y;
    setYaw(odom.pose.pose.orientation, measured.heading);
    odom.twist.twist.linear.x = twist.linearX;  // in base_link
    odom.twist.twist.linear.y = twist.linearY;
    odom.twist.twist.angular.z = twist.angularZ;
    io.odom.publish(odom);
    geometry_msgs::TransformStamped tf = frameAt(header, io.frame, {truth.x, truth.y, 0.0});
    setYaw(tf.transform.rotation, truth.heading);
    tf_.sendTransform(tf);
    const JointReadings joints = world_->joints(i);
    sensor_msgs::JointState state;
    state.header.stamp = now;
    for (const std::string& name : joints.names) state.name.push_back("robot_" + std::to_string(i) + "_" + name);
    state.position = joints.position;
    state.velocity = joints.velocity;
    state.effort = joints.effort;
    io.joints.publish(state);
  }
  // The bodies, headings and contacts for rviz and render_bag.py, at their own (lower) rate.
  if (markerPeriod_ > 0.0 && world_->time() >= nextMarkers_) {
    markerPub_.publish(makeWorldMarkers(*world_, header, agentRadius_));
    nextMarkers_ = world_->time() + markerPeriod_ - 0.5 * world_->settings().timeStep;
  }
}

void MujocoWorldNode::run() {
  const ros::WallTime start = ros::WallTime::now();
  const double simStart = world_->time();
  double next = simStart;
  while (ros::ok()) {
    ros::spinOnce();
    next += publishPeriod_;
    advance(next);
    publish();
    const double wall = (ros::WallTime::now() - start).toSec();
    achievedFactor_ = wall > 0.0 ? (world_->time() - simStart) / wall : 0.0;
    diagnostics_.update();
    if (realTimeFactor_ > 0.0) {
      const ros::WallTime due = start + ros::WallDuration((world_->time() - simStart) / realTimeFactor_);
      const ros::WallTime now = ros::WallTime::now();
      if (due > now) (due - now).sleep();
    }
  }
  if (runOver_) appendResult();
}

void MujocoWorldNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const ContactLog& c = world_->contacts();
  status.summary(c.count() > 0 ? diagnostic_msgs::DiagnosticStatus::WARN : diagnostic_msgs::DiagnosticStatus::OK,
                 c.count() > 0 ? std::to_string(c.count()) + " contacts" : "no contacts");
  status.add("robots", world_->robotCount());
  status.add("kinematics", kinematicsName(world_->settings().kinematics));
  status.add("simulated time [s]", world_->time());
  status.add("real-time factor, wanted", realTimeFactor_);
  status.add("real-time factor, achieved", achievedFactor_);
  status.add("contacts", c.count());
  status.add("touching now", c.active());
  status.add("first contact", c.first() ? "t = " + formatNumber(c.first()->time) + " s, " + c.first()->first +
                                              " and " + c.first()->second
                                        : std::string("none"));
  status.add("max interpenetration [m]", c.maxPenetration());
  status.add("max normal force [N]", c.maxNormalForce());
  status.add("cmd_vel saturated", saturated_);
  status.add("cmd_vel dropped", malformed_);
}

void MujocoWorldNode::appendResult() {
  if (resultFile_.empty() || resultWritten_) return;
  // The monitor writes the file before it says the run is over; the world adds its lines.
  resultWritten_ = appendToResult(resultFile_, world_->contacts().resultLines()) != Appended::notYet;
}

}  // namespace vf
