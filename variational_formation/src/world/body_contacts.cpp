#include "variational_formation/world/body_contacts.hpp"

#include <cmath>
#include <limits>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"

namespace vf {

BodyContacts::BodyContacts(int robots, double bodyRadius)
    : bodyRadius_(bodyRadius),
      known_(static_cast<std::size_t>(robots > 0 ? robots : 0), false),
      position_(3 * known_.size(), 0.0),
      log_(robots),
      closest_(std::numeric_limits<double>::infinity()) {
  if (robots <= 0) throw InvalidInput("robots: must be > 0, got " + std::to_string(robots));
  requireFiniteAbove("body_radius", bodyRadius, 0.0, "m");
}

void BodyContacts::setPosition(int robot, double x, double y, double z) {
  if (robot < 0 || robot >= static_cast<int>(known_.size())) return;
  const std::size_t i = static_cast<std::size_t>(robot);
  known_[i] = true;
  position_[3 * i] = x;
  position_[3 * i + 1] = y;
  position_[3 * i + 2] = z;
}

std::vector<ContactEvent> BodyContacts::check(double time, int only) {
  touching_.clear();
  const int n = static_cast<int>(known_.size());
  const double diameter = 2.0 * bodyRadius_;
  for (int a = 0; a < n; ++a) {
    if (!known_[static_cast<std::size_t>(a)]) continue;
    for (int b = a + 1; b < n; ++b) {
      if (!known_[static_cast<std::size_t>(b)] || (only >= 0 && a != only && b != only)) continue;
      const double* p = &position_[3 * static_cast<std::size_t>(a)];
      const double* q = &position_[3 * static_cast<std::size_t>(b)];
      const double d = std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
      closest_ = std::min(closest_, d);
      if (d < diameter) touching_.push_back({a, b, 0.0, diameter - d});  // no forces in a kinematic world
    }
  }
  return log_.record(time, touching_);
}

}  // namespace vf
