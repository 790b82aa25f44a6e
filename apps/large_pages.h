#pragma once
// The flatrad programs' allocator (CMakeLists.txt, FLATRAD_MIMALLOC; README,
// "Dependencies"): where the build links mimalloc, its memory comes in large
// OS pages (2 MiB: explicit huge pages where the system has some reserved,
// else transparent huge pages asked for through madvise), which
// spares the solver's large arrays most of their page faults and TLB misses:
// a round room of 10^6 walls solved in 8.7-10.6 s instead of 14.8-15.5 s.
// Only the programs do this; a program embedding the library keeps its own
// allocator (with glibc it can get huge pages from GLIBC_TUNABLES=
// glibc.malloc.hugetlb=1).
#include <cstdlib>

#if FLATRAD_WITH_MIMALLOC
#include <mimalloc.h>
#endif

namespace flatrad {

/// Whether the environment sets mimalloc's large-pages option (mimalloc
/// reads its variables in either case).
inline bool large_pages_set_by_environment() {
    return std::getenv("MIMALLOC_LARGE_OS_PAGES") || std::getenv("mimalloc_large_os_pages");
}

/// First thing in main(): mimalloc takes large OS pages from then on, unless
/// the environment says otherwise (MIMALLOC_LARGE_OS_PAGES=0 turns them
/// off). (mimalloc reads its options from the environment as the process
/// starts, so a new default would come too late: the option is set only
/// when the environment leaves it unset.) Without mimalloc, nothing.
inline void use_large_pages() {
#if FLATRAD_WITH_MIMALLOC
    if (!large_pages_set_by_environment()) mi_option_enable(mi_option_large_os_pages);
#endif
}

}  // namespace flatrad
