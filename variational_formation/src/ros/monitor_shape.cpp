// The run's shape as the monitor reports it (MonitorNode, monitor_node.hpp): the findings of the
// newest completed step, and at the end the verdict `simulate` gives too (core shapeOutcome):
// the desired shape, its mirror image, folded, still settling, or not converged.
#include <cmath>

#include "variational_formation/ros/monitor_node.hpp"

namespace vf {

void MonitorNode::noteShape(const FormationSnapshot& s) {
  lastShape_ = s.shape;
  lastPositions_ = s.positions;
  lastScale_ = s.scale;
}

ShapeOutcome MonitorNode::agentsVerdict() const {
  ShapeFindings f = lastShape_;
  // Beyond 50 agents the shape error skips steps (FormationSnapshot::shape): the verdict needs it.
  if (std::isnan(f.shapeError) && lastPositions_.size() > 0) {
    f.shapeError = measure().formation().shapeError(lastPositions_, lastScale_);
  }
  const ShapeOutcome o = shapeOutcome(f, congruentSince_, scenario_.mirrorAllowed, scenario_.timeStep);
  const std::string blocked = blockedBy();
  return blocked.empty() ? o : blockedShapeOutcome(o, blocked);
}

ShapeOutcome MonitorNode::shapeVerdict() const {
  // Robot mode: converged means the robots are in shape too (doc/robots.md).
  if (!robots_) return agentsVerdict();
  return robotModeOutcome(agentsVerdict(), robots_->outcome(scenario_.timeStep), scenario_.timeStep);
}

}  // namespace vf
