#include "variational_formation_core/integrators/variational_update.hpp"

#include <cmath>

namespace vf {

// doc/maths.md §2 and §6: only e^{+-kappa h} appear, never e^{kappa t}.
VariationalCoefficients::VariationalCoefficients(double h, double kappa)
    : timeStep(h), dampingGain(kappa) {
  const double growth = std::exp(kappa * h);  // e^{kappa h}
  decay = std::exp(-kappa * h);
  positionGain = 1.0 + decay;
  gradientGain = 2.0 * h * h / (1.0 + growth);
  startGain = 2.0 * h / (1.0 + growth);
}

}  // namespace vf
