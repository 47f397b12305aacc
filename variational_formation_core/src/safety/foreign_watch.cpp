#include "variational_formation_core/safety/foreign_watch.hpp"

#include <sstream>
#include <utility>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"

namespace vf {

ForeignWatch::ForeignWatch(std::shared_ptr<const ForeignAgents> agents) : agents_(std::move(agents)) {
  if (!agents_) throw InvalidInput("foreign watch: no table of other formations' agents");
}

bool ForeignWatch::note(long step, long foreignConstraintsActive) {
  if (foreignConstraintsActive <= 0) return false;
  const bool first = steps_.empty();
  steps_.insert(step);
  return first;
}

const ClosestForeign& ForeignWatch::observe(long step, const Positions& q) {
  last_ = agents_->closest(q);
  if (last_.distance < closest_.distance) {
    closest_ = last_;
    closestStep_ = step;
  }
  return last_;
}

std::string ForeignWatch::resultLines() const {
  std::ostringstream out;
  out << "closest_foreign_approach: ";
  if (closestStep_ < 0) {
    out << "~\n";
  } else {
    out << "{distance: " << formatNumber(closest_.distance) << ", agents: [agent_" << closest_.agent << ", "
        << closest_.foreign << "], step: " << closestStep_ << "}\n";
  }
  out << "foreign_constraint_steps: " << constraintSteps() << "\n";
  return out.str();
}

}  // namespace vf
