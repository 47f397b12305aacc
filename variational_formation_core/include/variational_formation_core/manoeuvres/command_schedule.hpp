#pragma once

#include <string>
#include <utility>
#include <vector>

#include "variational_formation_core/common/types.hpp"

namespace vf {

/**
 * A commanded motion of the whole formation (doc/manoeuvres.md, doc/maths.md §9), broadcast to
 * every agent. All vectors are in the world frame.
 */
struct Command {
  /// v*, the velocity of the formation's centroid [m/s]; z = 0 in 2D.
  Vector3 velocity = Vector3::Zero();
  /// omega*, the angular rate about the centroid [rad/s]; in 2D only z (counter-clockwise > 0).
  Vector3 angularRate = Vector3::Zero();
  /// s > 0, the factor on every desired distance [1].
  double scale = 1.0;

  bool rotates() const { return angularRate.x() != 0.0 || angularRate.y() != 0.0 || angularRate.z() != 0.0; }
  bool operator==(const Command& o) const {
    return velocity == o.velocity && angularRate == o.angularRate && scale == o.scale;
  }
  bool operator!=(const Command& o) const { return !(*this == o); }
};

/// One entry of a scenario's `manoeuvre:` schedule: `command` applies until time `until` [s].
struct ManoeuvreSegment {
  double until = 0.0;
  Command command;
};

/**
 * Step-stamped commands. Interval k is [t_k, t_{k+1}]; an entry (m, c) governs every interval
 * k >= m up to the next entry, and intervals before the first entry have the zero command
 * (v* = 0, omega* = 0, s = 1). The update that produces q_{k+1} (k >= 1) uses the commands of
 * intervals k-1 and k, the start q_1 that of interval 0 (doc/maths.md §9).
 */
class CommandSchedule {
 public:
  using Entry = std::pair<long, Command>;

  /// Appends (step, command). @throws InvalidInput naming `field` unless step > the last step
  /// (>= 0 for the first).
  void add(long step, const Command& command, const std::string& field = "step");
  /// From `step` on, `command` replaces the schedule: entries at step or later are dropped, then
  /// (step, command) is appended. @throws InvalidInput naming `field` if step < 0.
  void replaceFrom(long step, const Command& command, const std::string& field = "step");
  /// The command of interval k.
  const Command& at(long step) const;
  /// Index in entries() of the entry governing interval k, -1 before the first entry.
  long entryIndex(long step) const;
  const std::vector<Entry>& entries() const { return entries_; }
  bool empty() const { return entries_.empty(); }
  /// Some entry has a non-zero angular rate.
  bool rotates() const;
  /// The largest commanded scale (1 if there is no entry).
  double largestScale() const;

 private:
  std::vector<Entry> entries_;
  Command zero_;
};

/**
 * The schedule of step-stamped commands equivalent to a `manoeuvre:` list at time step h:
 * segment 0 applies from step 0, segment i >= 1 from the first step k with k h >= until_{i-1}
 * (t_k = k h in doubles, as the integrators compute it). When two segments start at the same
 * step the later one wins.
 */
CommandSchedule scheduleFromSegments(const std::vector<ManoeuvreSegment>& segments, double timeStep);

/// Header of a commands file: "step,vx,vy,vz,wx,wy,wz,scale".
extern const char* const kCommandsHeader;
/// Writes a commands file (header and one row per entry, 17 significant digits).
void writeCommands(std::ostream& out, const CommandSchedule& schedule);

}  // namespace vf
