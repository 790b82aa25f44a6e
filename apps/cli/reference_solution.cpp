#include "cli/reference_solution.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "cli/solution_error.h"
#include "cli/usage_error.h"
#include "solver/exact_mesh.h"
#include "solver/exact_solver.h"

namespace flatrad {

void check_reference_cap(const Scene& scene, long max_elements) {
    if (!reference_fits(scene, 1, max_elements))
        throw UsageError(fmt::format("--max-elements {}: the exact reference needs at least one element per patch, "
                                     "{} (or the exact solver's memory limit stops it); raise --max-elements",
                                     max_elements, scene.patches.size()));
}

bool reference_fits(const Scene& scene, long K, long max_elements) {
    const long patches = static_cast<long>(scene.patches.size());
    return K >= 1 && patches * K <= max_elements &&
           exact_solver_memory_bytes(scene, static_cast<int>(K)) <= exact_solver_memory_limit_bytes;
}

std::string reference_mesh_name(long K, long elements) {
    return K > 0 ? fmt::format("K = {} ({} elements)", K, elements) : fmt::format("graded ({} elements)", elements);
}

namespace {

// Whether a mesh of n elements fits (as reference_fits for K).
bool elements_fit(const Scene& scene, long n, long max_elements) {
    return n <= max_elements &&
           exact_solver_memory_bytes_for(scene, static_cast<double>(n)) <= exact_solver_memory_limit_bytes;
}

// Step 3's indicator of each element of the coarser solve (patch by patch,
// increasing t): the sum over its halves h in the finer solve, over
// channels, of L_h (B_h - B_e)^2. A finer element belongs to the coarser
// one that holds its midpoint.
std::vector<double> indicators(const Scene& scene, const Solution& coarse, const Solution& fine) {
    std::vector<double> eta;
    for (size_t p = 0; p < coarse.patches.size(); ++p) {
        const std::vector<ElementValue>& ce = coarse.patches[p].elements;
        const std::vector<ElementValue>& fe = fine.patches[p].elements;
        const double L = scene.patches[p].length;
        size_t j = 0;
        for (size_t i = 0; i < ce.size(); ++i) {
            double s = 0;
            for (; j < fe.size() && (i + 1 == ce.size() || 0.5 * (fe[j].t0 + fe[j].t1) < ce[i].t1); ++j)
                for (size_t c = 0; c < ce[i].B.size(); ++c) {
                    const double d = fe[j].B[c] - ce[i].B[c];
                    s += L * (fe[j].t1 - fe[j].t0) * d * d;
                }
            eta.push_back(s);
        }
    }
    return eta;
}

// The mesh of a solution's elements (their cuts, patch by patch).
ExactMesh mesh_of(const Solution& s) {
    ExactMesh m;
    m.cuts.resize(s.patches.size());
    for (size_t p = 0; p < s.patches.size(); ++p)
        for (size_t e = 1; e < s.patches[p].elements.size(); ++e) m.cuts[p].push_back(s.patches[p].elements[e].t0);
    return m;
}

// Step 3: the next graded mesh from the last pair, with at most `room`
// elements added; M itself when nothing is worth cutting or there is no
// room. `target2` is the target squared L2 distance (relative target
// squared times the finer solve's squared norm).
ExactMesh graded_step(const Scene& scene, const Solution& coarse, const Solution& fine, double target2, long room) {
    const std::vector<double> eta = indicators(scene, coarse, fine);
    ExactMesh mesh = mesh_of(coarse);
    if (eta.empty() || room <= 0) return mesh;
    // Cuts per element at threshold tau2: level k gives 2^k pieces, the
    // indicator falling as h^3, so k = ceil(log2(eta / tau2) / 3).
    std::vector<int> level(eta.size(), 0);
    auto levels = [&](double tau2) {
        long added = 0;
        for (size_t e = 0; e < eta.size(); ++e) {
            level[e] = 0;
            if (eta[e] > tau2) {
                level[e] = std::clamp(static_cast<int>(std::ceil(std::log2(eta[e] / tau2) / 3)), 1, max_graded_level);
                added += (1L << level[e]) - 1;
            }
        }
        return added;
    };
    // An equal share of the target for each element, raised until it fits.
    // (A target of 0, or one below rounding: start far below the largest.)
    const double largest = *std::max_element(eta.begin(), eta.end());
    if (!(largest > 0)) return mesh;
    double tau2 = target2 / static_cast<double>(eta.size());
    if (!(tau2 > 0)) tau2 = largest * 1e-30;
    while (levels(tau2) > room) tau2 *= 2;
    if (std::all_of(level.begin(), level.end(), [](int l) { return l == 0; })) {
        // The last doubling passed from too many cuts to none (indicators
        // within a factor 2 of each other): the previous threshold's cuts,
        // largest indicators first, while they fit.
        levels(tau2 / 2);
        std::vector<size_t> order(eta.size());
        for (size_t e = 0; e < order.size(); ++e) order[e] = e;
        std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return eta[a] > eta[b]; });
        long added = 0;
        for (size_t e : order) {
            const long more = level[e] > 0 ? (1L << level[e]) - 1 : 0;
            if (added + more > room) level[e] = 0;
            else added += more;
        }
    }
    return split_levels(mesh, level);
}

