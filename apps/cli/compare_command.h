#pragma once
/// `flatrad compare` (SPEC.md, "Command line"; DESIGN.md §5): the
/// hierarchical solver against the exact one, error and run time side by
/// side.
///
/// The reference must be much better than what it judges, so the exact
/// solver's own discretisation error is estimated and driven down:
///   1. solve hierarchically (--eps, --vis-eps);
///   2. solve exactly at K (--subdivide, default 16) and at 2K; the
///      estimate of the K solution's error is the relative L2 distance
///      between the two (below), and the hierarchical error is measured
///      against the 2K solution;
///   3. while the estimate exceeds 1/10 of the hierarchical error, double
///      K (the old 2K solve is reused) and go to 2 -- unless the next 2K
///      would exceed the exact solver's memory limit
///      (exact_solver_memory_bytes) or --max-elements, or the estimate is
///      at rounding level (1e-12: K and 2K agree, a finer mesh cannot do
///      better); then the last pair is reported with `reached: false` and
///      `stopped` says why.
/// The estimate is that of the K solution; the 2K reference used is
/// usually better still (its error shrinks with K), so the estimate is
/// conservative.
///
/// Errors are over patches (their length-weighted mean radiosity), all
/// channels, each patch weighted by its length L_p:
///   relative_l2  = sqrt(sum_pc L_p (B_pc - R_pc)^2 / sum_pc L_p R_pc^2),
///   max_relative = max_pc |B_pc - R_pc| / rms_c, rms_c the length-weighted
///                  RMS of the reference's channel c (so a dark patch's
///                  error counts at the scale of the scene, not of itself).
/// Both are 0 when the solutions agree, and 0 (not NaN) for an all-dark
/// reference that is matched exactly; +inf for a mismatch against it.
///
/// Output: a table on stderr (unless --quiet), the JSON object on stdout or
/// in -o (written atomically).
#include <iosfwd>
#include <string>

#include "engine/scene.h"
#include "solver/solution.h"

namespace CLI {
class App;
}

namespace flatrad {

struct CompareArgs {
    std::string scene;        ///< scene file
    std::string output;       ///< JSON file; empty: stdout
    double eps = 1e-2;        ///< hierarchical refinement tolerance, > 0
    double vis_eps = -1;      ///< hierarchical visibility tolerance; < 0: eps / 10
    int subdivide = 16;       ///< first reference K, >= 1
    long max_elements = 8000; ///< largest exact mesh (patches x K) tried
    int threads = 0;          ///< 0: all cores
    bool quiet = false;       ///< no table on stderr
};

/// Default --max-elements: a dense LU of 8000 unknowns is ~3e11 flops and
/// 1.5 GB (three matrices), a minute or two on a small machine; the exact
/// solver's own memory limit (8 GiB) would allow ~19000, hours of work.
inline constexpr long default_compare_max_elements = 8000;

/// Errors of `solution` against `reference` (same scene), as above.
struct CompareError {
    double relative_l2 = 0;
    double max_relative = 0;
    int worst_patch = -1;  ///< where max_relative is reached; -1 when none
};
CompareError compare_solutions(const Scene& scene, const Solution& solution, const Solution& reference);

/// Registers `compare` on `app`, filling `args`.
CLI::App* add_compare_command(CLI::App& app, CompareArgs& args);

/// Runs it. Throws UsageError for bad flags, InputError for a bad scene.
int run_compare(const CompareArgs& args, std::ostream& out, std::ostream& err);

}  // namespace flatrad
