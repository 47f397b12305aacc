#include "variational_formation/ros/frame_gate.hpp"

#include <utility>

#include <ros/console.h>

#include "variational_formation/ros/frames.hpp"

namespace vf {

FrameGate::FrameGate(std::string worldFrame, std::string who, std::string consequence)
    : world_(std::move(worldFrame)), who_(std::move(who)), consequence_(std::move(consequence)) {}

bool FrameGate::admit(const std::string& frame, const std::string& topic) {
  if (isFrame(frame, world_)) return true;
  ++refused_;
  if (warned_.insert(topic).second) {
    ROS_WARN("%s: refused odometry on %s in frame '%s', not the world frame '%s' (positions are taken as world "
             "positions: remap a pose in '%s' there); %s; every such message is refused and counted",
             who_.c_str(), topic.c_str(), frame.c_str(), world_.c_str(), world_.c_str(), consequence_.c_str());
  }
  return false;
}

std::string FrameGate::refusedNote() const {
  return refused_ > 0 ? " (" + std::to_string(refused_) + " refused: not in the world frame '" + world_ + "')" : "";
}

}  // namespace vf
