// The flatrad command-line program; everything happens in apps/cli.
#include <iostream>

#include "cli/cli.h"
#include "cli/scene_warnings.h"
#include "large_pages.h"

FLATRAD_USE_LARGE_PAGES

int main(int argc, char** argv) {
    flatrad::use_large_pages_in_main();
    flatrad::set_before_scene_read(&flatrad::large_pages_for_scene);  // large scenes: 4 KiB pages
    return flatrad::run_cli(argc, argv, std::cout, std::cerr);
}
