#include <iostream>

#include "variational_formation/tools/simulate_cli.hpp"

int main(int argc, char** argv) { return vf::runSimulateCli(argc, argv, std::cout, std::cerr); }
