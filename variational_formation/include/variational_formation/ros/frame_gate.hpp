#pragma once
// The check of a pose input's frame (odometry): the world frame's, or refused and counted.

#include <set>
#include <string>

namespace vf {

/**
 * The one check of the frame of a pose input (odometry): a message whose header.frame_id is not
 * the world frame is refused and counted, and the first refusal on each topic is one WARN naming
 * the topic, both frames and `consequence` (a TurtleBot's own odom starts each robot at 0, 0 of
 * a frame of its own: taken as world positions, it would place every robot wrongly, silently).
 */
class FrameGate {
 public:
  /// @param who the node's name in the WARN. @param consequence what happens while refused.
  FrameGate(std::string worldFrame, std::string who, std::string consequence);
  /// @return true if `frame` is the world frame; else counts it (and warns once per topic).
  bool admit(const std::string& frame, const std::string& topic);
  /// Messages refused so far, on every topic.
  long refused() const { return refused_; }
  const std::string& worldFrame() const { return world_; }
  /// " (N refused: not in the world frame 'W')" once any was refused, else "": for a waiting line.
  std::string refusedNote() const;

 private:
  std::string world_, who_, consequence_;
  long refused_ = 0;
  std::set<std::string> warned_;  // topics
};

}  // namespace vf
