#pragma once
// Relative L2 error of per-patch radiosity, length-weighted over all
// channels: the measure `flatrad compare` reports (apps/cli/solution_error.h),
// written out here so that solver tests need not link the CLI's.
#include <cmath>
#include <cstddef>

#include "engine/scene.h"
#include "solver/solution.h"

namespace flatrad::test {

inline double relative_l2(const Scene& scene, const Solution& h, const Solution& e) {
    double num = 0, den = 0;
    for (size_t p = 0; p < scene.patches.size(); ++p)
        for (int c = 0; c < scene.channels; ++c) {
            const size_t k = static_cast<size_t>(c);
            const double L = scene.patches[p].length;
            const double d = h.patches[p].radiosity[k] - e.patches[p].radiosity[k];
            num += L * d * d;
            den += L * e.patches[p].radiosity[k] * e.patches[p].radiosity[k];
        }
    return std::sqrt(num / den);
}

}  // namespace flatrad::test
