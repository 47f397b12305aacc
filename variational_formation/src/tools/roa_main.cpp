#include <unistd.h>

#include <iostream>

#include "variational_formation/tools/roa_cli.hpp"

int main(int argc, char** argv) {
  return vf::runRoaCli(argc, argv, std::cout, std::cerr, isatty(STDERR_FILENO) != 0);
}
