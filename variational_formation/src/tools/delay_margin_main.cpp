#include <unistd.h>

#include <iostream>

#include "variational_formation/tools/delay_margin_cli.hpp"

int main(int argc, char** argv) {
  return vf::runDelayMarginCli(argc, argv, std::cout, std::cerr, isatty(STDERR_FILENO) != 0);
}
