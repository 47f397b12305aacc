#include "variational_formation/ros/timed_agent_node.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/Twist.h>
#include <ros/callback_queue.h>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation_core/model/validation.hpp"
#include "variational_formation/ros/parameters.hpp"
#include "variational_formation/ros/formation_subscriptions.hpp"
#include "variational_formation/ros/foreign_formations.hpp"
#include "variational_formation/ros/frames.hpp"
#include "variational_formation/ros/liveness.hpp"
#include "variational_formation/ros/participant_names.hpp"
#include "variational_formation/ros/recalled.hpp"

namespace vf {

namespace {
constexpr double kReportEvery = 5.0;  // seconds between "waiting for ..." lines
constexpr double kHoldReportEvery = 2.0;
}  // namespace

TimedAgentNode::TimedAgentNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) : nh_(nh), diagnostics_(nh, pnh) {
  const int id = requiredParam<int>(pnh, "id");
  const std::string path = requiredParam<std::string>(pnh, "scenario");
  rate_ = optionalParam(pnh, "real_time_factor", 0.0);
  requireFiniteAbove("~real_time_factor (timed mode: the tick period is h / rate)", rate_, 0.0, "");
  monitor_ = participantName(nh, optionalParam<std::string>(pnh, "monitor", "monitor"));
  LinkFaultSettings faults;
  faults.delay = optionalParam(pnh, "delay", 0.0);
  faults.jitter = optionalParam(pnh, "jitter", 0.0);
  faults.loss = optionalParam(pnh, "loss", 0.0);
  try {
    validateLinkFaults(faults);
  } catch (const InvalidInput& e) {
    throw InvalidInput(std::string("~") + e.what());  // name the parameter
  }
  const int seed = optionalParam(pnh, "seed", id);
  if (seed < 0) throw InvalidInput("~seed: must be >= 0, got " + std::to_string(seed));
  const double maxAge = optionalParam(pnh, "max_age", 0.5);
  requireFiniteAbove("~max_age", maxAge, 0.0, "s");
  robot_ = optionalParam(pnh, "robot", false);
  const Scenario scenario = loadScenario(path);
  validateRealTimeFactor(rate_, scenario.timeStep, "~real_time_factor");
  agent_ = std::make_unique<TimedAgent>(scenario, id, maxAge);
  faults_ = std::make_unique<LinkFaults<Received>>(faults, static_cast<std::uint64_t>(seed));
  h_ = scenario.timeStep;
  name_ = "agent_" + std::to_string(id);
  const std::string ns = framePrefix(nh);
  frame_ = ns + name_;
  statePub_ = nh.advertise<AgentState>(name_ + "/state", 100, /*latch=*/true);
  posePub_ = nh.advertise<geometry_msgs::PoseStamped>(name_ + "/pose", 10);
  worldFrame_ = worldFrame(pnh);
  if (robot_) setUpRobot(nh, pnh, scenario, id);
  if (scenario.safety) setUpSafety(pnh, scenario);
  // With safety on every agent may come near: the filter hears them all (doc/robots.md "Safety").
  std::vector<int> heard = agent_->neighbourIds();
  if (agent_->safety()) {
    heard.clear();
    for (int j = 0; j < scenario.agentCount(); ++j) {
      if (j != id) heard.push_back(j);
    }
  }
  for (int j : heard) owners_[j] = agentNodeName(nh, j);
  subscribeToFormation(
      nh, heard, 100,
      [this](int j, const ros::MessageEvent<AgentState const>& e) { onNeighbourState(j, e); },
      [this](const ros::MessageEvent<RunProgress const>& e) { onProgress(e); }, subs_, progressSub_);
  commandSub_ = nh.subscribe<variational_formation_msgs::FormationCommands>(
      "command", 10,
      boost::function<void(const ros::MessageEvent<variational_formation_msgs::FormationCommands const>&)>(
          [this](const ros::MessageEvent<variational_formation_msgs::FormationCommands const>& e) { onCommands(e); }));
  recallServer_ = nh.advertiseService(name_ + "/recall", &TimedAgentNode::onRecall, this);
  // The server starts from ~kappa: the scenario's (an earlier value would be another run's).
  pnh.setParam("kappa", scenario.dampingGain);
  reconfigure_ = std::make_unique<dynamic_reconfigure::Server<variational_formation::TimedAgentConfig>>(pnh);
  reconfigure_->setCallback(
      [this](variational_formation::TimedAgentConfig& config, uint32_t level) { onReconfigure(config, level); });
  // The formation's kappa: the monitor's server in its namespace (MonitorNode::setUpParameters).
  formationParametersSub_ = nh.subscribe<dynamic_reconfigure::Config>(
      ros::names::append(ros::names::parentNamespace(monitor_), "parameter_updates"), 1,
      boost::function<void(const ros::MessageEvent<dynamic_reconfigure::Config const>&)>(
          [this](const ros::MessageEvent<dynamic_reconfigure::Config const>& e) { onFormationParameters(e); }));
  diagnostics_.setHardwareID(frame_);
  diagnostics_.add("timed agent", this, &TimedAgentNode::diagnose);
  for (const std::string& w : scenario.warnings) ROS_WARN("%s: %s", name_.c_str(), w.c_str());
  ROS_INFO("%s: timed mode, scenario '%s' (%s), %d neighbours, kappa %g, h %g, tick %g s, delay %g s, jitter %g s, "
           "loss %g, seed %d, max_age %g s%s, monitor %s",
           name_.c_str(), scenario.name.c_str(), path.c_str(), static_cast<int>(agent_->neighbourIds().size()),
           scenario.dampingGain, h_, h_ / rate_, faults.delay, faults.jitter, faults.loss, seed, maxAge,
           robot_ ? (", robot mode (" + std::string(kinematicsName(link_->settings().kinematics)) + ", " +
                     feedbackName(link_->settings().feedback) + " feedback, odom " + odomSub_.getTopic() + ")")
                        .c_str()
                  : "",
           monitor_.c_str());
}

