#include "variational_formation_core/common/number_checks.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>

#include "variational_formation_core/common/invalid_input.hpp"

namespace vf {

namespace {

[[noreturn]] void reject(const std::string& field, const std::string& limit, const std::string& unit,
                         double value) {
  throw InvalidInput(field + ": must be " + limit + (unit.empty() ? "" : " " + unit) + ", got " +
                     formatNumber(value));
}

}  // namespace

std::string formatNumber(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, value).ptr;
  return std::string(text, end);
}

std::string formatRounded(double value) {
  if (!std::isfinite(value)) return formatNumber(value);
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

void requireFiniteAtLeast(const std::string& field, double value, double lower, const std::string& unit) {
  if (!std::isfinite(value) || value < lower) reject(field, "finite and >= " + formatNumber(lower), unit, value);
}

void requireFiniteAbove(const std::string& field, double value, double lower, const std::string& unit) {
  if (!std::isfinite(value) || !(value > lower)) reject(field, "finite and > " + formatNumber(lower), unit, value);
}

void requireRobotLimits(double lag, double maxSpeed, double odometryNoise) {
  requireFiniteAtLeast("lag", lag, 0.0, "s");
  requireFiniteAbove("max_speed", maxSpeed, 0.0, "m/s");
  requireFiniteAtLeast("odometry_noise", odometryNoise, 0.0, "m");
}

void requireFiniteWithin(const std::string& field, double value, double lower, double upper,
                         const std::string& unit) {
  if (!std::isfinite(value) || value < lower || value > upper) {
    reject(field, "finite and in [" + formatNumber(lower) + ", " + formatNumber(upper) + "]", unit, value);
  }
}

}  // namespace vf
