#pragma once

#include <string>

#include <ros/ros.h>

#include "variational_formation/core/error.hpp"

namespace vf {

/// A required private parameter: no silent default. @throws InvalidInput naming it.
template <typename T>
T requiredParam(const ros::NodeHandle& pnh, const std::string& name) {
  T value;
  if (!pnh.getParam(name, value)) {
    throw InvalidInput("~" + name + ": required parameter missing or of the wrong type");
  }
  return value;
}

}  // namespace vf
