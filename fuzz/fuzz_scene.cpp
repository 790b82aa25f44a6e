// libFuzzer target for the scene reader and the form-factor entry points:
// every input goes through flatrad::fuzz::check_input (fuzz/fuzz_checks.h).
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

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    if (const auto finding = flatrad::fuzz::check_input(text)) {
        std::fprintf(stderr, "fuzz_scene: invariant broken: %s\n", finding->c_str());
        std::abort();
    }
    return 0;
}