double squared_norm(const Scene& scene, const Solution& s) {
    double n2 = 0;
    for (size_t p = 0; p < s.patches.size(); ++p)
        for (double b : s.patches[p].radiosity) n2 += scene.patches[p].length * b * b;
    return n2;
}

}  // namespace

Reference solve_reference(const Scene& scene, const ReferenceOptions& options,
                          const std::function<double(const Solution& candidate)>& compared_error) {
    if (options.subdivide < 1 || !reference_fits(scene, 1, options.max_elements))
        throw std::invalid_argument(
            fmt::format("solve_reference: K = {}, or one element per patch, does not fit", options.subdivide));
    const long patches = static_cast<long>(scene.patches.size());
    Reference ref;
    auto record = [&](Solution s, long K) {
        ref.ladder_subdivide.push_back(K);
        ref.time_total_s += s.stats.time_s;
        ref.ladder.push_back(std::move(s));
    };
    auto exact = [&](long K) {
        if (options.on_solve) options.on_solve(K, patches * K);
        ExactSolverOptions o;
        o.subdivide = static_cast<int>(K);
        o.threads = options.threads;
        record(solve_exact(scene, o), K);
    };
    auto exact_on = [&](const ExactMesh& mesh) {
        if (options.on_solve) options.on_solve(0, mesh.elements());
        ExactSolverOptions o;
        o.threads = options.threads;
        record(solve_exact(scene, mesh, o), 0);
    };
    // Judges the last two solves as a pair; true when the search ends.
    auto judge = [&]() {
        const Solution& coarse = ref.ladder[ref.ladder.size() - 2];
        const Solution& fine = ref.ladder.back();
        const long coarse_K = ref.ladder_subdivide[ref.ladder.size() - 2];
        const CompareError pair = compare_solutions(scene, coarse, fine);
        ref.error_estimate = pair.relative_l2;
        ref.estimate_max_relative = pair.max_relative;
        ref.estimate_patch_relative = pair.patch_relative;
        ref.estimate_from_subdivide = coarse_K;
        ref.estimate_from = fmt::format("{} against {}", reference_mesh_name(coarse_K, coarse.stats.elements),
                                        reference_mesh_name(ref.ladder_subdivide.back(), fine.stats.elements));
        const double judged = compared_error(fine);
        ref.steps.push_back({coarse_K, coarse.stats.elements, ref.error_estimate, judged});
        if (ref.error_estimate <= judged / reference_margin) {
            ref.reached = true;
            ref.stopped.clear();  // (the uniform doubling's stop, when grading reached it)
            return true;
        }
        if (ref.error_estimate <= reference_rounding_floor) {
            ref.stopped = fmt::format("the two exact solutions agree to rounding ({:g}); a finer mesh "
                                      "cannot be more accurate",
                                      reference_rounding_floor);
            // The finer solve of the pair is the reference (as for `reached`).
            return true;
        }
        return false;
    };

    // 1-2. Uniform: K and 2K, doubling K. The first K is halved while its
    // pair would not fit (a reference with an estimate of its own error
    // beats a finer one without); when no pair fits at all, K alone.
    // After the first pair, K doubles only while its pair fits in half the
    // cap: the rest is left to grading, which spends it where it is needed
    // (furnished_room capped at 12 000: K = 16 against 32, then graded
    // steps of a few hundred elements, each a solve of 11 900, instead of
    // graded meshes grown from K = 8 by half at a time).
    long K = options.subdivide;
    while (K > 1 && !reference_fits(scene, 2 * K, options.max_elements / 2)) K /= 2;
    exact(K);
    while (true) {
        if (!reference_fits(scene, 2 * K, options.max_elements / 2)) {
            ref.stopped = fmt::format("K = {} ({} elements) would pass {}", 2 * K, patches * 2 * K,
                                      patches * 2 * K > options.max_elements / 2
                                          ? "half of --max-elements (the other half is kept for grading)"
                                          : "the exact solver's memory limit");
            break;
        }
        exact(2 * K);
        if (judge()) return ref;
        K *= 2;
    }
    if (ref.ladder.size() < 2) return ref;  // no pair: nothing to grade from

    // 3. Graded: from the last pair, cut where its elements disagree.
    while (true) {
        const Solution& coarse = ref.ladder[ref.ladder.size() - 2];
        const Solution& fine = ref.ladder.back();
        const long n = coarse.stats.elements;
        long room = std::min(options.max_elements / 2 - n, static_cast<long>((graded_growth - 1) * static_cast<double>(n)));
        while (room > 0 && !elements_fit(scene, 2 * (n + room), options.max_elements)) room /= 2;
        // A step that may add only a few elements costs a whole pair of
        // solves for little: not below a twentieth of the mesh.
        const long least = std::max(1L, n / graded_min_step);
        if (room < least) room = 0;
        const double target = ref.steps.back().compared_error / reference_margin;
        const ExactMesh mesh = graded_step(scene, coarse, fine, target * target * squared_norm(scene, fine), room);
        if (mesh.elements() == n) {
            ref.stopped = room > 0 ? "no element left to cut"
                                   : fmt::format("a graded step from {} elements by at least {} would pass {}", n,
                                                 least,
                                                 2 * (n + least) > options.max_elements
                                                     ? "--max-elements (its halved pair)"
                                                     : "the exact solver's memory limit (its halved pair)");
            return ref;
        }
        exact_on(mesh);
        exact_on(halved(mesh));
        if (judge()) return ref;
    }
}

}  // namespace flatrad
