#include "variational_formation_core/robots/robot_mode.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include "variational_formation_core/studies/delay_margin.hpp"
#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/robots/unicycle_command.hpp"
#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation_core/robots/point_robot.hpp"
#include "variational_formation_core/robots/robot_link.hpp"
#include "variational_formation_core/agents/timed_agent.hpp"
#include "variational_formation_core/robots/unicycle_robot.hpp"
#include "variational_formation_core/model/validation.hpp"

namespace vf {

RobotLagCheck checkRobotLag(const Scenario& scenario, double lag, double tickPeriod, RobotFeedback feedback,
                            const std::string& optionPrefix) {
  requireFiniteAtLeast(optionPrefix + "robot_lag", lag, 0.0, "s");
  requireFiniteAbove("tick period", tickPeriod, 0.0, "s");
  const double h = scenario.timeStep;
  RobotLagCheck check;
  check.lagPlusTick = lag + tickPeriod;
  // Only delays up to one past lag + tick matter: stop the scan there.
  const long needed = static_cast<long>(std::ceil(check.lagPlusTick / h)) + 1;
  const DelayMargin margin =
      predictDelayMargin(makeFormation(scenario), h, scenario.dampingGain, std::min(needed, 1000L));
  check.marginSteps = margin.margin;
  check.capped = margin.capped;
  check.marginSeconds = std::max(0L, margin.margin) * h;
  check.exceeded = !margin.capped && (margin.margin < 0 || check.lagPlusTick > check.marginSeconds);
  check.applies = feedback == RobotFeedback::Odometry;
  const std::string& o = optionPrefix;
  const std::string lagText = "robot lag " + formatRounded(lag) + " s plus one tick " + formatRounded(tickPeriod) +
                              " s = " + formatRounded(check.lagPlusTick) + " s";
  const std::string comparison =
      margin.capped ? lagText + " is within the delay margin (stable for every delay up to it at kappa " +
                          formatRounded(scenario.dampingGain) + ", h " + formatRounded(h) + ")"
                    : lagText + (check.exceeded ? " exceeds" : " is within") + " the delay margin D* = " +
                          std::to_string(margin.margin) + " steps = " + formatRounded(check.marginSeconds) +
                          " s (kappa " + formatRounded(scenario.dampingGain) + ", h " + formatRounded(h) + ")";
  if (!check.applies) {
    check.info = o + "feedback integrated: " + comparison + "; the margin bounds " + o + "robot_lag only with " + o +
                 "feedback odometry: here the formation runs on the agents' own states and the lag reaches it "
                 "only through the " + o + "correction_time pull (doc/robots.md)";
  } else if (check.exceeded) {
    check.warning = o + "feedback odometry, " + o + "robot_lag: " + comparison +
                    ": the robots may never form the shape; a larger kappa or a smaller h widens the margin, or "
                    "use " + o + "feedback integrated (doc/robots.md)";
  } else {
    check.info = o + "feedback odometry, " + o + "robot_lag: " + comparison;
  }
  return check;
}

void correctedPosition(const std::vector<double>& integrated, const std::vector<double>& measured,
                       double timeStep, double correctionTime, std::vector<double>& out) {
  requireFiniteAbove("time_step", timeStep, 0.0, "s");
  requireFiniteAtLeast("correction_time", correctionTime, 0.0, "s");
  if (integrated.size() != measured.size()) {
    throw InvalidInput("measured position: expected " + std::to_string(integrated.size()) + " values, got " +
                       std::to_string(measured.size()));
  }
  // Exact discretisation of q' = (measured - q) / Tc over one tick.
  const double gain = correctionTime > 0.0 ? -std::expm1(-timeStep / correctionTime) : 1.0;
  out.resize(integrated.size());
  for (std::size_t a = 0; a < integrated.size(); ++a) {
    if (!std::isfinite(integrated[a]) || !std::isfinite(measured[a])) {
      throw InvalidInput("measured position: must be finite, got " + formatNumber(measured[a]));
    }
    out[a] = integrated[a] + gain * (measured[a] - integrated[a]);
  }
}

namespace {

// One simulated robot: PointRobot, or UnicycleRobot whose hand point is the agent's point.
class LoopRobot {
 public:
  LoopRobot(const RobotLoopSettings& s, const std::vector<double>& start, double heading, std::uint64_t seed)
      : handOffset_(s.handOffset), initialHeading_(heading) {
    if (s.kinematics == RobotKinematics::Holonomic) {
      PointRobotSettings p;
      p.lag = s.lag;
      p.maxSpeed = s.maxSpeed;
      p.maxAcceleration = s.maxAcceleration;
      p.odometryNoise = s.odometryNoise;
      point_ = std::make_unique<PointRobot>(p, start, seed);
    } else {
      if (start.size() != 2) throw InvalidInput("kinematics: unicycle robots need a planar scenario");
      UnicycleRobotSettings u;
      u.lag = s.lag;
      u.maxSpeed = s.maxSpeed;
      u.maxTurnRate = s.maxTurnRate;
      u.odometryNoise = s.odometryNoise;
      u.headingNoise = s.headingNoise;
      unicycle_ = std::make_unique<UnicycleRobot>(u, axleFromHandPoint(start.data(), heading, s.handOffset), seed);
    }
  }
  // Odometry, as the agent's link takes it.
  void measure(RobotLink& link) {
    if (point_) link.measurePoint(point_->measuredPosition());
    else link.measurePose(unicycle_->measuredPose());
  }
  std::vector<double> truePoint() const {
    if (point_) return point_->position();
    std::vector<double> p(2);
    handPoint(unicycle_->pose(), handOffset_, p.data());
    return p;
  }
  void command(const RobotLink::Command& c) {
    if (point_) point_->setCommand(std::vector<double>(c.linear, c.linear + point_->dimension()));
    else unicycle_->setCommand(c.linear[0], c.linear[1], c.angular);
  }
  void advance(double dt) {
    if (point_) point_->advance(dt);
    else unicycle_->advance(dt);
  }
  double headingChange() const {
    if (!unicycle_) return 0.0;
    const double d = unicycle_->pose().heading - initialHeading_;
    return std::abs(std::atan2(std::sin(d), std::cos(d)));
  }

