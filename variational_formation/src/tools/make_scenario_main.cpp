#include <iostream>

#include "variational_formation/tools/make_scenario_cli.hpp"

int main(int argc, char** argv) { return vf::runMakeScenarioCli(argc, argv, std::cout, std::cerr); }
