#include "variational_formation/tools/arguments.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation/tools/simulate_cli.hpp"

namespace vf {

Arguments::Arguments(int argc, const char* const* argv, const std::map<std::string, int>& arity) {
  for (int a = 1; a < argc; ++a) {
    const std::string flag = argv[a];
    const auto it = arity.find(flag);
    if (it == arity.end()) {
      throw InvalidInput(flag + ": unknown " + (flag.rfind("--", 0) == 0 ? "flag" : "argument") +
                         " (see --help)");
    }
    if (values_.count(flag)) throw InvalidInput(flag + ": given more than once");
    std::vector<std::string> vals;
    for (int k = 0; k < it->second; ++k) {
      if (a + 1 >= argc) {
        throw InvalidInput(flag + ": expects " + std::to_string(it->second) + " value" +
                           (it->second == 1 ? "" : "s"));
      }
      vals.emplace_back(argv[++a]);
    }
    values_[flag] = vals;
  }
}

void Arguments::require(const std::string& flag) const {
  if (!has(flag)) throw InvalidInput(flag + ": required (see --help)");
}

std::string Arguments::text(const std::string& flag, int i) const {
  require(flag);
  return values_.at(flag).at(static_cast<std::size_t>(i));
}

std::string Arguments::text(const std::string& flag, const std::string& fallback) const {
  return has(flag) ? text(flag, 0) : fallback;
}

double Arguments::number(const std::string& flag, int i) const {
  const std::string s = text(flag, i);
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v)) {
    throw InvalidInput(flag + ": expected a finite number, got '" + s + "'");
  }
  return v;
}

double Arguments::positiveNumber(const std::string& flag, int i) const {
  const double v = number(flag, i);
  if (!(v > 0.0)) throw InvalidInput(flag + ": must be > 0, got '" + text(flag, i) + "'");
  return v;
}

long Arguments::integer(const std::string& flag, long min, long max, int i) const {
  const std::string s = text(flag, i);
  errno = 0;
  char* end = nullptr;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE) {
    throw InvalidInput(flag + ": expected an integer, got '" + s + "'");
  }
  if (v < min || v > max) {
    throw InvalidInput(flag + ": must be between " + std::to_string(min) + " and " +
                       std::to_string(max) + ", got " + s);
  }
  return v;
}

ScenarioOverrides scenarioOverrides(const Arguments& args) {
  ScenarioOverrides overrides;
  if (args.has("--time-step")) overrides.timeStep = args.number("--time-step");
  if (args.has("--kappa")) overrides.dampingGain = args.number("--kappa");
  if (args.has("--steps")) {
    overrides.steps = args.integer("--steps", std::numeric_limits<long>::min(),
                                   std::numeric_limits<long>::max());
  }
  return overrides;
}

int writeOutput(const Arguments& args, const std::string& text, const std::string& tool, std::ostream& out,
                std::ostream& err) {
  if (!args.has("--out")) {
    out << text;
    return kExitOk;
  }
  std::ofstream file(args.text("--out"));
  if (!file) throw InvalidInput("--out: cannot write '" + args.text("--out") + "'");
  file << text;
  file.flush();
  if (!file) {
    err << tool << ": error: writing '" << args.text("--out") << "' failed (disk full?)\n";
    return kExitFailure;
  }
  return kExitOk;
}

}  // namespace vf
