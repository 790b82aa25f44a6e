#include "cli/reference_solution.h"

#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "cli/solution_error.h"
#include "solver/exact_solver.h"

namespace flatrad {

bool reference_fits(const Scene& scene, long K, long max_elements) {
    const long patches = static_cast<long>(scene.patches.size());
    return K >= 1 && patches * K <= max_elements &&
           exact_solver_memory_bytes(scene, static_cast<int>(K)) <= exact_solver_memory_limit_bytes;
}

Reference solve_reference(const Scene& scene, const ReferenceOptions& options,
                          const std::function<double(const Solution& candidate)>& compared_error) {
    if (!reference_fits(scene, options.subdivide, options.max_elements))
        throw std::invalid_argument(fmt::format("solve_reference: K = {} does not fit", options.subdivide));
    const long patches = static_cast<long>(scene.patches.size());
    Reference ref;
    auto exact = [&](long K) {
        if (options.on_solve) options.on_solve(K, patches * K);
        ExactSolverOptions o;
        o.subdivide = static_cast<int>(K);
        o.threads = options.threads;
        ref.ladder.push_back(solve_exact(scene, o));
        ref.ladder_subdivide.push_back(K);
        ref.time_total_s += ref.ladder.back().stats.time_s;
    };

    // 1-2. Exact at K and 2K, doubling K until the reference is good enough.
    long K = options.subdivide;
    exact(K);
    while (true) {
        if (!reference_fits(scene, 2 * K, options.max_elements)) {
            ref.stopped = fmt::format("K = {} ({} elements) would pass {}", 2 * K, patches * 2 * K,
                                      patches * 2 * K > options.max_elements ? "--max-elements"
                                                                              : "the exact solver's memory limit");
            break;
        }
        exact(2 * K);
        const Solution& coarse = ref.ladder[ref.ladder.size() - 2];
        const Solution& fine = ref.ladder.back();
        const CompareError pair = compare_solutions(scene, coarse, fine);
        ref.error_estimate = pair.relative_l2;
        ref.estimate_max_relative = pair.max_relative;
        ref.estimate_patch_relative = pair.patch_relative;
        ref.estimate_from_subdivide = K;
        const double judged = compared_error(fine);
        ref.steps.push_back({K, ref.error_estimate, judged});
        if (ref.error_estimate <= judged / reference_margin) {
            ref.reached = true;
            break;
        }
        if (ref.error_estimate <= reference_rounding_floor) {
            ref.stopped = fmt::format("the K and 2K exact solutions agree to rounding ({:g}); a finer mesh "
                                      "cannot be more accurate",
                                      reference_rounding_floor);
            // The finer solve of the pair is the reference (as for `reached`).
            break;
        }
        K *= 2;
    }
    return ref;
}

}  // namespace flatrad
