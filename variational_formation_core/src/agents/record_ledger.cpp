#include "variational_formation_core/agents/record_ledger.hpp"

#include <algorithm>
#include <cstring>
#include <string>

#include "variational_formation_core/common/invalid_input.hpp"

namespace vf {

bool StepSet::holds(long step) const { return step < next || ahead.count(step) > 0; }

bool StepSet::add(long step) {
  if (holds(step)) return false;
  ahead.insert(step);
  while (!ahead.empty() && *ahead.begin() == next) {
    ahead.erase(ahead.begin());
    ++next;
  }
  return true;
}

RecordLedger::RecordLedger(int agents, long keep) : agents_(static_cast<std::size_t>(std::max(agents, 0))), keep_(keep) {
  if (agents < 1) throw InvalidInput("record ledger: needs at least one agent, got " + std::to_string(agents));
  if (keep < 1) throw InvalidInput("record ledger: keep must be >= 1, got " + std::to_string(keep));
  for (AgentLedger& a : agents_) a.kept.resize(static_cast<std::size_t>(keep));
}

RecordLedger::Arrival RecordLedger::addState(int agent, long step, const std::vector<double>& position,
                                             const std::vector<double>& previousPosition) {
  if (agent < 0 || agent >= agentCount()) {
    throw InvalidInput("record ledger: agent " + std::to_string(agent) + " is not in 0.." + std::to_string(agentCount() - 1));
  }
  if (step < 0) throw InvalidInput("record ledger: step must be >= 0, got " + std::to_string(step));
  if (position.empty() || position.size() > 3 || previousPosition.size() != position.size()) {
    throw InvalidInput("record ledger: a state needs position and previous_position of 1 to 3 values each, got " +
                       std::to_string(position.size()) + " and " + std::to_string(previousPosition.size()));
  }
  // Unused coordinates stay 0.0 in both copies; memcmp compares bit patterns (0.0 and -0.0 differ).
  Coordinates c{};
  std::copy(position.begin(), position.end(), c.begin());
  std::copy(previousPosition.begin(), previousPosition.end(), c.begin() + 3);
  AgentLedger& a = agents_[static_cast<std::size_t>(agent)];
  Kept& slot = a.kept[static_cast<std::size_t>(((step % keep_) + keep_) % keep_)];
  if (a.steps.add(step)) {
    // The slot holds step - m keep for some m >= 1, or nothing; a step older than the kept ones
    // would overwrite a newer one, so it is not kept.
    if (step > a.newest - keep_) {
      slot.step = step;
      slot.coordinates = c;
      a.newest = std::max(a.newest, step);
    }
    return Arrival::New;
  }
  if (slot.step != step) return Arrival::Unchecked;
  return std::memcmp(slot.coordinates.data(), c.data(), sizeof(Coordinates)) == 0 ? Arrival::Identical : Arrival::Differs;
}

}  // namespace vf
