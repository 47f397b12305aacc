#include "variational_formation_core/model/validation.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/model/motion_parameters.hpp"
#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation_core/integrators/step_size_advice.hpp"
#include "variational_formation_core/integrators/variational_update.hpp"

namespace vf {

namespace {

// Shortest text that reads back as the same double: the value the user gave, and exact limits.
std::string show(double x) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, x);
  return std::string(buffer, result.ptr);
}

// A limit x > 0 for a person to read, rounded down to formatRounded's digits: every value up to
// the text is within the limit.
std::string roundedDown(double x) {
  std::string text = formatRounded(x);
  for (double step = std::pow(10.0, std::floor(std::log10(x)) - 5); std::stod(text) > x;) {
    text = formatRounded(std::stod(text) - step);
  }
  return text;
}

}  // namespace

std::string dynamicsProblem(double timeStep, double dampingGain, const FieldNames& names) {
  const double h = timeStep, kappa = dampingGain;
  if (!(std::isfinite(kappa) && kappa >= 0.0)) {
    return names.dampingGain + ": must be finite and >= 0, got " + show(kappa);
  }
  if (!(std::isfinite(h) && h > 0.0)) {
    return names.timeStep + ": must be finite and > 0, got " + show(h);
  }
  if (h > limits::kMaxTimeStep) {
    return names.timeStep + ": must be <= " + show(limits::kMaxTimeStep) +
           " s (beyond it 2 h^2 overflows), got " + show(h);
  }
  if (kappa * h > limits::kMaxDampingTimeStep) {
    return names.dampingGain + " * " + names.timeStep + ": must be <= " + show(limits::kMaxDampingTimeStep) +
           " (beyond it e^{-kappa h} underflows and the update freezes), got " + show(kappa) + " * " + show(h) +
           " = " + formatRounded(kappa * h);
  }
  // e^{-kappa h} is normal now; the position gains can still underflow when h is tiny.
  const VariationalCoefficients c(h, kappa);
  const std::pair<const char*, double> gains[] = {{"2h^2/(1 + e^{kappa h})", c.gradientGain},
                                                  {"2h/(1 + e^{kappa h})", c.startGain}};
  for (const auto& [name, gain] : gains) {
    if (!(gain >= limits::kSmallestGain)) {
      return names.timeStep + ": too small, the gain " + name + " = " + formatRounded(gain) + " must be >= " +
             show(limits::kSmallestGain) + " (the smallest normal double), got h = " + show(h) +
             " with kappa = " + show(kappa);
    }
  }
  return "";
}

void validateDynamics(double timeStep, double dampingGain, const FieldNames& names) {
  const std::string problem = dynamicsProblem(timeStep, dampingGain, names);
  if (!problem.empty()) throw InvalidInput(problem);
}

double maxDampingGain(double timeStep) {
  validateDynamics(timeStep, 0.0);  // a refused h has no kappa at all
  // The accepted kappas are [0, K] (every limit is monotone in kappa). Non-negative doubles are
  // ordered as their bit patterns: bisect those, so K is the exact edge of dynamicsProblem.
  const auto bitsOf = [](double x) {
    std::uint64_t b;
    std::memcpy(&b, &x, sizeof b);
    return b;
  };
  const auto valueOf = [](std::uint64_t b) {
    double x;
    std::memcpy(&x, &b, sizeof x);
    return x;
  };
  std::uint64_t accepted = bitsOf(0.0), refused = bitsOf(std::numeric_limits<double>::infinity());
  while (refused - accepted > 1) {
    const std::uint64_t mid = accepted + (refused - accepted) / 2;
    (dynamicsProblem(timeStep, valueOf(mid), {}).empty() ? accepted : refused) = mid;
  }
  return valueOf(accepted);
}

std::optional<std::string> refuseDampingGain(double timeStep, double requested, double current,
                                             const std::string& field) {
  if (dynamicsProblem(timeStep, requested, {field, "time_step", "steps"}).empty()) return std::nullopt;
  return field + ": " + formatNumber(requested) + " refused, outside the accepted range [0, " +
         roundedDown(maxDampingGain(timeStep)) + "] 1/s at time step h = " + formatRounded(timeStep) +
         " s; kappa stays " + formatNumber(current);
}

void validateSteps(long steps, bool requireBounded, const std::string& field) {
  if (steps < 0 || steps > limits::kMaxSteps) {
    throw InvalidInput(field + ": must be between 0 and " + std::to_string(limits::kMaxSteps) +
                       " (2^53), got " + std::to_string(steps));
  }
  if (requireBounded && steps == 0) {
    throw InvalidInput(field + ": must be >= 1 here, got 0 (0 = unbounded is only for the ROS run;" +
                       " the tools take --steps N)");
  }
}

