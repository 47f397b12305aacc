#pragma once

#include <stdexcept>
#include <string>

namespace vf {

/// Bad input to the core: a scenario field, a flag value or a message. The message is one line
/// of the form "<field>: <problem>" so that tools and nodes can print it as it is.
class InvalidInput : public std::runtime_error {
 public:
  explicit InvalidInput(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace vf
