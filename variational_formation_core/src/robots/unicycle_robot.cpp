#include "variational_formation_core/robots/unicycle_robot.hpp"

#include <algorithm>
#include <cmath>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"

namespace vf {

namespace {

double wrapAngle(double a) { return std::atan2(std::sin(a), std::cos(a)); }

// 3-point Gauss-Legendre on [0, 1]: nodes 1/2 -+ sqrt(3/5)/2 and 1/2, weights 5/18, 8/18, 5/18.
constexpr double kNodes[3] = {0.1127016653792583, 0.5, 0.8872983346207417};
constexpr double kWeights[3] = {5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};

}  // namespace

void validateUnicycleRobot(const UnicycleRobotSettings& settings) {
  requireRobotLimits(settings.lag, settings.maxSpeed, settings.odometryNoise);
  requireFiniteAbove("max_turn_rate", settings.maxTurnRate, 0.0, "rad/s");
  requireFiniteAtLeast("heading_noise", settings.headingNoise, 0.0, "rad");
}

UnicycleRobot::UnicycleRobot(const UnicycleRobotSettings& settings, const PlanarPose& initialPose,
                             std::uint64_t seed)
    : settings_(settings), x_(initialPose.x), y_(initialPose.y), theta_(initialPose.heading), engine_(seed) {
  validateUnicycleRobot(settings_);
  if (!std::isfinite(x_) || !std::isfinite(y_) || !std::isfinite(theta_)) {
    throw InvalidInput("initial pose: must be finite, got (" + formatNumber(x_) + ", " + formatNumber(y_) +
                       ", " + formatNumber(theta_) + ")");
  }
  theta_ = wrapAngle(theta_);
}

void UnicycleRobot::setCommand(double linear, double lateral, double angular) {
  if (!std::isfinite(linear) || !std::isfinite(lateral) || !std::isfinite(angular)) {
    throw InvalidInput("command: must be finite, got linear (" + formatNumber(linear) + ", " +
                       formatNumber(lateral) + "), angular " + formatNumber(angular));
  }
  uv_ = std::clamp(linear, -settings_.maxSpeed, settings_.maxSpeed);
  uw_ = std::clamp(angular, -settings_.maxTurnRate, settings_.maxTurnRate);
}

void UnicycleRobot::advance(double dt) {
  requireFiniteAtLeast("dt", dt, 0.0, "s");
  const double tau = settings_.lag;
  const double longest = tau > 0.0 ? std::min(0.01, 0.5 * tau) : 0.01;
  const long pieces = std::max(1L, static_cast<long>(std::ceil(dt / longest)));
  for (long i = 0; i < pieces; ++i) advanceSubinterval(dt / static_cast<double>(pieces));
  time_ += dt;
  theta_ = wrapAngle(theta_);
}

void UnicycleRobot::advanceSubinterval(double dt) {
  const double tau = settings_.lag;
  // Exact v(t), theta(t) for the constant command over [0, dt].
  const auto speedAt = [&](double t) { return tau > 0.0 ? uv_ + (v_ - uv_) * std::exp(-t / tau) : uv_; };
  const auto headingAt = [&](double t) {
    return tau > 0.0 ? theta_ + uw_ * t + (w_ - uw_) * tau * -std::expm1(-t / tau) : theta_ + uw_ * t;
  };
  double dx = 0.0, dy = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double t = kNodes[k] * dt;
    const double v = speedAt(t);
    const double th = headingAt(t);
    dx += kWeights[k] * v * std::cos(th);
    dy += kWeights[k] * v * std::sin(th);
  }
  x_ += dx * dt;
  y_ += dy * dt;
  theta_ = headingAt(dt);
  if (tau > 0.0) {
    const double decay = std::exp(-dt / tau);
    v_ = uv_ + (v_ - uv_) * decay;
    w_ = uw_ + (w_ - uw_) * decay;
  } else {
    v_ = uv_;
    w_ = uw_;
  }
}

PlanarPose UnicycleRobot::measuredPose() {
  PlanarPose measured = pose();
  measured.x += settings_.odometryNoise * normal_(engine_);
  measured.y += settings_.odometryNoise * normal_(engine_);
  measured.heading = wrapAngle(measured.heading + settings_.headingNoise * normal_(engine_));
  return measured;
}

PlanarPose UnicycleRobot::pose() const {
  PlanarPose p;
  p.x = x_;
  p.y = y_;
  p.heading = theta_;
  return p;
}

}  // namespace vf
