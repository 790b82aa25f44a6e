// apps/large_pages.h: a program linked as the flatrad tool is (with
// flatrad_allocator) allocates through mimalloc, with large OS pages on
// unless the environment says otherwise. Built without mimalloc
// (FLATRAD_MIMALLOC off, the package missing, or the sanitizers), the
// programs use the system malloc and there is nothing to check.
#include <doctest/doctest.h>

#include <cstdlib>
#include <memory>
#include <string>

#include "large_pages.h"

#if FLATRAD_WITH_MIMALLOC
TEST_CASE("the programs' operator new and malloc are mimalloc's, with large OS pages") {
    const bool env_set = flatrad::large_pages_set_by_environment();
    flatrad::use_large_pages();
    if (!env_set) CHECK(mi_option_is_enabled(mi_option_large_os_pages));
    // The environment's word stands (MIMALLOC_LARGE_OS_PAGES=0: none).
    const char* off = std::getenv("MIMALLOC_LARGE_OS_PAGES");
    if (off && std::string(off) == "0") CHECK_FALSE(mi_option_is_enabled(mi_option_large_os_pages));
    // The override is in effect (a link order that left glibc's malloc
    // first would fail these): small and large blocks, through new and
    // through malloc, come from mimalloc's heap.
    const auto small = std::make_unique<int>(7);
    const auto large = std::make_unique<double[]>(size_t{1} << 21);  // 16 MiB
    void* raw = std::malloc(100);
    CHECK(mi_is_in_heap_region(small.get()));
    CHECK(mi_is_in_heap_region(large.get()));
    CHECK(mi_is_in_heap_region(raw));
    std::free(raw);
}
#endif
