#include "cli/solution_error.h"

#include <cmath>
#include <limits>
#include <vector>

#include "engine/error.h"

namespace flatrad {

CompareError compare_solutions(const Scene& scene, const Solution& solution, const Solution& reference) {
    FLATRAD_ASSERT(solution.patches.size() == scene.patches.size() &&
                       reference.patches.size() == scene.patches.size(),
                   "both solutions are of this scene");
    const int C = scene.channels;
    // Length-weighted sums, in long double: thousands of patches of
    // very different brightness (a lamp beside shadows).
    long double diff2 = 0, ref2 = 0, length = 0;
    std::vector<long double> ref2_c(static_cast<size_t>(C), 0);
    for (size_t p = 0; p < scene.patches.size(); ++p) {
        const long double L = scene.patches[p].length;
        length += L;
        for (int c = 0; c < C; ++c) {
            const long double r = reference.patches[p].radiosity[static_cast<size_t>(c)];
            const long double d = solution.patches[p].radiosity[static_cast<size_t>(c)] - r;
            diff2 += L * d * d;
            ref2 += L * r * r;
            ref2_c[static_cast<size_t>(c)] += L * r * r;
        }
    }
    CompareError e;
    const double inf = std::numeric_limits<double>::infinity();
    e.relative_l2 = diff2 == 0 ? 0 : (ref2 > 0 ? static_cast<double>(std::sqrt(diff2 / ref2)) : inf);
    for (size_t p = 0; p < scene.patches.size(); ++p)
        for (int c = 0; c < C; ++c) {
            const double rms = length > 0 ? static_cast<double>(std::sqrt(ref2_c[static_cast<size_t>(c)] / length)) : 0;
            const double d = std::abs(solution.patches[p].radiosity[static_cast<size_t>(c)] -
                                      reference.patches[p].radiosity[static_cast<size_t>(c)]);
            const double rel = d == 0 ? 0 : (rms > 0 ? d / rms : inf);
            if (e.worst_patch < 0 || rel > e.max_relative || std::isnan(rel)) {
                e.max_relative = std::isnan(rel) ? inf : rel;
                e.worst_patch = static_cast<int>(p);
            }
        }
    if (e.max_relative == 0) e.worst_patch = -1;
    return e;
}

}  // namespace flatrad
