#include "variational_formation_core/agents/agent_neighbourhood.hpp"

#include <cmath>
#include <memory>
#include <string>

#include "variational_formation_core/common/invalid_input.hpp"

namespace vf {

AgentNeighbourhood::AgentNeighbourhood(const Scenario& scenario, int id, std::shared_ptr<const Formation> shared)
    : model_(shared ? std::move(shared) : std::make_shared<const Formation>(makeFormation(scenario))), id_(id) {
  const int n = model_.formation().agentCount();
  if (n != scenario.agentCount() || model_.formation().dimension() != scenario.dimension) {
    throw InvalidInput("formation: " + std::to_string(n) + " agents in " + std::to_string(model_.formation().dimension()) +
                       " dimensions for a scenario of " + std::to_string(scenario.agentCount()) + " in " +
                       std::to_string(scenario.dimension));
  }
  const Formation& formation = model_.formation();
  if (id < 0 || id >= n) {
    throw InvalidInput("id: must be an agent id 0.." + std::to_string(n - 1) + ", got " + std::to_string(id));
  }
  const int d = formation.dimension();
  q0_.assign(scenario.initialPositions.col(id).data(), scenario.initialPositions.col(id).data() + d);
  v0_.assign(scenario.initialVelocities.col(id).data(), scenario.initialVelocities.col(id).data() + d);
  for (const Neighbour& nb : formation.neighbours(id)) neighbourIds_.push_back(nb.agent);
  motion_ = motionParameters(formation, id);
}

AgentNeighbourhood::StateCheck AgentNeighbourhood::check(long sender, const std::vector<double>& position,
                                                         const std::vector<double>& previousPosition) const {
  bool isNeighbour = false;
  for (int j : neighbourIds_) isNeighbour = isNeighbour || j == sender;
  if (!isNeighbour) return StateCheck::UnknownSender;
  const std::size_t d = static_cast<std::size_t>(dimension());
  if (position.size() != d || previousPosition.size() != d) return StateCheck::WrongDimension;
  for (std::size_t a = 0; a < d; ++a) {
    if (!std::isfinite(position[a]) || !std::isfinite(previousPosition[a])) return StateCheck::NonFinite;
  }
  return StateCheck::Usable;
}

}  // namespace vf
