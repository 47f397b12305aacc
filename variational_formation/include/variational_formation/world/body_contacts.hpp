#pragma once

#include <vector>

#include "variational_formation/world/contact_log.hpp"

namespace vf {

/// The TurtleBot3 Burger's body radius [m] (its 0.21 m diameter, issue 31): robot_sim's default.
constexpr double kBurgerBodyRadius = 0.105;

/**
 * Body contacts of kinematic robots (robot_sim, doc/robots.md "Contacts"): two robots touch while
 * their body centres (a unicycle's axle, a holonomic robot's position) are closer than one body
 * diameter. Contacts are counted as the MuJoCo world counts them (ContactLog: a pair that keeps
 * touching is one contact, until it was apart for ContactLog::kSeparation), so both worlds report
 * `contacts:` and `first_contact:` alike.
 */
class BodyContacts {
 public:
  /// @param robots how many [> 0]. @param bodyRadius [m] > 0. @throws InvalidInput naming body_radius.
  BodyContacts(int robots, double bodyRadius);
  /// Robot `robot`'s body centre [m] (x, y, z; z = 0 on the plane). Ids outside [0, robots) are ignored.
  void setPosition(int robot, double x, double y, double z = 0.0);
  /**
   * The pairs that touch at `time` [s], among robots whose position is known: all pairs, or only
   * those with robot `only` (>= 0). @return the contacts that began.
   */
  std::vector<ContactEvent> check(double time, int only = -1);
  const ContactLog& log() const { return log_; }
  /// The closest body-centre distance of a checked pair so far [m] (+inf before any).
  double closest() const { return closest_; }
  double bodyRadius() const { return bodyRadius_; }

 private:
  double bodyRadius_;
  std::vector<bool> known_;
  std::vector<double> position_;  // 3 per robot
  ContactLog log_;
  double closest_;
  std::vector<Touch> touching_;
};

}  // namespace vf
