#include "variational_formation_core/robots/robot_shape_watch.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation_core/robots/robot_link.hpp"

namespace vf {

namespace {

std::string robotList(const std::vector<int>& ids) {
  std::string out = ids.size() == 1 ? "robot_" : "robots ";
  for (std::size_t k = 0; k < ids.size(); ++k) out += (k ? ", " : "") + std::to_string(ids[k]);
  return out;
}

// The verdict's order: a worse one decides a robot-mode run (the shapes with every edge right tie).
int rank(ShapeVerdict v) {
  return v == ShapeVerdict::DesiredShape ? 2 : v == ShapeVerdict::NotConverged ? 0 : 1;
}

}  // namespace

RobotShapeWatch::RobotShapeWatch(const Scenario& scenario, const RobotShapeSettings& settings)
    : formation_(makeFormation(scenario)),
      settings_(settings),
      dimension_(scenario.dimension),
      lastStep_(scenario.steps),
      mirrorAllowed_(scenario.mirrorAllowed),
      odometry_(static_cast<std::size_t>(scenario.agentCount())),
      congruence_(settings.tolerance, std::numeric_limits<double>::infinity()),
      points_(Positions::Zero(scenario.dimension, scenario.agentCount())) {
  requireFiniteAbove("robots_window", settings.window, 0.0, "s");
  requireFiniteAbove("silent_after", settings.silentAfter, 0.0, "s");
  requireFiniteAbove("tolerance", settings.tolerance, 0.0, "");
  if (settings.kinematics == RobotKinematics::Unicycle) {
    requireFiniteAbove("hand_offset", settings.handOffset, 0.0, "m");
    if (dimension_ != 2) {
      throw InvalidInput("kinematics: unicycle robots drive on the plane; the scenario is " +
                         std::to_string(dimension_) + "D");
    }
  }
}

void RobotShapeWatch::addOdometry(int id, double t, double x, double y, double z, double qx, double qy, double qz,
                                  double qw) {
  if (id < 0 || id >= static_cast<int>(odometry_.size())) {
    throw InvalidInput("robot_" + std::to_string(id) + ": no such robot (the scenario has " +
                       std::to_string(odometry_.size()) + ")");
  }
  std::vector<double> point(static_cast<std::size_t>(dimension_));
  try {
    if (!std::isfinite(t)) throw InvalidInput("odometry: time must be finite, got " + formatNumber(t));
    pointFromOdometry(settings_.kinematics, settings_.handOffset, dimension_, x, y, z, qx, qy, qz, qw, point.data());
  } catch (const InvalidInput& e) {
    throw InvalidInput("robot_" + std::to_string(id) + ": " + e.what());
  }
  auto& samples = odometry_[static_cast<std::size_t>(id)];
  samples.emplace_back(t, std::move(point));
  // Keep the newest window: older samples no longer count in the average.
  while (samples.front().first < t - settings_.window) samples.pop_front();
}

std::vector<int> RobotShapeWatch::unheard() const {
  std::vector<int> ids;
  for (std::size_t i = 0; i < odometry_.size(); ++i) {
    if (odometry_[i].empty()) ids.push_back(static_cast<int>(i));
  }
  return ids;
}

std::vector<int> RobotShapeWatch::silent(double now) const {
  std::vector<int> ids;
  for (std::size_t i = 0; i < odometry_.size(); ++i) {
    if (!odometry_[i].empty() && now - odometry_[i].back().first > settings_.silentAfter) {
      ids.push_back(static_cast<int>(i));
    }
  }
  return ids;
}

const RobotShapeStep& RobotShapeWatch::observe(long step, double now, double scale) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  RobotShapeStep& r = last_;
  r.findings = ShapeFindings{};
  r.findings.shapeError = r.findings.maxEdgeError = nan;
  const std::vector<int> never = unheard(), quiet = silent(now);
  r.measured = never.empty() && quiet.empty();
  r.unmeasured.clear();
  if (!never.empty()) {
    r.unmeasured = "no odometry from " + robotList(never);
  } else if (!quiet.empty()) {
    double longest = 0.0;
    for (int i : quiet) longest = std::max(longest, now - odometry_[static_cast<std::size_t>(i)].back().first);
    char text[64];
    std::snprintf(text, sizeof text, " silent for %s%.1f s", quiet.size() > 1 ? "up to " : "", longest);
    r.unmeasured = robotList(quiet) + text;
  }
  if (!r.measured) {
    r.inShapeSince = -1;
    return r;
  }
  for (std::size_t i = 0; i < odometry_.size(); ++i) {
    Eigen::VectorXd sum = Eigen::VectorXd::Zero(dimension_);
    for (const auto& sample : odometry_[i]) sum += Eigen::Map<const Eigen::VectorXd>(sample.second.data(), dimension_);
    points_.col(static_cast<Eigen::Index>(i)) = sum / static_cast<double>(odometry_[i].size());
  }
  scale_ = scale;
  const Velocities still = Velocities::Zero(points_.rows(), points_.cols());
  const bool inShape = congruence_.check(formation_, points_, still, scale);
  const bool withShapeError = shapeErrorMeasuredAt(step, formation_.agentCount(), lastStep_);
  r.findings = findShape(formation_, points_, still, scale, inShape, settings_.tolerance,
                         std::numeric_limits<double>::infinity(), withShapeError);
  if (!inShape) {
    r.inShapeSince = -1;
  } else if (r.inShapeSince < 0) {
    r.inShapeSince = step;
  }
  return r;
}

