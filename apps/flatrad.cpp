// The flatrad command-line program; everything happens in apps/cli.
#include <iostream>

#include "cli/cli.h"

int main(int argc, char** argv) { return flatrad::run_cli(argc, argv, std::cout, std::cerr); }
