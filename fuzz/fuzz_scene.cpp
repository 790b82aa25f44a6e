// libFuzzer target for the scene reader and the form-factor entry points:
// every input goes through flatrad::fuzz::check_input (fuzz/fuzz_checks.h).
// Built a second time with FLATRAD_FUZZ_HIERARCHICAL as fuzz_hierarchical,
// for the hierarchical solver: check_hierarchical_input instead.
// A broken invariant aborts with a message; an escaping exception (an
// InternalError from FLATRAD_ASSERT, say) terminates; sanitizer reports
// abort. libFuzzer reports each as a crash and keeps the input.
#include <omp.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "fuzz/fuzz_checks.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    omp_set_num_threads(1);  // one input at a time; threads only add noise
    return 0;
}

#ifdef FLATRAD_FUZZ_HIERARCHICAL
#define FLATRAD_FUZZ_CHECK check_hierarchical_input
#define FLATRAD_FUZZ_NAME "fuzz_hierarchical"
#else
#define FLATRAD_FUZZ_CHECK check_input
#define FLATRAD_FUZZ_NAME "fuzz_scene"
#endif

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    if (const auto finding = flatrad::fuzz::FLATRAD_FUZZ_CHECK(text)) {
        std::fprintf(stderr, FLATRAD_FUZZ_NAME ": invariant broken: %s\n", finding->c_str());
        std::abort();
    }
    return 0;
}