ShapeOutcome RobotShapeWatch::outcome(double timeStep) const {
  if (!last_.measured) {
    ShapeOutcome o;
    o.findings = last_.findings;
    o.line = "not converged (the robots: " + (last_.unmeasured.empty() ? "never measured" : last_.unmeasured) + ")";
    return o;
  }
  ShapeFindings f = last_.findings;
  if (std::isnan(f.shapeError)) f.shapeError = formation_.shapeError(points_, scale_);  // skipped at this step
  ShapeOutcome o = shapeOutcome(f, last_.inShapeSince, mirrorAllowed_, timeStep);
  char text[200];
  // Their velocities are taken as zero (at rest): a robots' shape with every edge right is folded or mirrored.
  switch (o.verdict) {
    case ShapeVerdict::MirrorImage:
      std::snprintf(text, sizeof text,
                    "not converged: the mirror image of the desired shape (the robots, from odometry, from step %ld; "
                    "mirror: forbidden)", last_.inShapeSince);
      break;
    case ShapeVerdict::Folded:
      std::snprintf(text, sizeof text, "not converged: folded (the robots, from odometry: every edge within tolerance "
                    "but not every pair; shape error %.3g m)", f.shapeError);
      break;
    case ShapeVerdict::NotConverged:
      std::snprintf(text, sizeof text,
                    "not converged (the robots, from odometry: max distance error %.3g m, shape error %.3g m)",
                    f.maxEdgeError, f.shapeError);
      break;
    case ShapeVerdict::DesiredShape:
    case ShapeVerdict::StillSettling:
      return o;
  }
  o.line = text;
  return o;
}

ShapeOutcome robotModeOutcome(const ShapeOutcome& agents, const ShapeOutcome& robots, double timeStep) {
  if (robots.verdict == ShapeVerdict::Folded && agents.verdict == ShapeVerdict::DesiredShape) {
    // The robots follow the agents, which are in shape: robots with every edge right but not every
    // pair have not caught up yet (their speeds are not measured), they are not folded.
    ShapeOutcome o = robots;
    o.verdict = ShapeVerdict::StillSettling;
    char text[200];
    std::snprintf(text, sizeof text,
                  "not converged: still settling at the last step (the robots, from odometry, behind the agents, "
                  "which are in the desired shape: shape error %.3g m)",
                  robots.findings.shapeError);
    o.line = text;
    return o;
  }
  if (rank(robots.verdict) < rank(agents.verdict)) return robots;
  if (agents.verdict != ShapeVerdict::DesiredShape) return agents;
  // Both in the desired shape: the run converged when the later of the two did.
  ShapeOutcome o = agents;
  o.convergedStep = std::max(agents.convergedStep, robots.convergedStep);
  char text[240];
  std::snprintf(text, sizeof text,
                "converged to the desired shape at step %ld (t = %.3f s)%s; the robots (odometry) from step %ld, "
                "the agents from step %ld",
                o.convergedStep, o.convergedStep * timeStep,
                agents.findings.mirrored ? ", its mirror image (mirror: allowed)" : "", robots.convergedStep,
                agents.convergedStep);
  o.line = text;
  return o;
}

}  // namespace vf
