#include "variational_formation_core/agents/run_tracker.hpp"

#include <cmath>

#include "variational_formation_core/safety/safety_stage.hpp"
#include "variational_formation_core/manoeuvres/commanded_frame.hpp"

namespace vf {

namespace {
const std::vector<int> kNone;
constexpr double kTolerance = 0.01;  // every pair within 1% of its desired distance
}  // namespace

RunTracker::RunTracker(const Scenario& scenario, const CommandSchedule& schedule)
    : scenario_(scenario),
      schedule_(schedule),
      congruence_(kTolerance, 0.1),  // the monitor's defaults (doc/maths.md §8)
      blocked_(scenario.safety ? scenario.safety->blockedAfter : 1.0, scenario.timeStep) {}

bool RunTracker::observe(const Integrator& integrator) {
  const long step = integrator.stepIndex();
  const Positions& q = integrator.positions();
  const double scale = integrator.commandedScale();
  const Formation& formation = integrator.formation();
  lastError_ = formation.maxDistanceError(q, scale);
  // An edge 1% past the tolerance fails the pair test for certain: skip its O(n^2) search then
  // (the congruence test itself is the monitor's, CongruenceTracker).
  bool plainlyOff = false;
  for (const Edge& e : formation.edges()) {
    const double error = std::abs((q.col(e.tail) - q.col(e.head)).norm() - scale * e.desiredDistance);
    if (error > 1.01 * kTolerance * scale * e.desiredDistance) {
      plainlyOff = true;
      break;
    }
  }
  bool congruent = false;
  if (!plainlyOff) {
    Velocities v = integrator.velocities();
    if (!schedule_.empty()) subtractCommandedMotion(schedule_.at(step > 0 ? step - 1 : 0), q, v);
    congruent = congruence_.check(formation, q, v, scale);
  }
  SafetyStage* safety = integrator.safety();
  if (!safety) return true;
  const ClosestPair pair = safety->closestPair(q, step);
  if (closestStep_ < 0 || pair.distance < closest_.distance) {
    closest_ = pair;
    closestStep_ = step;
  }
  // The half-spaces that bound in the step that produced q (none at step 0).
  const bool stepped = step > 0;
  if (stepped && !safety->bindingAgents().empty()) ++filterActiveSteps_;
  return !blocked_.update(step, lastError_, congruent, stepped ? safety->bindingAgents() : kNone,
                          stepped ? safety->bindingObstacles() : kNone);
}

}  // namespace vf