void TimedAgentNode::drop(const std::string& why) {
  ++dropped_;
  ROS_WARN_THROTTLE(1.0, "%s: dropped %s; %ld dropped so far", name_.c_str(), why.c_str(), dropped_);
}

void TimedAgentNode::onNeighbourState(int neighbour, const ros::MessageEvent<AgentState const>& event) {
  if (!fromOwner(event, owners_.at(neighbour))) {
    drop("a state on agent_" + std::to_string(neighbour) + "'s topic from " + event.getPublisherName() +
         ", which does not own it");
    return;
  }
  const AgentState& msg = *event.getConstMessage();
  // The id check is the core's (UnknownSender); the faults act on what the network delivered.
  faults_->offer({static_cast<int>(msg.id) == neighbour ? neighbour : -1, msg}, now());
}

void TimedAgentNode::setUpSafety(const ros::NodeHandle& pnh, const Scenario& scenario) {
  // Robot mode: the link saturates cmd_vel at ~max_speed, so that bounds the robots when the
  // scenario gives no safety.max_speed (doc/robots.md "Safety"); timed mode needs the scenario's.
  const double robotSpeed = robot_ ? link_->settings().hand.maxSpeed : std::numeric_limits<double>::quiet_NaN();
  const bool unicycle = robot_ && link_->settings().kinematics == RobotKinematics::Unicycle;
  const double handOffset = unicycle ? link_->settings().hand.handOffset : 0.0;
  agent_->enableSafety(scenario, timedSafetySpeed(*scenario.safety, robotSpeed), handOffset);
  // Other formations' agents too, as last heard, widened by age x max speed (doc/maths.md §10, avoid).
  foreign_ = ForeignFormations::watch(nh_, avoidParameter(pnh), scenario.dimension);
  if (foreign_) agent_->avoid(foreign_->agents());
  const SafetySettings& s = agent_->safety()->settings();
  ROS_INFO("%s: safety filter on: r %g m (%s), sensing radius %g m, gamma %g, max speed %g m/s (%s); every "
           "agent's state is heard, and r widens by age x max speed",
           name_.c_str(), s.radius, unicycle ? "with 2 x hand_offset" : "the scenario's", s.sensingRadius, s.gamma,
           s.maxSpeed, std::isfinite(scenario.safety->maxSpeed) ? "the scenario's" : "the robot link's ~max_speed");
}

