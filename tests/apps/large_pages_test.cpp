// apps/large_pages.h: a program linked as the flatrad tool is (with
// flatrad_allocator) allocates through mimalloc, with large OS pages on
// unless the environment says otherwise, set before main() (before the
// first allocation: the main thread's first segment is mapped then).
// Built without mimalloc (FLATRAD_MIMALLOC off, the package missing, or
// the sanitizers), the programs use the system malloc and there is
// nothing to check.
#include <doctest/doctest.h>

#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "large_pages.h"
#include "support/cli_run.h"

FLATRAD_USE_LARGE_PAGES  // as apps/flatrad.cpp does

#if FLATRAD_WITH_MIMALLOC
namespace {
// Read by a dynamic initializer: these run after every library's
// constructors (mimalloc's included) and before main(), so the option is
// already on here only if .preinit_array set it, ahead of all of them.
const bool on_before_main = mi_option_is_enabled(mi_option_large_os_pages);
const long delay_before_main = mi_option_get(mi_option_eager_commit_delay);
}  // namespace

TEST_CASE("the environment's setting of large pages is found in envp") {
    char a[] = "PATH=/bin", b[] = "MIMALLOC_LARGE_OS_PAGES=0", c[] = "mimalloc_large_os_pages=1",
         d[] = "MIMALLOC_LARGE_OS_PAGESX=1", e[] = "XMIMALLOC_LARGE_OS_PAGES=1";
    char* none[] = {a, d, e, nullptr};
    char* upper[] = {a, b, nullptr};
    char* lower[] = {c, a, nullptr};
    CHECK_FALSE(flatrad::large_pages_set_by_environment(none));
    CHECK(flatrad::large_pages_set_by_environment(upper));
    CHECK(flatrad::large_pages_set_by_environment(lower));
    CHECK_FALSE(flatrad::large_pages_set_by_environment(nullptr));
    char f[] = "MIMALLOC_EAGER_COMMIT_DELAY=2", g[] = "mimalloc_eager_commit_delay=1", h[] = "MIMALLOC_EAGER_COMMIT=1";
    char* delay_upper[] = {a, f, nullptr};
    char* delay_lower[] = {g, nullptr};
    char* other[] = {h, b, nullptr};
    CHECK(flatrad::option_set_by_environment(delay_upper, "MIMALLOC_EAGER_COMMIT_DELAY"));
    CHECK(flatrad::option_set_by_environment(delay_lower, "MIMALLOC_EAGER_COMMIT_DELAY"));
    CHECK_FALSE(flatrad::option_set_by_environment(other, "MIMALLOC_EAGER_COMMIT_DELAY"));
    CHECK_FALSE(flatrad::option_set_by_environment(upper, "MIMALLOC_EAGER_COMMIT_DELAY"));
}

TEST_CASE("large pages are turned off for a scene file above the limit, and only then") {
    // large_pages_for_scene: a file of more than large_pages_max_scene_bytes
    // turns mimalloc's option off for what is mapped next; one of exactly
    // that size, a path that is no file, or a directory leave it; the
    // environment's setting always stands.
    const bool env = std::getenv("MIMALLOC_LARGE_OS_PAGES") || std::getenv("mimalloc_large_os_pages");
    flatrad::use_large_pages_in_main();  // (where .preinit_array did not set them)
    const bool before = mi_option_is_enabled(mi_option_large_os_pages);
    if (!env) REQUIRE(before);  // on, so that turning them off is seen
    // Put back at the end, whatever happens: the next case checks that the
    // option is on (each case must pass run alone or in one run of all).
    struct Restore {
        bool on;
        ~Restore() { mi_option_set_enabled(mi_option_large_os_pages, on); }
    } restore{before};
    flatrad::test::TempDir tmp;
    const std::string at_limit = tmp.file("at_limit.json", std::string(flatrad::large_pages_max_scene_bytes, ' '));
    const std::string above = tmp.file("above.json", std::string(flatrad::large_pages_max_scene_bytes + 1, ' '));
    flatrad::large_pages_for_scene(at_limit);
    flatrad::large_pages_for_scene(tmp.path("missing.json"));
    flatrad::large_pages_for_scene(tmp.dir().string());
    CHECK(mi_option_is_enabled(mi_option_large_os_pages) == before);
    flatrad::large_pages_for_scene(above);
    if (env)
        CHECK(mi_option_is_enabled(mi_option_large_os_pages) == before);
    else
        CHECK_FALSE(mi_option_is_enabled(mi_option_large_os_pages));
    // Allocation goes on as before (from 4 KiB pages).
    std::vector<double> big(size_t{1} << 23, 1.0);  // 64 MiB: new segments
    CHECK(mi_is_in_heap_region(big.data()));
    CHECK(big.back() == 1.0);
}

TEST_CASE("the programs' operator new and malloc are mimalloc's, with large OS pages from before main") {
    const char* env = std::getenv("MIMALLOC_LARGE_OS_PAGES");
    if (!env) env = std::getenv("mimalloc_large_os_pages");
#if defined(__ELF__) && defined(__linux__)
    if (!env) CHECK(on_before_main);
    // Every thread's first segment committed at once, in large pages.
    if (!std::getenv("MIMALLOC_EAGER_COMMIT_DELAY") && !std::getenv("mimalloc_eager_commit_delay"))
        CHECK(delay_before_main == 0);
#endif
    flatrad::use_large_pages_in_main();
    if (!env) CHECK(mi_option_is_enabled(mi_option_large_os_pages));
    // The environment's word stands (MIMALLOC_LARGE_OS_PAGES=0: none).
    if (env && std::string(env) == "0") CHECK_FALSE(mi_option_is_enabled(mi_option_large_os_pages));
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
