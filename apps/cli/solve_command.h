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
    std::string method = "exact";     ///< "exact" or "hierarchical"
    std::optional<double> eps;        ///< hierarchical refinement tolerance
    std::optional<double> vis_eps;    ///< hierarchical visibility tolerance
    int subdivide = 1;                ///< elements per patch (exact), >= 1
    std::string svg;                  ///< picture of the solution; empty: none
    int threads = 0;                  ///< 0: all cores
    bool quiet = false;               ///< no summary on stderr
};

/// Largest dense form-factor matrix the exact solver is allowed to build
/// (elements^2 x 8 bytes): beyond it a run would swap or be killed rather
/// than fail cleanly, so it is refused up front with the size it would need.
constexpr double exact_matrix_limit_bytes = 8.0 * 1024 * 1024 * 1024;

/// Validates `args` (throws UsageError), loads the scene (InputError),
/// solves it, and writes the result to args.output atomically or to `out`.
/// Nothing is written when any step fails. The summary goes to `err`.
int run_solve(const SolveArgs& args, std::ostream& out, std::ostream& err);

}  // namespace flatrad
