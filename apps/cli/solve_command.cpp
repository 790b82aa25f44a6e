#include "cli/solve_command.h"

#include <cmath>
#include <ostream>

#include <fmt/format.h>

#include "cli/atomic_write.h"
#include "cli/progress.h"
#include "cli/result_json.h"
#include "cli/scene_svg.h"
#include "cli/scene_warnings.h"
#include "cli/summary.h"
#include "cli/tolerance_flag.h"
#include "cli/usage_error.h"
#include "engine/scene.h"
#include "solver/exact_solver.h"
#include "solver/hierarchical_solver.h"

namespace flatrad {

namespace {

void check_arguments(const SolveArgs& args) {
    if (args.method != "exact" && args.method != "hierarchical")
        throw UsageError(fmt::format("--method {}: expected exact or hierarchical", args.method));
    if (args.subdivide < 1)
        throw UsageError(fmt::format("--subdivide: expected an integer >= 1, got {}", args.subdivide));
    if (args.threads < 0)
        throw UsageError(fmt::format("--threads: expected an integer >= 0 (0: all cores), got {}",
                                     args.threads));
    // (One bound whatever the value: -1 and 0 are refused alike.)
    check_tolerance(args.eps, "--eps", args.method == "hierarchical", " (--method hierarchical; 0 would refine forever)");
    check_tolerance(args.vis_eps, "--vis-eps");
    if (!args.output.empty()) check_output_path(args.output, "-o");
    if (!args.svg.empty()) check_output_path(args.svg, "--svg");
}

}  // namespace

int run_solve(const SolveArgs& args, std::ostream& out, std::ostream& err) {
    check_arguments(args);
    const Scene scene = load_scene_reporting(args.scene, err);
    Solution solution;
    if (args.method == "hierarchical") {
        HierarchicalOptions options;
        if (args.eps) options.eps = *args.eps;
        if (args.vis_eps) options.vis_eps = *args.vis_eps;
        options.threads = args.threads;
        // Progress on stderr when it is a terminal (cli/progress.h); erased
        // before the summary, and on an exception by the destructor.
        ProgressLine progress(err, !args.quiet && is_terminal_stderr(err));
        if (progress.enabled()) options.progress = progress.callback("solve: ");
        solution = solve_hierarchical(scene, options);
        progress.clear();
    } else {
        // Refused before any work when it would not fit (the message says how
        // much it would need); the flag is named when --subdivide is the cause.
        check_exact_solver_memory(scene, args.subdivide);

        ExactSolverOptions options;
        options.subdivide = args.subdivide;
        options.threads = args.threads;
        solution = solve_exact(scene, options);
    }

    const std::string text = result_text(scene, solution);
    // Drawn before anything is written, so that a failure writes nothing.
    const std::string picture = args.svg.empty() ? std::string() : render_scene_svg(scene, solution);
    if (args.output.empty()) {
        out << text << std::flush;
    } else {
        write_file_atomically(args.output, text);
    }
    if (!args.svg.empty()) write_file_atomically(args.svg, picture);
    if (!args.quiet) print_summary(err, scene, solution, args.output);
    return 0;
}

}  // namespace flatrad