void validateRealTimeFactor(double realTimeFactor, double timeStep, const std::string& field) {
  if (!(std::isfinite(realTimeFactor) && realTimeFactor >= 0.0)) {
    throw InvalidInput(field + ": must be finite and >= 0 (0 = as fast as possible), got " +
                       show(realTimeFactor));
  }
  if (realTimeFactor > 0.0 && !(timeStep / realTimeFactor <= limits::kMaxPacingSeconds)) {
    throw InvalidInput(field + ": the pacing time_step / " + field + " must be <= " +
                       show(limits::kMaxPacingSeconds) + " s (a ROS duration), got " +
                       show(timeStep) + " / " + show(realTimeFactor) + " = " +
                       formatRounded(timeStep / realTimeFactor) + " s");
  }
}

void validateInitialHeadings(const Scenario& s) {
  if (s.initialHeadings.empty()) return;
  if (s.dimension != 2) {
    throw InvalidInput("initial_heading: only for planar (dimension 2) unicycles, the scenario has dimension " +
                       std::to_string(s.dimension));
  }
  if (static_cast<int>(s.initialHeadings.size()) != s.agentCount()) {
    throw InvalidInput("initial_heading: expected one per agent (" + std::to_string(s.agentCount()) +
                       "), got " + std::to_string(s.initialHeadings.size()));
  }
  for (std::size_t i = 0; i < s.initialHeadings.size(); ++i) {
    const double heading = s.initialHeadings[i];
    if (!std::isfinite(heading)) {
      throw InvalidInput("agents[" + std::to_string(i) + "].initial_heading: must be finite, got " +
                         formatNumber(heading));
    }
  }
}

double initialHeading(const Scenario& s, int id) {
  if (id < 0 || id >= s.agentCount()) {
    throw InvalidInput("id: must be in 0.." + std::to_string(s.agentCount() - 1) + ", got " + std::to_string(id));
  }
  return s.initialHeadings.empty() ? 0.0 : s.initialHeadings[static_cast<std::size_t>(id)];
}

void validateScenario(Scenario& s, bool requireBoundedSteps, const FieldNames& names) {
  validateDynamics(s.timeStep, s.dampingGain, names);
  validateSteps(s.steps, requireBoundedSteps, names.steps);
  // Formation's constructor checks the edges and the desired shape.
  const Formation formation = makeFormation(s);
  validateInitialHeadings(s);
  s.warnings.clear();
  if (s.agentCount() >= 2 && !formation.isInfinitesimallyRigid(s.desiredPositions)) {
    s.warnings.push_back("edges: the desired graph is not infinitesimally rigid (rank " +
                         std::to_string(formation.rigidityRank(s.desiredPositions)) + ", need " +
                         std::to_string(rigidEdgeCount(s.dimension, s.agentCount())) +
                         "): the shape is not determined by its edge lengths");
  }
  const StepSizeAdvice advice =
      adviseTimeStep(formation, s.initialPositions, s.timeStep, s.dampingGain, names.timeStep);
  if (advice.exceeded) s.warnings.push_back(advice.message);
  validateManoeuvre(s, formation, names);
  validateSafety(s);
}

CommandFieldNames CommandFieldNames::keys(const std::string& prefix) {
  return {prefix + ".velocity", prefix + ".angular_rate", prefix + ".scale"};
}

CommandFieldNames CommandFieldNames::columns(const std::string& prefix) {
  return {prefix + ": vx,vy,vz", prefix + ": wx,wy,wz", prefix + ": scale"};
}

void validateCommand(const Command& c, int dimension, double timeStep, const CommandFieldNames& names) {
  if (!c.velocity.allFinite()) throw InvalidInput(names.velocity + ": must be finite");
  if (!c.angularRate.allFinite()) throw InvalidInput(names.angularRate + ": must be finite");
  if (!(std::isfinite(c.scale) && c.scale > 0.0)) {
    throw InvalidInput(names.scale + ": must be finite and > 0, got " + show(c.scale));
  }
  if (dimension == 2 && c.velocity.z() != 0.0) {
    throw InvalidInput(names.velocity + ": a 2D formation has no z velocity, got " + show(c.velocity.z()));
  }
  if (dimension == 2 && (c.angularRate.x() != 0.0 || c.angularRate.y() != 0.0)) {
    throw InvalidInput(names.angularRate + ": a 2D formation turns about z only, got x = " +
                       show(c.angularRate.x()) + ", y = " + show(c.angularRate.y()));
  }
  const double turn = timeStep * c.angularRate.norm();
  if (!(turn <= limits::kMaxTurnPerStep)) {
    throw InvalidInput(names.angularRate + ": turns h |omega| = " + formatRounded(turn) + " rad per step, more than " +
                       show(limits::kMaxTurnPerStep) + " (|omega| must be <= " +
                       formatRounded(limits::kMaxTurnPerStep / timeStep) + " rad/s at h = " + show(timeStep) + ")");
  }
}

