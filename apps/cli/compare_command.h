#pragma once
/// `flatrad compare` (SPEC.md, "Command line"; DESIGN.md §5): the
/// hierarchical solver against the exact one, error and run time side by
/// side.
///
/// The reference is an exact solution whose own estimated discretisation
/// error is at most a tenth of the hierarchical error
/// (cli/reference_solution.h); the errors are those of
/// cli/solution_error.h (relative L2 and max relative over patches).
///
/// Output: a table on stderr (unless --quiet), the JSON object on stdout or
/// in -o (written atomically).
#include <iosfwd>
#include <optional>
#include <string>

#include "cli/reference_solution.h"
#include "cli/solution_error.h"
#include "solver/hierarchical_solver.h"

namespace CLI {
class App;
}

namespace flatrad {

/// Default --max-elements (cli/reference_solution.h).
inline constexpr long default_compare_max_elements = default_reference_max_elements;

struct CompareArgs {
    std::string scene;        ///< scene file
    std::string output;       ///< JSON file; empty: stdout
    std::string reference_output;  ///< the reference's result file (SPEC.md "Result file"); empty: none
    double eps = HierarchicalOptions{}.eps;  ///< hierarchical refinement tolerance, > 0 (solve's default)
    std::optional<double> vis_eps;  ///< hierarchical visibility tolerance; absent: eps / 10
    int subdivide = 16;       ///< first reference K, >= 1
    long max_elements = default_compare_max_elements; ///< largest exact mesh (elements) tried
    int threads = 0;          ///< 0: all cores
    bool quiet = false;       ///< no table on stderr
};

/// Registers `compare` on `app`, filling `args`.
CLI::App* add_compare_command(CLI::App& app, CompareArgs& args);

/// Runs it. Throws UsageError for bad flags, InputError for a bad scene.
int run_compare(const CompareArgs& args, std::ostream& out, std::ostream& err);

}  // namespace flatrad
