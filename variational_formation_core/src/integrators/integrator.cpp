#include "variational_formation_core/integrators/integrator.hpp"

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/integrators/explicit_integrators.hpp"
#include "variational_formation_core/model/validation.hpp"
#include "variational_formation_core/integrators/variational_integrator.hpp"

namespace vf {

Method parseMethod(const std::string& text, const std::string& field) {
  if (text == "vi") return Method::Variational;
  if (text == "euler") return Method::ExplicitEuler;
  if (text == "rk4") return Method::RungeKutta4;
  throw InvalidInput(field + ": unknown method '" + text + "' (expected vi, euler or rk4)");
}

StartMethod parseStartMethod(const std::string& text, const std::string& field) {
  if (text == "variational") return StartMethod::Variational;
  if (text == "paper") return StartMethod::Paper;
  throw InvalidInput(field + ": unknown start '" + text + "' (expected variational or paper)");
}

std::unique_ptr<Integrator> makeIntegrator(Method method, const Formation& formation,
                                           const Positions& q0, const Velocities& v0,
                                           double timeStep, double dampingGain,
                                           StartMethod start) {
  const int d = formation.dimension();
  const int n = formation.agentCount();
  if (q0.rows() != d || q0.cols() != n) throw InvalidInput("initial_position: wrong size");
  if (v0.rows() != d || v0.cols() != n) throw InvalidInput("initial_velocity: wrong size");
  if (!q0.allFinite()) throw InvalidInput("initial_position: values must be finite");
  if (!v0.allFinite()) throw InvalidInput("initial_velocity: values must be finite");
  validateDynamics(timeStep, dampingGain);
  switch (method) {
    case Method::Variational:
      return std::make_unique<VariationalIntegrator>(formation, q0, v0, timeStep, dampingGain,
                                                     start);
    case Method::ExplicitEuler:
      return std::make_unique<ExplicitEulerIntegrator>(formation, q0, v0, timeStep, dampingGain);
    case Method::RungeKutta4:
      return std::make_unique<RungeKutta4Integrator>(formation, q0, v0, timeStep, dampingGain);
  }
  throw InvalidInput("--method: unknown method");
}

}  // namespace vf
