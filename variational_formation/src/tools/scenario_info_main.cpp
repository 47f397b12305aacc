// `scenario_info --scenario FILE|NAME [--real-time-factor R] [--rigidity]`: validates a scenario
// and prints "agents N" (used by the launch scripts); warnings and the graph's rigidity class on
// stderr (scenario_info_cli.hpp). Exit 2 on bad input.
#include <iostream>

#include "variational_formation/tools/scenario_info_cli.hpp"

int main(int argc, char** argv) { return vf::runScenarioInfoCli(argc, argv, std::cout, std::cerr); }
