#pragma once

#include <string>

#include <ros/time.h>

#include "variational_formation_msgs/WorldContact.h"
#include "variational_formation/world/contact_log.hpp"

namespace vf {

/// The message of a contact as both worlds publish it (mujoco_world, robot_sim): `count` contacts
/// so far, this one included.
inline variational_formation_msgs::WorldContact worldContactMessage(const ContactEvent& c, const ros::Time& stamp,
                                                               const std::string& frame, long count) {
  variational_formation_msgs::WorldContact msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = frame;
  msg.first = c.first;
  msg.second = c.second;
  msg.sim_time = c.time;
  msg.normal_force = c.normalForce;
  msg.count = count;
  return msg;
}

}  // namespace vf