 private:
  double handOffset_;
  double initialHeading_;
  std::unique_ptr<PointRobot> point_;
  std::unique_ptr<UnicycleRobot> unicycle_;
};

// max over all pairs of | |p_i - p_j| - |q*_i - q*_j| | [m].
double pairError(const Scenario& s, const std::vector<std::vector<double>>& points) {
  double worst = 0.0;
  const int n = s.agentCount();
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      double a = 0.0;
      for (int c = 0; c < s.dimension; ++c) {
        const double d = points[i][c] - points[j][c];
        a += d * d;
      }
      const double desired = (s.desiredPositions.col(i) - s.desiredPositions.col(j)).norm();
      worst = std::max(worst, std::abs(std::sqrt(a) - desired));
    }
  }
  return worst;
}

}  // namespace

RobotLoopResult runRobotLoop(const Scenario& scenario, const RobotLoopSettings& s) {
  if (scenario.steps < 1) throw InvalidInput("steps: the closed loop needs a bounded run, got 0");
  requireFiniteAtLeast("correction_time", s.correctionTime, 0.0, "s");
  requireFiniteAbove("tolerance", s.tolerance, 0.0, "m");
  const int n = scenario.agentCount();
  const double h = scenario.timeStep;
  RobotLinkSettings linkSettings;
  linkSettings.kinematics = s.kinematics;
  linkSettings.feedback = s.feedback;
  linkSettings.hand.handOffset = s.handOffset;
  linkSettings.hand.maxSpeed = s.maxSpeed;
  linkSettings.hand.maxTurnRate = s.maxTurnRate;
  linkSettings.lag = s.lag;
  linkSettings.correctionTime = s.correctionTime;
  linkSettings.trackingGain = s.trackingGain;
  std::vector<TimedAgent> agents;
  std::vector<LoopRobot> robots;
  std::vector<RobotLink> links;
  for (int i = 0; i < n; ++i) {
    agents.emplace_back(scenario, i, 1.0);
    links.emplace_back(linkSettings, scenario.dimension, h);
    const std::vector<double> start(scenario.initialPositions.col(i).data(),
                                    scenario.initialPositions.col(i).data() + scenario.dimension);
    const double heading = scenario.initialHeadings.empty() ? drawInitialHeading(s.headingSeed, i)
                                                            : initialHeading(scenario, i);
    robots.emplace_back(s, start, heading, s.seed + static_cast<std::uint64_t>(i));
  }
  RobotLoopResult result;
  const long lastSecond = std::max(0L, scenario.steps - static_cast<long>(std::lround(1.0 / h)));
  std::vector<double> start;
  for (long k = 0; k < scenario.steps; ++k) {
    const double now = k * h;
    // Every agent's newest state, as published at the previous tick.
    for (int i = 0; i < n; ++i) {
      for (int j : agents[i].neighbourIds()) {
        agents[i].receive(j, agents[j].step(), agents[j].position(), agents[j].previousPosition(), now);
      }
    }
    for (int i = 0; i < n; ++i) {
      robots[i].measure(links[i]);
      links[i].startPosition(agents[i].position(), start);
      agents[i].setMeasuredPosition(start);
      agents[i].tick(now);
      robots[i].command(links[i].command(agents[i].commandedVelocity(), agents[i].previousPosition()));
    }
    std::vector<std::vector<double>> points;
    for (LoopRobot& robot : robots) {
      robot.advance(h);
      points.push_back(robot.truePoint());
    }
    const double error = pairError(scenario, points);
    if (error <= s.tolerance) {
      if (result.convergedStep < 0) result.convergedStep = k + 1;
    } else {
      result.convergedStep = -1;
    }
    if (k >= lastSecond) result.maxErrorLastSecond = std::max(result.maxErrorLastSecond, error);
    result.finalError = error;
  }
  for (const RobotLink& link : links) result.saturatedCommands += link.saturatedCommands();
  result.convergedTime = result.convergedStep >= 0 ? result.convergedStep * h : -1.0;
  for (const LoopRobot& robot : robots) result.maxHeadingChange = std::max(result.maxHeadingChange, robot.headingChange());
  return result;
}

}  // namespace vf
