#pragma once
/// `flatrad solve` (SPEC.md, "Command line"): read a scene, solve it, write
/// the result file.
#include <iosfwd>
#include <optional>
#include <string>

namespace flatrad {

struct SolveArgs {
    std::string scene;                ///< scene file
    std::string output;               ///< result file; empty: stdout
    std::string method = "hierarchical";  ///< "hierarchical" (SPEC's default) or "exact"
    std::optional<double> eps;        ///< hierarchical refinement tolerance
    std::optional<double> vis_eps;    ///< hierarchical visibility tolerance
    int subdivide = 1;                ///< elements per patch (exact), >= 1
    std::string svg;                  ///< picture of the solution; empty: none
    int threads = 0;                  ///< 0: all cores
    bool quiet = false;               ///< no summary (nor progress line, cli/progress.h) on stderr
};

/// Validates `args` (throws UsageError), loads the scene (InputError),
/// refuses a run beyond the exact solver's memory limit (InputError, from
/// check_exact_solver_memory in solver/exact_solver.h), solves it, and
/// writes the result to args.output atomically or to `out`.
/// Nothing is written when any step fails. The summary goes to `err`.
int run_solve(const SolveArgs& args, std::ostream& out, std::ostream& err);

}  // namespace flatrad
