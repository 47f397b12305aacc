#include "variational_formation_core/agents/link_faults.hpp"

#include <algorithm>

#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation_core/common/standard_normal.hpp"

namespace vf {

void validateLinkFaults(const LinkFaultSettings& settings) {
  requireFiniteAtLeast("delay", settings.delay, 0.0, "s");
  requireFiniteAtLeast("jitter", settings.jitter, 0.0, "s");
  requireFiniteWithin("loss", settings.loss, 0.0, 1.0, "");
}

LinkFaultModel::LinkFaultModel(const LinkFaultSettings& settings, std::uint64_t seed)
    : settings_(settings), engine_(seed) {
  validateLinkFaults(settings_);
}

bool LinkFaultModel::transparent() const {
  return settings_.delay == 0.0 && settings_.jitter == 0.0 && settings_.loss == 0.0;
}

std::optional<double> LinkFaultModel::draw() {
  // u in [0, 1) < loss: never lost at loss = 0, always at loss = 1.
  const bool lost = uniformUnit(engine_) < settings_.loss;
  const double spread = 2.0 * uniformUnit(engine_) - 1.0;  // [-1, 1)
  if (lost) return std::nullopt;
  return std::max(0.0, settings_.delay + settings_.jitter * spread);
}

}  // namespace vf
