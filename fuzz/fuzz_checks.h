#pragma once
/// What the scene fuzzer checks on one input, shared by the libFuzzer
/// target (fuzz/fuzz_scene.cpp) and the replay of the seed and regression
/// corpus in the normal test suite (tests/solver/extremes_test.cpp), so that
/// every input the fuzzer ever broke keeps being checked without clang.
///
/// The bytes go to parse_scene. A refusal (InputError) is the expected
/// answer to most inputs; anything else thrown (an InternalError from
/// FLATRAD_ASSERT, a stray library exception) escapes to the caller. An
/// accepted scene of at most max_segments segments then goes through
/// group_form_factor (first surface -> last, exact and unoccluded) and, when
/// small enough, solve_exact with K = 1 and 2. Checked: the scene's own
/// invariants, every number finite, exact group F in [0, 1 + f_slack],
/// exact <= unoccluded, radiosity finite and >= 0.
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "engine/error.h"
#include "engine/scene.h"
#include "solver/exact_solver.h"
#include "solver/group_form_factor.h"
#include "solver/hierarchical_solver.h"

namespace flatrad::fuzz {

// Larger scenes are only parsed: a form factor's cost grows with the square
// of the blockers in its shaft, and the fuzzer needs many runs per second.
inline constexpr size_t max_segments = 64;
// solve_exact runs when patches x K stays below this (the dense system and
// all pairs' exact form factors grow as its square).
inline constexpr size_t max_elements = 48;
// A group form factor is a sum of exact ones, each right to ~1e-13, and at
// most 1 in exact arithmetic; 1e-9 flags real errors, not rounding.
inline constexpr double f_slack = 1e-9;

/// A broken invariant, as "what (value)".
using Finding = std::optional<std::string>;

inline Finding broken(const char* what, double value) { return fmt::format("{} (value {:.17g})", what, value); }

inline Finding check_scene(const Scene& scene) {
    if (scene.surfaces.empty() || scene.patches.empty()) return broken("accepted scene without patches", 0);
    for (const SceneSegment& s : scene.segments) {
        const double L = s.seg.length();
        if (!(L > 0) || !std::isfinite(L)) return broken("segment length not finite and > 0", L);
    }
    for (const Patch& p : scene.patches)
        if (!(p.length > 0) || !std::isfinite(p.length)) return broken("patch length not finite and > 0", p.length);
    for (const Material& m : scene.materials)
        if (m.reflectance.size() != static_cast<size_t>(scene.channels) ||
            m.emission.size() != static_cast<size_t>(scene.channels))
            return broken("material channel count", static_cast<double>(m.reflectance.size()));
    return std::nullopt;
}

inline size_t patches_of(const Scene& scene, int surface) {
    size_t n = 0;
    for (const Patch& p : scene.patches) n += p.surface == surface;
    return n;
}

inline Finding check_form_factors(const Scene& scene) {
    const int first = 0, last = static_cast<int>(scene.surfaces.size()) - 1;
    // Exact: a fraction of what leaves A, so at most 1.
    const GroupFormFactor exact = group_form_factor(scene, {first}, {last}, FormFactorMethod::Exact);
    for (double F : {exact.F, exact.F_reverse})
        if (!std::isfinite(F) || F < 0 || F > 1 + f_slack) return broken("exact group F outside [0, 1]", F);
    // Unoccluded ignores blockers, so walls hidden behind others count too
    // and a sum over several patches may pass 1; each pair's F_ij is at
    // most 1, so the group value is at most the receiving patch count.
    const GroupFormFactor open = group_form_factor(scene, {first}, {last}, FormFactorMethod::Unoccluded);
    const auto bad_sum = [](double F, size_t receivers) {
        return !std::isfinite(F) || F < 0 || F > static_cast<double>(receivers) * (1 + f_slack);
    };
    if (bad_sum(open.F, patches_of(scene, last))) return broken("unoccluded group F", open.F);
    if (bad_sum(open.F_reverse, patches_of(scene, first))) return broken("unoccluded group F_reverse", open.F_reverse);
    // Blockers only take light away (up to the rounding of two formulas).
    if (exact.F > open.F * (1 + f_slack) + f_slack) return broken("exact F above unoccluded F", exact.F - open.F);
    return std::nullopt;
}

inline Finding check_solution(const Scene& scene, int K) {
    Solution sol;
    try {
        sol = solve_exact(scene, ExactSolverOptions{K, 1});
    } catch (const InputError&) {
        return std::nullopt;  // no unique solution (a closed white enclosure): a clean refusal
    }
    if (sol.patches.size() != scene.patches.size()) return broken("patch count of the solution", 0);
    double largest = 0;
    for (const PatchResult& p : sol.patches) {
        if (p.elements.size() != static_cast<size_t>(K)) return broken("elements per patch", 0);
        for (const ElementValue& e : p.elements)
            for (double b : e.B) {
                if (!std::isfinite(b)) return broken("element radiosity not finite", b);
                largest = std::max(largest, std::abs(b));
            }
    }
    // B >= 0 in exact arithmetic; the dense solve may leave a patch that
    // receives (almost) nothing at minus a few ulps of the largest B.
    for (const PatchResult& p : sol.patches)
        for (double b : p.radiosity)
            if (!std::isfinite(b) || b < -f_slack * largest) return broken("patch radiosity not finite and >= 0", b);
    for (const auto* v : {&sol.totals.emitted, &sol.totals.absorbed, &sol.totals.escaped, &sol.totals.balance})
        for (double x : *v)
            if (!std::isfinite(x)) return broken("totals not finite", x);
    return std::nullopt;
}

/// The hierarchical solver at eps `eps` on one thread: no assert, no
/// sanitizer report, and every radiosity, total and stat a finite number.
/// Not B >= 0: in stiff scenes (reflectance near 1) the refinement's error,
/// which eps bounds in power, comes back about 1 / (1 - rho) times and may
/// push a dim patch below 0 (docs/solver-history.md, forty-first session).
inline Finding check_hierarchical(const Scene& scene, double eps) {
    Solution sol;
    try {
        HierarchicalOptions o;
        o.eps = eps;
        o.threads = 1;
        sol = solve_hierarchical(scene, o);
    } catch (const InputError&) {
        return std::nullopt;  // a closed white enclosure: a clean refusal
    }
    if (sol.patches.size() != scene.patches.size()) return broken("hierarchical: patch count of the solution", 0);
    for (const PatchResult& p : sol.patches) {
        for (double b : p.radiosity)
            if (!std::isfinite(b)) return broken("hierarchical: patch radiosity not finite", b);
        for (const ElementValue& e : p.elements)
            for (double b : e.B)
                if (!std::isfinite(b)) return broken("hierarchical: element radiosity not finite", b);
    }
    for (const auto* v : {&sol.totals.emitted, &sol.totals.absorbed, &sol.totals.escaped, &sol.totals.balance})
        for (double x : *v)
            if (!std::isfinite(x)) return broken("hierarchical: totals not finite", x);
    if (!std::isfinite(sol.stats.residual)) return broken("hierarchical: residual not finite", sol.stats.residual);
    return std::nullopt;
}

// The hierarchical target's eps: the default's neighbourhood is slow on
// stiff fuzzed scenes (one took 3.6 s at eps 1e-2 in a Release build, past
// libFuzzer's 10 s in the sanitizers'); these two still split links down
// to elements and exercise clusters, visibility and the solve.
inline constexpr double hierarchical_eps[] = {1.0, 0.1};

/// Parses `text` and, for an accepted scene that keeps its invariants and
/// has at most max_segments segments, returns check(scene). nullopt:
/// refused cleanly, too large to solve, or the check found nothing.
template <class Check>
Finding on_accepted_scene(const std::string& text, const Check& check) {
    Scene scene;
    try {
        scene = parse_scene(text, "fuzz.json");
    } catch (const InputError&) {
        return std::nullopt;  // refused cleanly
    }
    if (Finding f = check_scene(scene)) return f;
    if (scene.segments.size() > max_segments) return std::nullopt;
    return check(scene);
}

/// Everything above on one input text. nullopt: refused cleanly or all
/// invariants hold.
inline Finding check_input(const std::string& text) {
    return on_accepted_scene(text, [](const Scene& scene) -> Finding {
        if (Finding f = check_form_factors(scene)) return f;
        for (int K : {1, 2})
            if (scene.patches.size() * static_cast<size_t>(K) <= max_elements)
                if (Finding f = check_solution(scene, K)) return f;
        return std::nullopt;
    });
}

/// The hierarchical solver's checks on one input text (the second target,
/// fuzz_hierarchical): an accepted scene of at most max_segments segments
/// solved at each of hierarchical_eps.
inline Finding check_hierarchical_input(const std::string& text) {
    return on_accepted_scene(text, [](const Scene& scene) -> Finding {
        for (double eps : hierarchical_eps)
            if (Finding f = check_hierarchical(scene, eps)) return f;
        return std::nullopt;
    });
}

}  // namespace flatrad::fuzz
