#pragma once

#include <optional>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace vf {

/// One touching pair of participants (robots, then obstacles) at one physics step.
struct Touch {
  int a = 0, b = 0;            ///< participant ids, a < b
  double normalForce = 0.0;    ///< summed normal force of the pair's contact points [N]
  double penetration = 0.0;    ///< deepest interpenetration of the pair [m] (>= 0)
  double x = 0.0, y = 0.0;     ///< where they touch on the floor [m]: the mean of the contact points
};

/// A contact: a pair that touches at a step and had not touched for kSeparation before.
struct ContactEvent {
  double time = 0.0;           ///< simulated time of the first touching step [s]
  std::string first, second;   ///< the participants' names ("robot_1", "obstacle_0")
  double normalForce = 0.0;    ///< at that step [N]
  double x = 0.0, y = 0.0;     ///< where they touched [m], world frame
};

/**
 * Counts contacts between robots and between robots and obstacles (doc/robots.md, "Contacts"):
 * a pair that keeps touching over many steps is one contact, and so is a pair whose contact
 * flickers while they push; it counts again only after it was apart for more than kSeparation.
 * Keeps the first contact, the deepest interpenetration and the largest normal force seen.
 * Participants 0..robots-1 are robot_<i>, the next ones obstacle_<k>.
 */
class ContactLog {
 public:
  /// Time [s] a pair must be apart before touching again is a new contact.
  static constexpr double kSeparation = 0.1;
  explicit ContactLog(int robots) : robots_(robots) {}
  /// The pairs touching at the step that ended at `time` [s]; returns the contacts it began.
  std::vector<ContactEvent> record(double time, const std::vector<Touch>& touching);
  std::string participantName(int id) const;
  long count() const { return count_; }
  const std::optional<ContactEvent>& first() const { return first_; }
  /// Pairs touching at the last recorded step.
  std::size_t active() const { return active_; }
  double maxPenetration() const { return maxPenetration_; }
  double maxNormalForce() const { return maxNormalForce_; }
  /// Every contact so far, in order (the markers show where each was).
  const std::vector<ContactEvent>& events() const { return events_; }
  /// The result file's lines: "contacts: N" and "first_contact: ..." (a quoted line, or ~).
  std::string resultLines() const;

 private:
  int robots_;
  std::map<std::pair<int, int>, double> lastTouched_;  // pair -> last time it touched [s]
  std::size_t active_ = 0;
  long count_ = 0;
  std::optional<ContactEvent> first_;
  std::vector<ContactEvent> events_;
  double maxPenetration_ = 0.0, maxNormalForce_ = 0.0;
};

}  // namespace vf
