#pragma once

#include <string>
#include <type_traits>
#include <vector>

#include <ros/ros.h>

#include "variational_formation_core/common/invalid_input.hpp"

namespace vf {

/// What a parameter of type T must be, for error messages.
template <typename T>
const char* parameterKind() {
  if (std::is_same<T, bool>::value) return "true or false";
  if (std::is_integral<T>::value) return "an integer";
  if (std::is_floating_point<T>::value) return "a number";
  if (std::is_same<T, std::vector<double>>::value) return "a list of numbers";
  return "a string";
}

/// A required private parameter: no silent default. @throws InvalidInput naming it.
template <typename T>
T requiredParam(const ros::NodeHandle& pnh, const std::string& name) {
  if (!pnh.hasParam(name)) throw InvalidInput("~" + name + ": required parameter missing");
  T value;
  if (!pnh.getParam(name, value)) {
    throw InvalidInput("~" + name + ": expected " + parameterKind<T>() + ", got a value of another type");
  }
  return value;
}

/// An optional private parameter: the default only when it is absent; a value of the wrong
/// type is an error, not a silent default. @throws InvalidInput naming it.
template <typename T>
T optionalParam(const ros::NodeHandle& pnh, const std::string& name, const T& fallback) {
  return pnh.hasParam(name) ? requiredParam<T>(pnh, name) : fallback;
}

}  // namespace vf
