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
//
// When the option is set matters. mimalloc maps the main thread's first
// segment (32 MiB) at the first allocation, which the C++ runtime makes
// before main(); an option set in main() reaches only the segments mapped
// after. A solve that fits in that first segment (the 1000-segment forest
// of `flatrad_bench versus`: 17 MB) then takes its pages 4 KiB at a time:
// 2968 page faults for one `flatrad solve` at eps 12 against 785 with the
// option set from the start, and 80.7 ms against 65.6 ms (medians of 15,
// alternating; page faults cost ~5 us each on this virtual machine). So on
// ELF systems the option is set from .preinit_array, which the dynamic
// loader runs after relocation and before any library's constructor,
// mimalloc's included, so before the first allocation; elsewhere, first
// thing in main().
#include <cstdlib>
#include <cstring>

#if FLATRAD_WITH_MIMALLOC
#include <mimalloc.h>
#endif

namespace flatrad {

/// Whether the environment `envp` (a null-terminated array of NAME=VALUE)
/// sets mimalloc's large-pages option (mimalloc reads its variables in
/// either case, in upper or lower case). Reads envp, not getenv(): in
/// .preinit_array the C library's environ may not be set up yet.
inline bool large_pages_set_by_environment(char** envp) {
    for (char** e = envp; e && *e; ++e)
        if (std::strncmp(*e, "MIMALLOC_LARGE_OS_PAGES=", 24) == 0 ||
            std::strncmp(*e, "mimalloc_large_os_pages=", 24) == 0)
            return true;
    return false;
}

/// mimalloc takes large OS pages from then on, unless the environment `envp`
/// says otherwise (MIMALLOC_LARGE_OS_PAGES=0 turns them off). mimalloc reads
/// its options from the environment as it initialises, and only those it
/// has not been given: the option is set only when the environment leaves
/// it unset. Only sets a flag in mimalloc's static option table (no
/// allocation), so it can run before mimalloc is initialised. Without
/// mimalloc, nothing.
inline void use_large_pages(char** envp) {
#if FLATRAD_WITH_MIMALLOC
    if (!large_pages_set_by_environment(envp)) mi_option_enable(mi_option_large_os_pages);
#else
    (void)envp;
#endif
}

namespace detail {
inline void use_large_pages_preinit(int, char**, char** envp) { use_large_pages(envp); }
}  // namespace detail

/// First thing in main(): where .preinit_array is not available (see
/// FLATRAD_USE_LARGE_PAGES), sets the option there, late but for every
/// segment mapped from then on; elsewhere nothing (it is set already).
inline void use_large_pages_in_main() {
#if !(defined(__ELF__) && defined(__linux__)) && FLATRAD_WITH_MIMALLOC
    if (!std::getenv("MIMALLOC_LARGE_OS_PAGES") && !std::getenv("mimalloc_large_os_pages"))
        mi_option_enable(mi_option_large_os_pages);
#endif
}

}  // namespace flatrad

// Once, at namespace scope, in a program's main file (never in a library:
// .preinit_array is for executables only): large pages from the start.
#if defined(__ELF__) && defined(__linux__)
#define FLATRAD_USE_LARGE_PAGES                                                                      \
    __attribute__((section(".preinit_array"), used)) static void (*const flatrad_large_pages_preinit)( \
        int, char**, char**) = &flatrad::detail::use_large_pages_preinit;
#else
#define FLATRAD_USE_LARGE_PAGES
#endif
