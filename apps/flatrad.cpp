// The flatrad command-line program; everything happens in apps/cli.
#include <iostream>

#include "cli/cli.h"
#include "large_pages.h"

FLATRAD_USE_LARGE_PAGES

int main(int argc, char** argv) {
    flatrad::use_large_pages_in_main();
    return flatrad::run_cli(argc, argv, std::cout, std::cerr);
}
