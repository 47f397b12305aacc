#include "variational_formation_core/manoeuvres/manoeuvre_model.hpp"

#include <cmath>

namespace vf {

// doc/maths.md §9, the discrete forcing that makes the commanded rigid motion exact.
ManoeuvreGains manoeuvreGains(const Command& command, const VariationalCoefficients& c) {
  ManoeuvreGains g;
  const double h = c.timeStep;
  const double oneMinusDecay = -std::expm1(-c.dampingGain * h);  // 1 - e^{-kappa h}, accurately
  const double startShift = h * std::tanh(0.5 * c.dampingGain * h);  // h - 2h/(1 + e^{kappa h})
  for (int a = 0; a < 3; ++a) {
    g.translation[a] = oneMinusDecay * h * command.velocity(a);
    g.startTranslation[a] = startShift * command.velocity(a);
  }
  g.scaleSquared = command.scale * command.scale;
  const double rate = command.angularRate.norm();
  if (rate > 0.0) {
    g.rotates = true;
    const Vector3 axis = command.angularRate / rate;
    const double theta = h * rate;
    const double halfSine = std::sin(0.5 * theta);
    const double alpha = oneMinusDecay * std::sin(theta);
    const double beta = (1.0 + c.decay) * 2.0 * halfSine * halfSine;  // (1 + a)(1 - cos theta)
    const double k[3][3] = {{0.0, -axis.z(), axis.y()}, {axis.z(), 0.0, -axis.x()}, {-axis.y(), axis.x(), 0.0}};
    for (int r = 0; r < 3; ++r) {
      for (int col = 0; col < 3; ++col) {
        // K^2 = axis axis^T - I
        const double k2 = axis(r) * axis(col) - (r == col ? 1.0 : 0.0);
        g.rotation[r][col] = alpha * k[r][col] + beta * k2;
      }
    }
  }
  return g;
}

ManoeuvreGains nodeGains(const ManoeuvreGains& before, const ManoeuvreGains& after) {
  ManoeuvreGains g;
  for (int a = 0; a < 3; ++a) {
    g.translation[a] = 0.5 * (before.translation[a] + after.translation[a]);
    g.startTranslation[a] = 0.5 * (before.startTranslation[a] + after.startTranslation[a]);
    for (int b = 0; b < 3; ++b) g.rotation[a][b] = 0.5 * (before.rotation[a][b] + after.rotation[a][b]);
  }
  g.scaleSquared = 0.5 * (before.scaleSquared + after.scaleSquared);
  g.rotates = before.rotates || after.rotates;
  return g;
}

ManoeuvreModel::ManoeuvreModel(const VariationalCoefficients& coefficients, CommandSchedule schedule)
    : coefficients_(coefficients), schedule_(std::move(schedule)) {
  for (const auto& entry : schedule_.entries()) gains_.push_back(manoeuvreGains(entry.second, coefficients_));
}

void ManoeuvreModel::add(long step, const Command& command) {
  schedule_.add(step, command);
  gains_.push_back(manoeuvreGains(command, coefficients_));
}

void ManoeuvreModel::replaceFrom(long step, const Command& command) {
  schedule_.replaceFrom(step, command);
  gains_.resize(schedule_.entries().size() - 1);
  gains_.push_back(manoeuvreGains(command, coefficients_));
}

const ManoeuvreGains& ManoeuvreModel::intervalGains(long step) const {
  const long i = schedule_.entryIndex(step);
  return i < 0 ? zero_ : gains_[static_cast<std::size_t>(i)];
}

ManoeuvreGains ManoeuvreModel::updateGains(long step) const {
  if (step == 0) return intervalGains(0);
  const long before = schedule_.entryIndex(step - 1);
  const long after = schedule_.entryIndex(step);
  if (before == after) return intervalGains(step);
  return nodeGains(intervalGains(step - 1), intervalGains(step));
}

double ManoeuvreModel::scaleAt(long step) const { return schedule_.at(step > 0 ? step - 1 : 0).scale; }

}  // namespace vf
