#pragma once

#include <iosfwd>
#include <map>
#include <string>
#include <vector>

#include "variational_formation_core/model/validation.hpp"

namespace vf {

/**
 * Command-line flags of the ROS-free tools: "--name value..." with a fixed number of values
 * per flag. Every problem is an InvalidInput naming the flag, so each tool reports bad flags
 * with the same one-line error and exit status 2.
 */
class Arguments {
 public:
  /// @param arity flag name (with "--") -> number of values it takes (0 for a switch).
  Arguments(int argc, const char* const* argv, const std::map<std::string, int>& arity);

  bool has(const std::string& flag) const { return values_.count(flag) != 0; }
  /// The i-th value of a flag. @throws InvalidInput if the flag is absent.
  std::string text(const std::string& flag, int i = 0) const;
  std::string text(const std::string& flag, const std::string& fallback) const;
  /// A finite double. @throws InvalidInput if absent or not a number.
  double number(const std::string& flag, int i = 0) const;
  /// A finite double > 0.
  double positiveNumber(const std::string& flag, int i = 0) const;
  /// An integer within [min, max].
  long integer(const std::string& flag, long min, long max, int i = 0) const;
  /// @throws InvalidInput "<flag>: required" unless present.
  void require(const std::string& flag) const;

 private:
  std::map<std::string, std::vector<std::string>> values_;
};

/// The scenario overrides --time-step H, --kappa K and --steps N that are present, parsed but
/// not checked: applyOverrides validates them like the file's values.
ScenarioOverrides scenarioOverrides(const Arguments& args);

/**
 * Writes `text` to the file --out names, or to `out` without --out. @return kExitOk, or
 * kExitFailure with "<tool>: error: writing '<file>' failed (disk full?)" on err.
 * @throws InvalidInput "--out: cannot write '<file>'" if the file cannot be opened.
 */
int writeOutput(const Arguments& args, const std::string& text, const std::string& tool, std::ostream& out,
                std::ostream& err);

}  // namespace vf
