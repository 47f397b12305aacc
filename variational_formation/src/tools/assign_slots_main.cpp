#include <iostream>

#include "variational_formation/tools/assign_slots_cli.hpp"

int main(int argc, char** argv) { return vf::runAssignSlotsCli(argc, argv, std::cout, std::cerr); }
