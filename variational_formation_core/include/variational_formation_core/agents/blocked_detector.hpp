#pragma once

#include <string>
#include <vector>

namespace vf {

/**
 * Tells a blocked formation from a slow one (issue 31): the safety filter can hold agents
 * against each other for ever. The run is blocked at a step where some half-space of the
 * filter binds, the formation is not congruent, and the max distance error has not fallen below
 * (1 - kProgress) times its value at the last such fall for `blockedAfter` seconds.
 */
class BlockedDetector {
 public:
  /// A fall of the error by this fraction counts as progress.
  static constexpr double kProgress = 0.01;

  /// @param blockedAfter [s] > 0. @param timeStep h [s] > 0.
  BlockedDetector(double blockedAfter, double timeStep);

  /**
   * One step, in order. @param error max distance error [m]. @param congruent whether the
   * formation has the desired shape. @param bindingAgents, bindingObstacles what the filter's
   * binding half-spaces involve (SafetyStage), ascending.
   * @return whether the run is blocked from this step on.
   */
  bool update(long step, double error, bool congruent, const std::vector<int>& bindingAgents,
              const std::vector<int>& bindingObstacles);

  bool blocked() const { return blocked_; }
  /// "blocked: agents 2, 4" (and "; obstacles 0" if any binds), of the step that found it.
  std::string description() const;

 private:
  long window_;
  double reference_ = 0.0;
  long progressStep_ = -1;
  bool blocked_ = false;
  std::vector<int> agents_, obstacles_;
};

}  // namespace vf
