#pragma once

#include <cmath>
#include <string>

namespace vf {

/**
 * Checks of single numbers (node parameters, fault settings, robot limits), each failing with one
 * line "<field>: must be <limit>, got <value>" as InvalidInput. `unit` is appended to the limit
 * ("s", "m/s", or "" for none).
 */
/// value finite and >= lower. @throws InvalidInput
void requireFiniteAtLeast(const std::string& field, double value, double lower, const std::string& unit);
/// value finite and > lower. @throws InvalidInput
void requireFiniteAbove(const std::string& field, double value, double lower, const std::string& unit);
/// value finite and in [lower, upper]. @throws InvalidInput
void requireFiniteWithin(const std::string& field, double value, double lower, double upper,
                         const std::string& unit);
/// The limits every simulated robot has (robot_sim's parameter names): lag [s] >= 0,
/// max_speed [m/s] > 0, odometry_noise [m] >= 0, all finite. @throws InvalidInput
void requireRobotLimits(double lag, double maxSpeed, double odometryNoise);
/// Shortest decimal text that reads back as the same double ("0.1", "-inf", "nan"): a value
/// as the user gave it, an exact limit, a number a tool reads back.
std::string formatNumber(double value);
/// A computed number for a person to read (a sum, a quotient, a derived limit): 6 significant
/// digits, so 0.1 + 0.02 reads "0.12", not "0.12000000000000001" ("-inf", "nan" as above).
std::string formatRounded(double value);

/// Every coordinate of a state (its position and previous position, any containers of doubles)
/// is finite: false once a run has diverged.
template <class Position, class Previous>
bool finiteState(const Position& position, const Previous& previousPosition) {
  for (double x : position) {
    if (!std::isfinite(x)) return false;
  }
  for (double x : previousPosition) {
    if (!std::isfinite(x)) return false;
  }
  return true;
}

}  // namespace vf
