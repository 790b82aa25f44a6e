#include "cli/solution_error.h"

#include <algorithm>
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
    std::vector<long double> diff2_p(scene.patches.size(), 0);  // per patch, all channels
    for (size_t p = 0; p < scene.patches.size(); ++p) {
        const long double L = scene.patches[p].length;
        length += L;
        for (int c = 0; c < C; ++c) {
            const long double r = reference.patches[p].radiosity[static_cast<size_t>(c)];
            const long double d = solution.patches[p].radiosity[static_cast<size_t>(c)] - r;
            diff2_p[p] += L * d * d;
            ref2 += L * r * r;
            ref2_c[static_cast<size_t>(c)] += L * r * r;
        }
        diff2 += diff2_p[p];
    }
    CompareError e;
    // The largest shares: a partial sort of the patch numbers (a share of
    // a sum that is not finite is left out: no share says anything then).
    if (diff2 > 0 && std::isfinite(static_cast<double>(diff2))) {
        std::vector<int> order;
        for (size_t p = 0; p < diff2_p.size(); ++p)
            if (diff2_p[p] > 0) order.push_back(static_cast<int>(p));
        const size_t k = std::min<size_t>(largest_error_patches, order.size());
        std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(k), order.end(), [&](int a, int b) {
            const long double x = diff2_p[static_cast<size_t>(a)], y = diff2_p[static_cast<size_t>(b)];
            return x > y || (x == y && a < b);
        });
        for (size_t q = 0; q < k; ++q)
            e.largest.push_back({order[q], static_cast<double>(diff2_p[static_cast<size_t>(order[q])] / diff2)});
    }
    const double inf = std::numeric_limits<double>::infinity();
    e.relative_l2 = diff2 == 0 ? 0 : (ref2 > 0 ? static_cast<double>(std::sqrt(diff2 / ref2)) : inf);
    // Each difference at the scene's scale (max_relative) and at its own
    // patch's (q_pc, length-weighted quantiles below).
    struct Weighted {
        double q, length;
    };
    std::vector<Weighted> q;
    q.reserve(scene.patches.size() * static_cast<size_t>(C));
    long double total = 0;  // their weights' sum
    for (size_t p = 0; p < scene.patches.size(); ++p)
        for (int c = 0; c < C; ++c) {
            const double rms = length > 0 ? static_cast<double>(std::sqrt(ref2_c[static_cast<size_t>(c)] / length)) : 0;
            const double r = reference.patches[p].radiosity[static_cast<size_t>(c)];
            const double d = std::abs(solution.patches[p].radiosity[static_cast<size_t>(c)] - r);
            const double rel = d == 0 ? 0 : (rms > 0 ? d / rms : inf);
            if (e.worst_patch < 0 || rel > e.max_relative || std::isnan(rel)) {
                e.max_relative = std::isnan(rel) ? inf : rel;
                e.worst_patch = static_cast<int>(p);
            }
            const double own = d == 0 ? 0 : (r != 0 ? d / std::abs(r) : inf);
            q.push_back({std::isnan(own) ? inf : own, scene.patches[p].length});
            total += scene.patches[p].length;
        }
    if (e.max_relative == 0) e.worst_patch = -1;
    if (!q.empty()) {
        std::sort(q.begin(), q.end(), [](const Weighted& a, const Weighted& b) { return a.q < b.q; });
        auto quantile = [&](double share) {
            long double below = 0;
            for (const Weighted& w : q) {
                below += w.length;
                if (below >= share * total) return w.q;
            }
            return q.back().q;  // (rounding of the running sum)
        };
        e.patch_relative = {quantile(0.5), quantile(0.9), q.back().q};
    }
    return e;
}

}  // namespace flatrad
