#include "variational_formation/tools/deployment.hpp"

#include <limits>
#include <ostream>
#include <random>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation_core/common/standard_normal.hpp"
#include "variational_formation_core/model/validation.hpp"
#include "variational_formation/tools/arguments.hpp"

namespace vf {

Positions scatteredPositions(const Positions& desired, double side, double minGap, std::uint64_t seed) {
  requireFiniteAbove("--scatter", side, 0.0, "m");
  requireFiniteAtLeast("--min-gap", minGap, 0.0, "m");
  const Eigen::VectorXd centre = desired.rowwise().mean();
  const Eigen::Index d = desired.rows(), n = desired.cols();
  std::mt19937_64 engine(seed);
  Positions q(d, n);
  const long maxTries = 1000 * static_cast<long>(n);
  long tries = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    for (;;) {
      if (++tries > maxTries) {
        throw InvalidInput("--min-gap: could not place " + std::to_string(n) + " agents " + formatNumber(minGap) +
                           " m apart in a box of side " + formatNumber(side) + " m in " + std::to_string(maxTries) +
                           " draws; give a larger --scatter or a smaller --min-gap");
      }
      for (Eigen::Index a = 0; a < d; ++a) q(a, i) = centre(a) + side * (uniformUnit(engine) - 0.5);
      bool apart = true;
      for (Eigen::Index j = 0; apart && j < i; ++j) apart = (q.col(i) - q.col(j)).norm() >= minGap;
      if (apart) break;
    }
  }
  return q;
}

std::string applyDeploymentFlags(const Arguments& args, std::uint64_t seed, Scenario& s) {
  if (args.has("--min-gap") && !args.has("--scatter")) throw InvalidInput("--min-gap: only with --scatter");
  if (args.has("--max-speed") && !args.has("--safety")) throw InvalidInput("--max-speed: only with --safety");
  if (args.has("--safety")) {
    SafetySettings safety;
    safety.radius = args.number("--safety", 0);
    safety.sensingRadius = args.number("--safety", 1);
    safety.gamma = args.number("--safety", 2);
    if (args.has("--max-speed")) safety.maxSpeed = args.number("--max-speed");
    s.safety = safety;
  }
  std::string description;
  if (args.has("--scatter")) {
    if (args.has("--perturb")) throw InvalidInput("--perturb: not with --scatter (the start is scattered instead)");
    const double side = args.number("--scatter");
    const double gap = args.has("--min-gap") ? args.number("--min-gap") : (s.safety ? s.safety->radius : 0.0);
    s.initialPositions = scatteredPositions(s.desiredPositions, side, gap, seed);
    description = "start: uniform in a " + std::string(s.dimension == 2 ? "square" : "cube") + " of side " +
                  formatNumber(side) + " m round the desired centroid, at least " + formatNumber(gap) +
                  " m apart, seed " + std::to_string(seed);
  }
  validateSafety(s);
  return description;
}

void writeSafetyYaml(const Scenario& s, std::ostream& out) {
  const auto vector = [&](const Eigen::Vector3d& v) {
    out << '[';
    for (int a = 0; a < s.dimension; ++a) out << (a ? ", " : "") << formatNumber(v(a));
    out << ']';
  };
  if (s.safety) {
    const SafetySettings& safety = *s.safety;
    out << "safety: {radius: " << formatNumber(safety.radius) << ", sensing_radius: "
        << formatNumber(safety.sensingRadius) << ", gamma: " << formatNumber(safety.gamma);
    if (safety.maxSpeed != std::numeric_limits<double>::infinity()) out << ", max_speed: " << formatNumber(safety.maxSpeed);
    out << ", blocked_after: " << formatNumber(safety.blockedAfter) << "}\n";
  }
  if (s.obstacles.empty()) return;
  out << "obstacles:\n";
  for (const Obstacle& o : s.obstacles) {
    if (o.shape == Obstacle::Shape::Ball) {
      out << "  - {center: ";
      vector(o.centre);
      out << ", radius: " << formatNumber(o.radius) << "}\n";
    } else {
      out << "  - {min: ";
      vector(o.min);
      out << ", max: ";
      vector(o.max);
      out << "}\n";
    }
  }
}

}  // namespace vf
