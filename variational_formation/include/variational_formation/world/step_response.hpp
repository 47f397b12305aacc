#pragma once

#include "variational_formation/world/world_settings.hpp"

namespace vf {

/// How one robot of a MuJoCo world follows a step of its forward speed command.
struct StepResponse {
  double command = 0.0;    ///< the step [m/s]
  double lag = 0.0;        ///< time to 63.2% of the step [s]: a first-order lag's time constant
  double riseTime = 0.0;   ///< from 10% to 90% [s]
  double final = 0.0;      ///< speed at the end [m/s]
  double overshoot = 0.0;  ///< largest speed beyond the command, as a share of it (>= 0)
};

/**
 * Builds a world of one robot with these settings at the origin, lets it settle on the floor
 * for 0.2 s, steps cmd_vel linear.x from 0 to `command` [m/s] > 0 and follows its forward speed
 * for `duration` [s]. The lag is what robot_sim's `lag` is to its model, and what the agents'
 * lag check compares with the delay margin (doc/robots.md, "The MuJoCo world").
 * @throws InvalidInput naming a bad setting or argument; if the speed never reaches 63.2%.
 */
StepResponse measureStepResponse(const WorldSettings& settings, double command, double duration = 2.0);

}  // namespace vf
