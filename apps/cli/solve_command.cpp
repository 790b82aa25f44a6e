#include "cli/solve_command.h"

#include <cmath>
#include <ostream>

#include <fmt/format.h>

#include "cli/atomic_write.h"
#include "cli/result_json.h"
#include "cli/summary.h"
#include "cli/usage_error.h"
#include "engine/scene.h"
#include "solver/exact_solver.h"

namespace flatrad {

namespace {

void check_tolerance(const std::optional<double>& value, const char* flag) {
    if (value && !(std::isfinite(*value) && *value >= 0))
        throw UsageError(fmt::format("{}: expected a finite number >= 0, got {}", flag, *value));
}

void check_arguments(const SolveArgs& args) {
    if (args.method == "hierarchical")
        throw UsageError(
            "--method hierarchical: not available yet (the hierarchical solver has not landed); "
            "use --method exact");
    if (args.method != "exact")
        throw UsageError(fmt::format("--method {}: expected exact or hierarchical", args.method));
    if (!args.svg.empty())
        throw UsageError("--svg: not available yet (the SVG writer has not landed)");
    if (args.subdivide < 1)
        throw UsageError(fmt::format("--subdivide: expected an integer >= 1, got {}", args.subdivide));
    if (args.threads < 0)
        throw UsageError(fmt::format("--threads: expected an integer >= 0 (0: all cores), got {}",
                                     args.threads));
    check_tolerance(args.eps, "--eps");
    check_tolerance(args.vis_eps, "--vis-eps");
    if (!args.output.empty()) check_output_path(args.output, "-o");
}

// The exact solver holds a dense elements x elements matrix of doubles.
void check_exact_size(const Scene& scene, int subdivide) {
    const double patches = static_cast<double>(scene.patches.size());
    const double elements = patches * subdivide;
    const double bytes = elements * elements * 8;
    if (bytes > exact_matrix_limit_bytes)
        throw UsageError(fmt::format(
            "--subdivide {}: {:.0f} elements ({} patches x {}) would need {:.1f} GiB for the "
            "exact solver's form-factor matrix (elements^2 x 8 bytes); the limit is {:.0f} GiB",
            subdivide, elements, scene.patches.size(), subdivide, bytes / (1024.0 * 1024 * 1024),
            exact_matrix_limit_bytes / (1024.0 * 1024 * 1024)));
}

}  // namespace

int run_solve(const SolveArgs& args, std::ostream& out, std::ostream& err) {
    check_arguments(args);
    const Scene scene = load_scene(args.scene);
    check_exact_size(scene, args.subdivide);

    ExactSolverOptions options;
    options.subdivide = args.subdivide;
    options.threads = args.threads;
    const Solution solution = solve_exact(scene, options);

    const std::string text = format_result(result_json(scene, solution));
    if (args.output.empty()) {
        out << text << std::flush;
    } else {
        write_file_atomically(args.output, text);
    }
    if (!args.quiet) print_summary(err, scene, solution, args.output);
    return 0;
}

}  // namespace flatrad
