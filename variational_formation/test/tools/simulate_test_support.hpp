#pragma once
// The simulate CLI run in-process, shared by the simulate tests.

#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "variational_formation/tools/simulate_cli.hpp"

namespace vf {
namespace test {

/// The shipped scenarios, config/ of the source tree.
const std::string kConfig = std::string(VF_SOURCE_DIR) + "/config/";

struct CliResult {
  int status;
  std::string out;
  std::string err;
};

/// Any of the tools' run*Cli functions, in-process, with `args` after the program name.
inline CliResult runCli(int (*cli)(int, const char* const*, std::ostream&, std::ostream&), std::vector<std::string> args,
                        const std::string& program = "tool") {
  args.insert(args.begin(), program);
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  std::ostringstream out, err;
  const int status = cli(static_cast<int>(argv.size()), argv.data(), out, err);
  return {status, out.str(), err.str()};
}

inline CliResult simulate(std::vector<std::string> args) { return runCli(runSimulateCli, std::move(args), "simulate"); }

/// Exit status 2 and exactly one line "simulate: error: ..." containing `fragment`.
inline void expectBadInput(const std::vector<std::string>& args, const std::string& fragment) {
  const CliResult r = simulate(args);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.err.rfind("simulate: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(fragment), std::string::npos) << r.err << " / " << fragment;
}

}  // namespace test
}  // namespace vf