double TimedAgentNode::sentAt(const AgentState& state) const {
  // The stamp is ROS time: on the wall clock unless a simulator sets it; then the receive time.
  if (ros::Time::isSimTime() || state.header.stamp.isZero()) return std::numeric_limits<double>::quiet_NaN();
  return std::min(state.header.stamp.toSec(), now());
}

void TimedAgentNode::onProgress(const ros::MessageEvent<RunProgress const>& event) {
  if (!fromOwner(event, monitor_)) {
    drop("a progress message from " + event.getPublisherName() + ", which is not the monitor " + monitor_);
    return;
  }
  const RunProgress& p = *event.getConstMessage();
  if (p.state == RunProgress::FINISHED || p.state == RunProgress::FAILED) {
    if (exitStatus_ < 0) {
      ROS_INFO("%s: the run is over at step %ld (%s); %ld ticks held, %ld neighbour states lost (injected), %ld "
               "outdated or refused; idle until shut down",
               name_.c_str(), agent_->step(),
               p.state == RunProgress::FINISHED ? "finished" : ("failed: " + p.reason).c_str(), agent_->heldTicks(),
               faults_->lost(), agent_->dropped());
    }
    exitStatus_ = p.state == RunProgress::FINISHED ? 0 : 1;
    running_ = false;
    if (robot_) cmdVelPub_.publish(geometry_msgs::Twist());
  } else if (!running_ && exitStatus_ < 0 && p.state == RunProgress::RUNNING && p.allowed_step >= 1) {
    // Start by identity, as in lockstep; afterwards the flow-control window is ignored.
    running_ = true;
    ROS_INFO("%s: the monitor started the run; ticking every %g s from step %ld", name_.c_str(), h_ / rate_,
             agent_->step());
  }
}

void TimedAgentNode::onCommands(const ros::MessageEvent<variational_formation_msgs::FormationCommands const>& event) {
  const auto& list = event.getConstMessage()->commands;
  if (!fromOwner(event, monitor_)) {
    drop("a command list from " + event.getPublisherName() + ", which is not the monitor " + monitor_);
  } else if (list.size() != commandsSeen_ && !list.empty()) {
    try {
      agent_->setCommand(commandOf(list.back()));
      commandsSeen_ = list.size();
      ROS_INFO("%s: command %zu from the next tick (step %ld on)", name_.c_str(), list.size(), agent_->step() + 1);
    } catch (const InvalidInput& e) {
      drop(std::string("a command: ") + e.what());
    }
  }
}

