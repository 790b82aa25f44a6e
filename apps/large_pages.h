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
// 2968 page faults for one `flatrad solve` at eps 12 against 688 with the
// option set as below, and 81.6 ms against 71.3 ms (medians of 15,
// alternating; page faults cost ~5-10 us each on this virtual machine). So on
// ELF systems the option is set from .preinit_array, which the dynamic
// loader runs after relocation and before any library's constructor,
// mimalloc's included, so before the first allocation; elsewhere, first
// thing in main().
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <system_error>

#if FLATRAD_WITH_MIMALLOC
#include <mimalloc.h>
#endif

namespace flatrad {

/// Whether the environment `envp` (a null-terminated array of NAME=VALUE)
/// sets the mimalloc option `name` (upper case, as MIMALLOC_LARGE_OS_PAGES;
/// mimalloc reads its variables in either case, so the lower-case spelling
/// counts too). Reads envp, not getenv(): in .preinit_array the C
/// library's environ may not be set up yet.
inline bool option_set_by_environment(char** envp, const char* name) {
    const size_t n = std::strlen(name);
    for (char** e = envp; e && *e; ++e) {
        bool same = std::strncmp(*e, name, n) == 0, lower = true;
        for (size_t k = 0; k < n && lower; ++k)
            lower = (*e)[k] == static_cast<char>(name[k] >= 'A' && name[k] <= 'Z' ? name[k] - 'A' + 'a' : name[k]);
        if ((same || lower) && (*e)[n] == '=') return true;
    }
    return false;
}

/// Whether `envp` sets mimalloc's large-pages option.
inline bool large_pages_set_by_environment(char** envp) {
    return option_set_by_environment(envp, "MIMALLOC_LARGE_OS_PAGES");
}

/// mimalloc takes large OS pages from then on, unless the environment `envp`
/// says otherwise (MIMALLOC_LARGE_OS_PAGES=0 turns them off). mimalloc reads
/// its options from the environment as it initialises, and only those it
/// has not been given: an option is set only when the environment leaves
/// it unset. Only sets flags in mimalloc's static option table (no
/// allocation), so it can run before mimalloc is initialised. Without
/// mimalloc, nothing.
///
/// Also every thread's first segment: mimalloc commits a new thread's
/// first segment lazily, 4 KiB pages as they are touched and never large
/// (eager_commit_delay 1), so the OpenMP worker's scratch (the self-
/// occlusion's envelopes, the refinement's visibility workspaces) page-
/// faulted where the main thread's did not. With the delay 0 (unless
/// MIMALLOC_EAGER_COMMIT_DELAY is set): the 1000-segment forest at eps 12,
/// `flatrad solve` 69.5 -> 64.6 ms (medians of 15, alternating), 941 ->
/// 230 page faults for one in-process solve and 117 -> 1 for each further
/// one; in-process medians 57.1 -> 56.0 ms.
inline void use_large_pages(char** envp) {
#if FLATRAD_WITH_MIMALLOC
    if (!large_pages_set_by_environment(envp)) mi_option_enable(mi_option_large_os_pages);
    if (!option_set_by_environment(envp, "MIMALLOC_EAGER_COMMIT_DELAY")) mi_option_set(mi_option_eager_commit_delay, 0);
#else
    (void)envp;
#endif
}

/// Whether this process's environment sets mimalloc's large-pages option
/// (either spelling), read with getenv (from main() on).
inline bool large_pages_set_in_environment() {
    return std::getenv("MIMALLOC_LARGE_OS_PAGES") || std::getenv("mimalloc_large_os_pages");
}

/// Scene files larger than this turn large pages off (large_pages_for_scene).
inline constexpr std::uintmax_t large_pages_max_scene_bytes = std::uintmax_t{2} << 20;

/// Large pages only for small scenes: for a scene file of more than
/// large_pages_max_scene_bytes (some 20 000 segments on), the segments
/// mapped from then on come in 4 KiB pages, unless the environment sets
/// MIMALLOC_LARGE_OS_PAGES (whose word stands). The main thread's first
/// segment, mapped before main(), keeps its large pages. The flatrad tool
/// calls it right before reading each scene (cli/scene_warnings.h's
/// set_before_scene_read). A path that is not a regular file: nothing.
///
/// Why: on this machine (a virtual machine whose guest reports freed memory
/// to its host, "Free page reporting enabled" at boot) a 2 MiB page costs
/// about twice the system time per byte of 4 KiB pages when first touched
/// (a freed huge page is a whole block the guest hands back, backed afresh
/// when used again), and the large footprints of large scenes pay it over
/// and over; small ones touch a few segments and keep the gain of few
/// faults. `flatrad solve`, interleaved runs with MIMALLOC_LARGE_OS_PAGES=0
/// against large pages throughout (medians; the forests of `scripts/
/// make-scene N --seed 1 --density 30` at eps 10, the round room of
/// `--round` at eps 3e-3): 10^3 segments (0.1 MB file, eps 12) 38.3 against
/// 35.3 ms, 10^4 (1 MB) 0.473 against 0.458 s; 3 x 10^4 (3 MB) 1.40
/// against 1.55 s; 10^5 (10 MB) 4.15 against 4.28 s, 4.68 against 4.92 s
/// from start to result; the round room of 10^6 (33 MB) 4.22 against 5.33
/// s (sys 1.75 against 3.4 s); reading the 10^6 forest's 107 MB file 3.7
/// against 6.1 s.
inline void large_pages_for_scene(const std::string& path) {
#if FLATRAD_WITH_MIMALLOC
    if (large_pages_set_in_environment()) return;
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(path, ec);  // (an error for what is not a regular file)
    if (!ec && size > large_pages_max_scene_bytes) mi_option_disable(mi_option_large_os_pages);
#else
    (void)path;
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
    if (!large_pages_set_in_environment()) mi_option_enable(mi_option_large_os_pages);
    if (!std::getenv("MIMALLOC_EAGER_COMMIT_DELAY") && !std::getenv("mimalloc_eager_commit_delay"))
        mi_option_set(mi_option_eager_commit_delay, 0);
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
