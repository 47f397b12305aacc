#pragma once

#include <atomic>
#include <limits>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "variational_formation_core/common/types.hpp"
#include "variational_formation_core/safety/safety_filter.hpp"

namespace vf {

/// How far an agent of another formation may have moved since it was last heard (doc/maths.md §10,
/// "Other formations").
enum class ForeignMargin {
  /// Lockstep: its last step, |q^m - q^{m-1}| [m]: it takes about one more step while this agent
  /// takes its own (the formations paced alike; the clocks of two lockstep runs are not tied).
  LastStep,
  /// Timed and robot mode: age x max speed, as for the formation's own agents (stalenessMargin).
  Age
};

/// The closest pair of one of the formation's agents and an agent of another formation.
struct ClosestForeign {
  double distance = std::numeric_limits<double>::infinity();  ///< [m]; +inf: no foreign agent held
  int agent = -1;       ///< the formation's own agent (column of the positions)
  std::string foreign;  ///< the other agent's name, its state topic's namespace (/team_b/formation/agent_3)
};

/**
 * The agents of other formations on the same master, as last heard (doc/maths.md §10, "Other
 * formations"): the newest position of each, by name. They do not take part in this formation's
 * lockstep and do not reciprocate its constraints, so an agent takes the whole constraint itself
 * (SensedAgent::reciprocates false) against the position held, widened by how far the other agent
 * may have moved since (ForeignMargin). Thread-safe: the ROS layer fills it from the other
 * formations' topics while the agents read it; with nothing held, sense() costs one atomic load.
 */
class ForeignAgents {
 public:
  /// @param dimension d (2 or 3): states of another dimension are refused.
  explicit ForeignAgents(int dimension);

  /**
   * Keeps the state of agent `name` (q^m and q^{m-1}, d doubles each [m]) heard at `heardAt` [s]
   * (the caller's clock; the clock of sense()'s `now`), replacing what was held of it.
   * @return false (nothing kept) if a value is not finite.
   */
  bool hold(const std::string& name, const double* position, const double* previousPosition, double heardAt);

  /**
   * Appends to `out` every held agent within reach of q (|q - p| < R + margin, as safetyConstraints
   * senses), with id firstId + its index (ascending, after the formation's own ids when firstId is
   * the formation's size), its margin by `rule`, and reciprocates false.
   * @param q d doubles [m]. @param sensingRadius R [m]. @param now [s] (Age). @param maxSpeed [m/s] (Age).
   */
  void sense(const double* q, double sensingRadius, double now, ForeignMargin rule, double maxSpeed, int firstId,
             std::vector<SensedAgent>& out) const;

  /// The name of the agent sense() gave the id firstId + index.
  std::string name(int index) const;
  /// The closest pair of a column of q (d x n, the formation's positions [m]) and a held agent.
  ClosestForeign closest(const Positions& q) const;
  /// How many agents are held.
  std::size_t size() const { return count_.load(std::memory_order_acquire); }
  int dimension() const { return dimension_; }

 private:
  struct Held {
    std::string name;
    double position[3] = {0.0, 0.0, 0.0};
    double lastStep = 0.0;  // |q^m - q^{m-1}| [m]
    double heardAt = 0.0;
  };
  int dimension_;
  mutable std::mutex mutex_;
  std::map<std::string, std::size_t> index_;
  std::vector<Held> held_;
  std::atomic<std::size_t> count_{0};
};

}  // namespace vf