void TimedAgentNode::onTick() {
  diagnostics_.update();  // rate-limited by the updater itself (~diagnostic_period, 1 s)
  const double t = now();
  for (Received& r : faults_->takeDue(t)) {
    const AgentState& s = r.state;
    try {
      const auto receipt = agent_->receive(r.sender, s.step, s.position, s.previous_position, t, sentAt(s));
      if (receipt == TimedAgent::Receipt::Accepted) {
        newest_[r.sender] = s;
      } else if (receipt != TimedAgent::Receipt::Outdated) {
        drop("a state on agent_" + std::to_string(s.id) + "'s topic (step " + std::to_string(s.step) +
             "): " + TimedAgent::describe(receipt));
      }
    } catch (const std::exception& e) {
      drop(std::string("a state: ") + e.what());
    }
  }
  if (robot_ && !link_->measured()) {
    ROS_WARN_THROTTLE(kReportEvery, "%s: holding: no odometry on %s yet%s", name_.c_str(), odomSub_.getTopic().c_str(),
                      odomFrames_->refusedNote().c_str());
    return;
  }
  if (!running_ && exitStatus_ < 0 && secondsSince(lastPublishAt_) > 0.25 * agent_->maxAge()) {
    // Before the start, keep the neighbours' copy of our first state fresh: else they would
    // find it older than max_age at their first tick and hold once.
    publish();
  }
  if (!running_ || agent_->finished()) return;
  if (robot_) {
    link_->startPosition(agent_->position(), start_);
    agent_->setMeasuredPosition(start_);
  }
  const TimedAgent::TickResult result = agent_->tick(t);
  if (result.holding) {
    std::string who;
    for (const auto& s : result.stale) {
      char age[64];
      if (s.heard) {
        std::snprintf(age, sizeof age, "silent for %.2f s", s.age);
      } else {
        std::snprintf(age, sizeof age, "never heard");
      }
      who += (who.empty() ? "" : ", ") + std::string("agent_") + std::to_string(s.id) + " " + age;
    }
    ROS_WARN_THROTTLE(kHoldReportEvery, "%s: holding at step %ld: %s (max_age %g s)", name_.c_str(), result.step,
                      who.c_str(), agent_->maxAge());
  }
  for (double x : agent_->position()) {
    if (!std::isfinite(x)) {
      ROS_ERROR("%s: step %ld is not finite (the formation diverged); stopping", name_.c_str(), agent_->step());
      running_ = false;
      AgentState msg;
      msg.id = static_cast<uint32_t>(agent_->id());
      msg.step = agent_->step();
      msg.failure = "step " + std::to_string(agent_->step()) + " is not finite (the run diverged)";
      msg.position.assign(agent_->position().size(), 0.0);
      msg.previous_position = msg.position;
      statePub_.publish(msg);
      return;
    }
  }
  publish();
  if (robot_) sendCommand();
}

void TimedAgentNode::reportWaiting() {
  if (running_ || exitStatus_ >= 0 || agent_->finished()) return;
  if (secondsSince(lastReportAt_) < kReportEvery) return;
  ROS_INFO("%s: at step %ld, waiting for the monitor %s to start the run", name_.c_str(), agent_->step(),
           monitor_.c_str());
  lastReportAt_ = ros::WallTime::now();
}

void TimedAgentNode::recover() {
  const Recalled r = recallNewest(nh_, agent_->id(), agent_->neighbourIds(), monitor_);
  if (r.step <= 0) {
    ROS_INFO("%s: nobody holds a state of mine beyond step 0: starting from the scenario", name_.c_str());
    return;
  }
  try {
    agent_->restore(r.step, r.found.position);
    ROS_INFO("%s: recovered step %ld from %s; restarting from rest there", name_.c_str(), r.step, r.from.c_str());
  } catch (const std::exception& e) {
    ROS_WARN("%s: cannot restore from %s (%s): starting from the scenario", name_.c_str(), r.from.c_str(), e.what());
  }
}

bool TimedAgentNode::onRecall(RecallState::Request& request, RecallState::Response& response) {
  const auto it = newest_.find(static_cast<int>(request.id));
  response.held = it != newest_.end();
  if (response.held) {
    response.step = it->second.step;
    response.position = it->second.position;
    response.previous_position = it->second.previous_position;
  }
  return true;
}

int TimedAgentNode::run() {
  recover();
  publish();  // the first state (step 0, or the recovered one), latched
  lastReportAt_ = ros::WallTime::now();
  tickTimer_ = nh_.createWallTimer(ros::WallDuration(h_ / rate_), [this](const ros::WallTimerEvent&) { onTick(); });
  watchTimer_ = nh_.createWallTimer(ros::WallDuration(1.0), [this](const ros::WallTimerEvent&) { reportWaiting(); });
  while (ros::ok()) ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.1));
  ROS_INFO("%s: done at step %ld, %ld ticks held, %ld states dropped, %ld lost (injected), %ld outdated or refused",
           name_.c_str(), agent_->step(), agent_->heldTicks(), dropped_, faults_->lost(), agent_->dropped());
  return exitStatus_ < 0 ? 0 : exitStatus_;
}

}  // namespace vf
