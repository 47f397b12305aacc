#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation_core/model/spatial_grid.hpp"
#include "variational_formation_core/model/validation.hpp"

namespace vf {

namespace {

std::string metres(double x) { return formatNumber(x) + " m"; }

void validateObstacles(const Scenario& s) {
  for (std::size_t k = 0; k < s.obstacles.size(); ++k) {
    const Obstacle& o = s.obstacles[k];
    const std::string field = "obstacles[" + std::to_string(k) + "]";
    if (o.shape == Obstacle::Shape::Ball) {
      requireFiniteAtLeast(field + ".radius", o.radius, 0.0, "m");
      continue;
    }
    for (int a = 0; a < s.dimension; ++a) {
      if (!(o.min(a) <= o.max(a))) {
        throw InvalidInput(field + ".min: coordinate " + std::to_string(a) + " is " + formatNumber(o.min(a)) +
                           ", above max's " + formatNumber(o.max(a)) + " (a box needs min <= max)");
      }
    }
  }
}

}  // namespace

void validateSafety(Scenario& s) {
  if (!s.safety) {
    if (!s.obstacles.empty()) {
      throw InvalidInput("obstacles: need a safety: block (its radius r sets the clearance r/2 agents keep)");
    }
    return;
  }
  const SafetySettings& safety = *s.safety;
  requireFiniteAbove("safety.radius", safety.radius, 0.0, "m");
  if (!(safety.sensingRadius > safety.radius)) {
    throw InvalidInput("safety.sensing_radius: must be > safety.radius = " + metres(safety.radius) +
                       " (an agent must sense another before it is within r), got " + formatNumber(safety.sensingRadius));
  }
  if (!(safety.gamma > 0.0 && safety.gamma <= 1.0)) {
    throw InvalidInput("safety.gamma: must be in (0, 1] (the share of the gap to r a pair may close per step; 0 "
                       "would freeze every sensed pair), got " + formatNumber(safety.gamma));
  }
  if (safety.maxSpeed != std::numeric_limits<double>::infinity()) {  // +inf: not given
    requireFiniteAbove("safety.max_speed", safety.maxSpeed, 0.0, "m/s");
  }
  requireFiniteAbove("safety.blocked_after", safety.blockedAfter, 0.0, "s");
  validateObstacles(s);

  // The desired shape at its smallest commanded scale must keep every pair r apart.
  double smallest = 1.0;
  for (const ManoeuvreSegment& segment : s.manoeuvre) smallest = std::min(smallest, segment.command.scale);
  const ClosestPair desired = closestPair(s.desiredPositions, safety.sensingRadius);
  if (desired.first >= 0 && smallest * desired.distance < safety.radius) {
    throw InvalidInput("agents[" + std::to_string(desired.second) + "].desired_position: " +
                       metres(desired.distance) + " from agent " + std::to_string(desired.first) +
                       "'s" + (smallest < 1.0 ? " (" + metres(smallest * desired.distance) +
                                                    " at the manoeuvre's scale " + formatNumber(smallest) + ")"
                                              : std::string()) +
                       ", closer than safety.radius = " + metres(safety.radius) +
                       ": the filter would never let the formation take this shape");
  }
  const ClosestPair start = closestPair(s.initialPositions, safety.sensingRadius);
  if (start.first >= 0 && start.distance < safety.radius) {
    throw InvalidInput("agents[" + std::to_string(start.second) + "].initial_position: " + metres(start.distance) +
                       " from agent " + std::to_string(start.first) + "'s, closer than safety.radius = " +
                       metres(safety.radius) + " at the start");
  }
  const double clearance = 0.5 * safety.radius;
  for (int i = 0; i < s.agentCount(); ++i) {
    for (std::size_t k = 0; k < s.obstacles.size(); ++k) {
      double w[3];
      obstacleOffset(s.obstacles[k], s.dimension, s.initialPositions.col(i).data(), w);
      const double distance = std::sqrt(w[0] * w[0] + w[1] * w[1] + (s.dimension == 3 ? w[2] * w[2] : 0.0));
      if (distance < clearance) {
        throw InvalidInput("agents[" + std::to_string(i) + "].initial_position: " + metres(distance) +
                           " from obstacles[" + std::to_string(k) + "], closer than safety.radius / 2 = " +
                           metres(clearance) + " at the start");
      }
    }
  }
  // doc/maths.md §10: pairs beyond R state no constraint, so one step of each must not close the gap
  // R - r (without max_speed only the run's speeds bound it: doc/maths.md §10).
  const double reach = 2.0 * safety.maxSpeed * s.timeStep;
  if (std::isfinite(reach) && !(reach < safety.sensingRadius - safety.radius)) {
    s.warnings.push_back("safety.max_speed: two agents at " + formatNumber(safety.maxSpeed) + " m/s close " +
                         metres(reach) + " per step, more than sensing_radius - radius = " +
                         metres(safety.sensingRadius - safety.radius) +
                         ": a pair sensed too late is not guaranteed to stay apart");
  }
}

}  // namespace vf