void checkFormationCanTurn(const Formation& formation, const std::string& field) {
  for (int i = 0; i < formation.agentCount(); ++i) {
    const MotionParameters mu = motionParameters(formation, i);
    if (!mu.exact) throw InvalidInput(field + ": " + mu.problem);
  }
}

void validateManoeuvre(Scenario& s, const Formation& formation, const FieldNames& names) {
  if (s.manoeuvre.empty()) return;
  bool turns = false, moves = false;
  double largestScale = 1.0;
  for (std::size_t i = 0; i < s.manoeuvre.size(); ++i) {
    const std::string field = "manoeuvre[" + std::to_string(i) + "]";
    const ManoeuvreSegment& segment = s.manoeuvre[i];
    if (!(segment.until > 0.0)) throw InvalidInput(field + ".until: must be > 0 s, got " + show(segment.until));
    if (i > 0 && !(segment.until > s.manoeuvre[i - 1].until)) {
      throw InvalidInput(field + ".until: must be greater than manoeuvre[" + std::to_string(i - 1) +
                         "].until = " + show(s.manoeuvre[i - 1].until) + ", got " + show(segment.until));
    }
    validateCommand(segment.command, s.dimension, s.timeStep, CommandFieldNames::keys(field));
    turns = turns || segment.command.rotates();
    moves = moves || segment.command.rotates() || !segment.command.velocity.isZero(0.0);
    largestScale = std::max(largestScale, segment.command.scale);
  }
  if (turns) {
    checkFormationCanTurn(formation, "manoeuvre");
    // doc/maths.md §9: turning softens the shape modes by about w*^2; half the softest mode's
    // frequency (s w_min at scale s) is the range tested to hold the shape.
    const double softest = minStiffnessFrequency(formation, formation.desiredShape());
    for (std::size_t i = 0; i < s.manoeuvre.size(); ++i) {
      const Command& c = s.manoeuvre[i].command;
      const double allowed = 0.5 * c.scale * softest;
      if (c.angularRate.norm() > allowed) {
        s.warnings.push_back("manoeuvre[" + std::to_string(i) + "].angular_rate: |omega| = " +
                             formatRounded(c.angularRate.norm()) + " rad/s is above half the softest shape mode's frequency (" +
                             formatRounded(allowed) + " rad/s at scale " + show(c.scale) +
                             "): the turning formation may be slow to take its shape, or lose it");
      }
    }
  }
  if (moves && s.dampingGain == 0.0) {
    s.warnings.push_back("manoeuvre: " + names.dampingGain +
                         " = 0: the damping is the gain that drives the velocities to the command, so "
                         "the formation will not take up the commanded velocity or rate");
  }
  if (largestScale > 1.0) {
    // The Hessian at the scaled shape is s^2 times the unscaled one: w grows as s.
    const double w = largestScale * maxStiffnessFrequency(formation, formation.desiredShape());
    if (!isLinearlyStable(s.timeStep, w, s.dampingGain)) {
      s.warnings.push_back("manoeuvre: " + names.timeStep + " = " + show(s.timeStep) +
                           " exceeds the linear stability limit " + formatRounded(stableTimeStepLimit(w, s.dampingGain)) +
                           " s of the shape scaled by " + show(largestScale));
    }
  }
}

void applyOverrides(Scenario& s, const ScenarioOverrides& overrides, bool requireBoundedSteps) {
  FieldNames names;
  if (overrides.timeStep) {
    s.timeStep = *overrides.timeStep;
    names.timeStep = "--time-step";
  }
  if (overrides.dampingGain) {
    s.dampingGain = *overrides.dampingGain;
    names.dampingGain = "--kappa";
  }
  if (overrides.steps) {
    s.steps = *overrides.steps;
    names.steps = "--steps";
  }
  validateScenario(s, requireBoundedSteps, names);
}

}  // namespace vf
