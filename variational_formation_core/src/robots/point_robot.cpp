#include "variational_formation_core/robots/point_robot.hpp"

#include <algorithm>
#include <cmath>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"

namespace vf {

namespace {

double norm(const std::vector<double>& x) {
  double sum = 0.0;
  for (double c : x) sum += c * c;
  return std::sqrt(sum);
}

void checkVector(const char* field, const std::vector<double>& x, std::size_t size) {
  if (x.size() != size) {
    throw InvalidInput(std::string(field) + ": expected " + std::to_string(size) + " values, got " +
                       std::to_string(x.size()));
  }
  for (double c : x) {
    if (!std::isfinite(c)) throw InvalidInput(std::string(field) + ": must be finite, got " + formatNumber(c));
  }
}

}  // namespace

void validatePointRobot(const PointRobotSettings& settings) {
  requireRobotLimits(settings.lag, settings.maxSpeed, settings.odometryNoise);
  requireFiniteAbove("max_acceleration", settings.maxAcceleration, 0.0, "m/s^2");
}

PointRobot::PointRobot(const PointRobotSettings& settings, const std::vector<double>& initialPosition,
                       std::uint64_t seed)
    : settings_(settings), p_(initialPosition), engine_(seed) {
  validatePointRobot(settings_);
  if (initialPosition.size() != 2 && initialPosition.size() != 3) {
    throw InvalidInput("initial_position: expected 2 or 3 values, got " + std::to_string(initialPosition.size()));
  }
  checkVector("initial_position", initialPosition, initialPosition.size());
  v_.assign(p_.size(), 0.0);
  u_.assign(p_.size(), 0.0);
}

void PointRobot::setCommand(const std::vector<double>& velocity) {
  checkVector("command", velocity, p_.size());
  const double speed = norm(velocity);
  const double scale = speed > settings_.maxSpeed ? settings_.maxSpeed / speed : 1.0;
  for (std::size_t a = 0; a < u_.size(); ++a) u_[a] = scale * velocity[a];
}

void PointRobot::advance(double dt) {
  requireFiniteAtLeast("dt", dt, 0.0, "s");
  const std::size_t d = p_.size();
  const double tau = settings_.lag;
  const double aMax = settings_.maxAcceleration;
  time_ += dt;
  std::vector<double> gap(d);  // u - v
  for (std::size_t a = 0; a < d; ++a) gap[a] = u_[a] - v_[a];
  const double s = norm(gap);
  double remaining = dt;
  // Phase 1: |u - v| above aMax tau, so (u - v)/tau is saturated: v moves towards u at aMax.
  const double sLinear = aMax * tau;
  if (s > sLinear) {
    const double t1 = (s - sLinear) / aMax;
    const double t = std::min(dt, t1);
    for (std::size_t a = 0; a < d; ++a) {
      const double e = gap[a] / s;
      p_[a] += v_[a] * t + 0.5 * aMax * t * t * e;
      // At the phase boundary put v exactly at distance sLinear from u.
      v_[a] = t == t1 ? u_[a] - sLinear * e : v_[a] + aMax * t * e;
    }
    remaining = dt - t;
  }
  if (remaining <= 0.0) return;
  // Phase 2: the linear lag, solved exactly: v = u + (v0 - u) e^{-t/tau}.
  if (tau > 0.0) {
    const double decay = std::exp(-remaining / tau);
    const double lost = tau * (1.0 - decay);  // integral of e^{-t/tau} over [0, remaining]
    for (std::size_t a = 0; a < d; ++a) {
      const double offset = v_[a] - u_[a];
      p_[a] += u_[a] * remaining + offset * lost;
      v_[a] = u_[a] + offset * decay;
    }
  } else {
    for (std::size_t a = 0; a < d; ++a) {
      p_[a] += u_[a] * remaining;
      v_[a] = u_[a];
    }
  }
}

std::vector<double> PointRobot::measuredPosition() {
  std::vector<double> measured(p_);
  for (double& c : measured) c += settings_.odometryNoise * normal_(engine_);
  return measured;
}

}  // namespace vf
